//! TinyRISC register file: 16 x 32-bit, `r0` reads as zero, `r15` is the
//! link register of `jal`.

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RegisterFile {
    r: [u32; 16],
}

impl RegisterFile {
    #[inline(always)]
    pub fn read(&self, k: u8) -> u32 {
        self.r[k as usize & 15]
    }

    /// Write (at the clock edge); writes to `r0` are dropped.
    #[inline(always)]
    pub fn write(&mut self, k: u8, v: u32) {
        if k & 15 != 0 {
            self.r[k as usize & 15] = v;
        }
    }

    pub fn all(&self) -> &[u32; 16] {
        &self.r
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn r0_is_zero() {
        let mut r = super::RegisterFile::default();
        r.write(0, 5);
        r.write(7, 9);
        assert_eq!((r.read(0), r.read(7)), (0, 9));
    }
}
