//! External (main) memory: byte-addressed, little-endian.
//!
//! TinyRISC fetches its instructions and loads/stores its data here, and
//! the DMA controller moves blocks between it and the frame buffer or the
//! context memory. The model is ideal: one access per requester per cycle,
//! no contention between TinyRISC and DMA (the DMA's bandwidth is set by
//! [`crate::dma::DmaTiming`]). Accesses outside the memory or misaligned are
//! faults.

use crate::kernel::Fault;

pub const DEFAULT_SIZE: usize = 16 << 20;

pub struct MainMemory {
    m: Vec<u8>,
}

impl MainMemory {
    pub fn new(bytes: usize) -> MainMemory {
        MainMemory { m: vec![0; bytes] }
    }

    pub fn size(&self) -> usize {
        self.m.len()
    }

    /// Is `[addr, addr + len)` inside the memory?
    #[inline(always)]
    pub fn contains(&self, addr: u32, len: u32) -> bool {
        (addr as u64 + len as u64) <= self.m.len() as u64
    }

    /// Check an access of `size` bytes (1, 2, 4): inside and aligned.
    #[inline(always)]
    pub fn check(&self, addr: u32, size: u32) -> Result<(), Fault> {
        if addr.is_multiple_of(size) && self.contains(addr, size) {
            Ok(())
        } else {
            Err(self.fault(addr, size))
        }
    }

    /// The aligned word at `addr`, if inside (an instruction fetch).
    #[inline(always)]
    pub fn word(&self, addr: u32) -> Option<u32> {
        if !addr.is_multiple_of(4) {
            return None;
        }
        let a = addr as usize;
        let b = self.m.get(a..a.checked_add(4)?)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    /// Why an access of `size` bytes at `addr` is refused (misaligned, or
    /// else outside; called when [`MainMemory::check`] fails).
    #[cold]
    #[inline(never)]
    pub fn fault(&self, addr: u32, size: u32) -> Fault {
        if !addr.is_multiple_of(size) {
            return Fault::new(
                "memory",
                format!("misaligned {size}-byte access at 0x{addr:08x}"),
            );
        }
        Fault::new(
            "memory",
            format!(
                "address 0x{addr:08x} outside main memory (0..0x{:x})",
                self.m.len()
            ),
        )
    }

    /// Read `size` bytes (zero-extended); the caller has checked the access.
    #[inline(always)]
    pub fn read(&self, addr: u32, size: u32) -> u32 {
        let a = addr as usize;
        match size {
            1 => self.m[a] as u32,
            2 => u16::from_le_bytes([self.m[a], self.m[a + 1]]) as u32,
            _ => {
                let b = &self.m[a..a + 4];
                u32::from_le_bytes([b[0], b[1], b[2], b[3]])
            }
        }
    }

    #[inline(always)]
    pub fn write(&mut self, addr: u32, size: u32, v: u32) {
        let a = addr as usize;
        match size {
            1 => self.m[a] = v as u8,
            2 => self.m[a..a + 2].copy_from_slice(&(v as u16).to_le_bytes()),
            _ => self.m[a..a + 4].copy_from_slice(&v.to_le_bytes()),
        }
    }

    /// Loader access.
    pub fn load(&mut self, addr: u32, data: &[u8]) -> Result<(), Fault> {
        if !self.contains(addr, data.len() as u32) {
            return Err(Fault::new(
                "loader",
                format!(
                    "segment 0x{addr:08x}+{} outside main memory (0..0x{:x})",
                    data.len(),
                    self.m.len()
                ),
            ));
        }
        self.m[addr as usize..addr as usize + data.len()].copy_from_slice(data);
        Ok(())
    }

    pub fn bytes(&self, addr: u32, len: usize) -> &[u8] {
        &self.m[addr as usize..addr as usize + len]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn little_endian_and_checked() {
        let mut m = MainMemory::new(64);
        m.write(4, 4, 0x1122_3344);
        assert_eq!(m.read(4, 1), 0x44);
        assert_eq!(m.read(6, 2), 0x1122);
        assert!(m.check(62, 4).is_err());
        assert!(m.check(5, 2).is_err());
        assert!(m.check(60, 4).is_ok());
        assert!(m.check(64, 1).is_err());
    }
}
