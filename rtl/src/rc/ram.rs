//! The RC's local RAM: 512 words per RC (16-bit: 1 KB; 32-bit: 2 KB), one
//! access per cycle.
//!
//! Addresses are checked: an access outside 0..=511 in an executing RC is a
//! fault (the RC stack of the ray tracer relies on this to catch overflow),
//! never a silent wrap.

use super::word::Word;

pub const WORDS: usize = 512;

pub struct Ram<const N: usize, W: Word = i16> {
    /// Address-major: word `a` of every lane is the row `m[a]`, so an
    /// access at the same address in every RC (the common case: constants,
    /// the stack, the hit record) is one contiguous row.
    m: Vec<[W; N]>,
}

impl<const N: usize, W: Word> Default for Ram<N, W> {
    fn default() -> Self {
        Ram {
            m: vec![[W::ZERO; N]; WORDS],
        }
    }
}

impl<const N: usize, W: Word> Ram<N, W> {
    #[inline(always)]
    pub fn read(&self, lane: usize, addr: usize) -> W {
        self.m[addr][lane]
    }

    /// Write at the clock edge.
    #[inline(always)]
    pub fn write(&mut self, lane: usize, addr: usize, v: W) {
        self.m[addr][lane] = v;
    }

    /// Word `addr` of every lane.
    #[inline(always)]
    pub fn row(&self, addr: usize) -> &[W; N] {
        &self.m[addr]
    }

    /// Word `addr` of every lane, for writing at the clock edge.
    #[inline(always)]
    pub fn row_mut(&mut self, addr: usize) -> &mut [W; N] {
        &mut self.m[addr]
    }

    /// Is `addr` a valid word address?
    #[inline(always)]
    pub fn valid(addr: i32) -> bool {
        (0..WORDS as i32).contains(&addr)
    }
}
