//! The RC register file: 16 words (16 or 32 bits), two read ports and one write port.
//!
//! Held lane-wise: `r[k]` is register `k` of every lane, so one broadcast
//! context reads or writes one contiguous vector. Reads see the state
//! during the cycle; the write lands at the clock edge
//! ([`RegisterFile::write`] is only called from the array's commit).

use super::lanes::Mask;
use super::word::Word;
use super::word::{blend, select_word};

pub(crate) const REGS: usize = 16;

pub struct RegisterFile<const N: usize, W: Word = i16> {
    pub(crate) r: [[W; N]; REGS],
}

impl<const N: usize, W: Word> Default for RegisterFile<N, W> {
    fn default() -> Self {
        RegisterFile {
            r: [[W::ZERO; N]; REGS],
        }
    }
}

impl<const N: usize, W: Word> RegisterFile<N, W> {
    /// Read port: register `k` of every lane.
    #[inline(always)]
    pub fn read(&self, k: u8) -> &[W; N] {
        &self.r[k as usize & 15]
    }

    /// Write port, at the clock edge: register `k` of the lanes in `mask`.
    #[inline(always)]
    pub fn write(&mut self, k: u8, mask: Mask, data: &[W; N]) {
        select_word(&mut self.r[k as usize & 15], mask, data);
    }

    /// [`RegisterFile::write`] with the mask already expanded to 0 / -1
    /// lanes ([`super::word::expand`]).
    #[inline(always)]
    pub fn write_lanes(&mut self, k: u8, m: &[W; N], data: &[W; N]) {
        blend(&mut self.r[k as usize & 15], m, data);
    }

    /// Set a register of one lane directly (testbench and loader access, not
    /// a datapath port).
    pub fn poke(&mut self, lane: usize, k: u8, v: W) {
        self.r[k as usize & 15][lane] = v;
    }
}
