//! The RC's local RAM: 512 x 16-bit (1 KB) per RC, one access per cycle.
//!
//! Addresses are checked: an access outside 0..=511 in an executing RC is a
//! fault (the RC stack of the ray tracer relies on this to catch overflow),
//! never a silent wrap.

pub const WORDS: usize = 512;

pub struct Ram<const N: usize> {
    /// Address-major: word `a` of every lane is the row `m[a]`, so an
    /// access at the same address in every RC (the common case: constants,
    /// the stack, the hit record) is one contiguous row.
    m: Vec<[i16; N]>,
}

impl<const N: usize> Default for Ram<N> {
    fn default() -> Self {
        Ram {
            m: vec![[0; N]; WORDS],
        }
    }
}

impl<const N: usize> Ram<N> {
    #[inline(always)]
    pub fn read(&self, lane: usize, addr: usize) -> i16 {
        self.m[addr][lane]
    }

    /// Write at the clock edge.
    #[inline(always)]
    pub fn write(&mut self, lane: usize, addr: usize, v: i16) {
        self.m[addr][lane] = v;
    }

    /// Word `addr` of every lane.
    #[inline(always)]
    pub fn row(&self, addr: usize) -> &[i16; N] {
        &self.m[addr]
    }

    /// Word `addr` of every lane, for writing at the clock edge.
    #[inline(always)]
    pub fn row_mut(&mut self, addr: usize) -> &mut [i16; N] {
        &mut self.m[addr]
    }

    /// Is `addr` (a 16-bit value read as unsigned) a valid word address?
    #[inline(always)]
    pub fn valid(addr: i32) -> bool {
        (0..WORDS as i32).contains(&addr)
    }
}
