//! The frame buffer: 2 sets x 2 banks x 16K words of the datapath width
//! (16-bit: 128 KB; 32-bit chip: 256 KB).
//!
//! An FB address is 16 bits: bit 15 the set, bit 14 the bank, bits 13..0
//! the word in the bank; the bank index `addr >> 14` (0..3) names one of
//! the four banks.
//!
//! * **Broadcast to the array**: each set supplies at most one datum per
//!   cycle, seen by all 64 RCs as operand source `fb0` / `fb1`; so two data
//!   per cycle with both sets streaming (`dbcb`).
//! * **Write path**: `wfb` writes the 64 RC outputs (row-major) into 64
//!   consecutive words of one bank, one row of 8 per cycle.
//! * **DMA** fills or drains one bank while the array uses another. The FB
//!   itself only stores; the chip checks every array and TinyRISC access
//!   against the banks the DMA owns ([`crate::dma::Dma::owned_fb_banks`])
//!   and faults on a conflict.

pub(crate) const BANK_WORDS: usize = 1 << 14;
pub const WORDS: usize = 1 << 16;

use crate::rc::Word;

/// Bank index (0..3) of an FB address.
#[inline(always)]
pub const fn bank(addr: u16) -> usize {
    (addr >> 14) as usize
}

/// Set (0, 1) of an FB address.
#[inline(always)]
pub const fn set(addr: u16) -> usize {
    (addr >> 15) as usize
}

pub struct FrameBuffer<W: Word = i16> {
    m: Vec<W>,
}

impl<W: Word> Default for FrameBuffer<W> {
    fn default() -> Self {
        FrameBuffer {
            m: vec![W::ZERO; WORDS],
        }
    }
}

impl<W: Word> FrameBuffer<W> {
    #[inline(always)]
    pub fn read(&self, addr: u16) -> W {
        self.m[addr as usize]
    }

    /// Write (at the clock edge).
    #[inline(always)]
    pub fn write(&mut self, addr: u16, v: W) {
        self.m[addr as usize] = v;
    }

    /// Testbench/loader access to a run of words.
    pub fn slice(&self, addr: u16, n: usize) -> &[W] {
        &self.m[addr as usize..addr as usize + n]
    }

    pub fn fill(&mut self, addr: u16, data: &[W]) {
        self.m[addr as usize..addr as usize + data.len()].copy_from_slice(data);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn address_fields() {
        assert_eq!((set(0x0000), bank(0x0000)), (0, 0));
        assert_eq!((set(0x4000), bank(0x4000)), (0, 1));
        assert_eq!((set(0x8000), bank(0x8000)), (1, 2));
        assert_eq!((set(0xFFFF), bank(0xFFFF)), (1, 3));
        assert_eq!(BANK_WORDS * 4, WORDS);
        let mut fb = FrameBuffer::<i16>::default();
        fb.write(0xC001, -7);
        assert_eq!(fb.read(0xC001), -7);
        assert_eq!(fb.slice(0xC000, 2), &[0, -7]);
    }
}
