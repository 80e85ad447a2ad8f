//! Context memory: 8 x 1K x 32-bit, in two banks.
//!
//! Organisation: eight 1K-word planes interleaved on the low three address
//! bits, so context address `a` (0..8191) is word `a >> 3` of plane `a & 7`.
//! Bank 0 is addresses 0..4095, bank 1 is 4096..8191 (each bank is the half
//! of every plane). The interleave is what makes row and column mode work
//! in one cycle: an 8-aligned group of 8 words is one word from each plane,
//! read at once, word `i` to row (or column) `i`.
//!
//! While the array streams from one bank, DMA (`ldctxt`) may load the other;
//! the chip faults if the array reads a bank the DMA is loading.
//!
//! Contexts are **decoded once, when written** (by DMA or the loader), and
//! stored decoded beside the raw word: the array never decodes in its cycle
//! loop. A word that does not decode is stored as such and faults only if
//! the array executes it.

use crate::rc::context::{Context, DecodeError};

pub const WORDS: usize = 8192;
pub(crate) const BANK_WORDS: usize = 4096;

#[inline(always)]
pub const fn bank(addr: u16) -> usize {
    addr as usize / BANK_WORDS
}

pub struct ContextMemory {
    /// Decode for the 32-bit datapath (`f[10]` is bit 5 of the multiplier
    /// shift) rather than the 16-bit one (`f[10]` reserved).
    wide: bool,
    words: Vec<u32>,
    decoded: Vec<Context>,
    /// `Some(error)` where the word does not decode.
    errors: Vec<Option<DecodeError>>,
}

impl Default for ContextMemory {
    fn default() -> Self {
        let nop = Context::NOP;
        ContextMemory {
            wide: false,
            words: vec![nop.encode(); WORDS],
            decoded: vec![nop; WORDS],
            errors: vec![None; WORDS],
        }
    }
}

impl ContextMemory {
    /// The context memory of the 32-bit chip (or not).
    pub fn for_datapath(wide: bool) -> ContextMemory {
        ContextMemory {
            wide,
            ..ContextMemory::default()
        }
    }

    /// Write one word (at the clock edge): decoded here, once.
    #[inline]
    pub fn write(&mut self, addr: u16, word: u32) {
        let a = addr as usize;
        self.words[a] = word;
        match Context::decode_for(word, self.wide) {
            Ok(c) => {
                self.decoded[a] = c;
                self.errors[a] = None;
            }
            Err(e) => {
                self.decoded[a] = Context::NOP;
                self.errors[a] = Some(e);
            }
        }
    }

    #[inline(always)]
    pub fn word(&self, addr: u16) -> u32 {
        self.words[addr as usize]
    }

    /// The decoded context at `addr`.
    #[inline(always)]
    pub fn context(&self, addr: u16) -> Result<&Context, DecodeError> {
        match self.errors[addr as usize] {
            None => Ok(&self.decoded[addr as usize]),
            Some(e) => Err(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rc::context::Op;

    #[test]
    fn words_are_decoded_at_write_and_bad_words_kept_as_errors() {
        let mut m = ContextMemory::default();
        let c = Context::rri(Op::Add, 1, 2, -5);
        m.write(4100, c.encode());
        assert_eq!(m.context(4100), Ok(&c));
        assert_eq!(m.word(4100), c.encode());
        assert_eq!(bank(4095), 0);
        assert_eq!(bank(4096), 1);
        m.write(7, 0x3F << 26);
        assert!(m.context(7).is_err());
        assert_eq!(m.context(8), Ok(&Context::NOP));
    }
}
