//! The RC's local RAM: 512 x 16-bit (1 KB) per RC, one access per cycle.
//!
//! Addresses are checked: an access outside 0..=511 in an executing RC is a
//! fault (the RC stack of the ray tracer relies on this to catch overflow),
//! never a silent wrap.

pub const WORDS: usize = 512;

pub struct Ram<const N: usize> {
    /// Lane-major: lane `i` owns `m[i * 512 .. (i + 1) * 512]`.
    m: Vec<i16>,
}

impl<const N: usize> Default for Ram<N> {
    fn default() -> Self {
        Ram {
            m: vec![0; N * WORDS],
        }
    }
}

impl<const N: usize> Ram<N> {
    #[inline(always)]
    pub fn read(&self, lane: usize, addr: usize) -> i16 {
        self.m[lane * WORDS + addr]
    }

    /// Write at the clock edge.
    #[inline(always)]
    pub fn write(&mut self, lane: usize, addr: usize, v: i16) {
        self.m[lane * WORDS + addr] = v;
    }

    /// Is `addr` (a 16-bit value read as unsigned) a valid word address?
    #[inline(always)]
    pub fn valid(addr: i32) -> bool {
        (0..WORDS as i32).contains(&addr)
    }
}
