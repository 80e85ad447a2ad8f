//! The RC register file: 16 x 16-bit, two read ports and one write port.
//!
//! Held lane-wise: `r[k]` is register `k` of every lane, so one broadcast
//! context reads or writes one contiguous vector. Reads see the state
//! during the cycle; the write lands at the clock edge
//! ([`RegisterFile::write`] is only called from the array's commit).

use super::lanes::{select16, Mask};

pub const REGS: usize = 16;

pub struct RegisterFile<const N: usize> {
    pub(crate) r: [[i16; N]; REGS],
}

impl<const N: usize> Default for RegisterFile<N> {
    fn default() -> Self {
        RegisterFile { r: [[0; N]; REGS] }
    }
}

impl<const N: usize> RegisterFile<N> {
    /// Read port: register `k` of every lane.
    #[inline(always)]
    pub fn read(&self, k: u8) -> &[i16; N] {
        &self.r[k as usize & 15]
    }

    /// Write port, at the clock edge: register `k` of the lanes in `mask`.
    #[inline(always)]
    pub fn write(&mut self, k: u8, mask: Mask, data: &[i16; N]) {
        select16(&mut self.r[k as usize & 15], mask, data);
    }

    /// Set a register of one lane directly (testbench and loader access, not
    /// a datapath port).
    pub fn poke(&mut self, lane: usize, k: u8, v: i16) {
        self.r[k as usize & 15][lane] = v;
    }
}
