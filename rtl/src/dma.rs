//! The DMA controller: main memory <-> frame buffer, main memory -> context
//! memory, concurrently with the array and TinyRISC.
//!
//! One channel. TinyRISC starts a transfer (`ldfb`, `stfb`, `ldctxt`) and
//! goes on; a second transfer, or `dwait`, stalls TinyRISC until the
//! channel is free (counted as DMA stall cycles).
//!
//! **Timing model** ([`DmaTiming`], every parameter a user can change): a
//! transfer issued in cycle `t` spends `setup_cycles` cycles on setup
//! (address phase, external memory latency), then moves `bytes_per_cycle`
//! bytes per cycle: an FB word is 2 bytes (4 on the 32-bit chip), a context
//! word 4. The last word
//! lands at the clock edge of cycle `t + setup_cycles + ceil(bytes /
//! bytes_per_cycle)`, so a transfer occupies the channel for
//! [`DmaTiming::cycles`] cycles after its issue cycle.
//!
//! **Ownership.** From its issue until its last word, a transfer owns the
//! FB or context-memory banks it touches: an array or TinyRISC access to
//! such a bank is a fault ("DMA conflict"), never a silent race.

use crate::context_memory::{self, ContextMemory};
use crate::fb::{self, FrameBuffer};
use crate::memory::MainMemory;
use crate::rc::Word;

/// The DMA timing parameters.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DmaTiming {
    /// Cycles between the issue of a transfer and its first word.
    pub setup_cycles: u32,
    /// Bytes moved per cycle once the transfer streams (external bus width).
    pub bytes_per_cycle: u32,
}

impl Default for DmaTiming {
    fn default() -> Self {
        DmaTiming {
            setup_cycles: 10,
            bytes_per_cycle: 4,
        }
    }
}

impl DmaTiming {
    /// Cycles a transfer of `words` words of `word_bytes` bytes occupies the
    /// channel after its issue cycle.
    pub fn cycles(&self, words: u32, word_bytes: u32) -> u64 {
        let bpc = self.bytes_per_cycle.max(1) as u64;
        self.setup_cycles as u64 + (words as u64 * word_bytes as u64).div_ceil(bpc)
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DmaKind {
    /// `ldfb`: main memory to frame buffer (FB words: 16 or 32 bits).
    MemToFb = 1,
    /// `stfb`: frame buffer to main memory.
    FbToMem = 2,
    /// `ldctxt`: main memory to context memory (32-bit words).
    MemToCtx = 3,
}

impl DmaKind {
    /// Bytes per word on the 16-bit chip.
    pub fn word_bytes(self) -> u32 {
        self.word_bytes_for(2)
    }

    /// Bytes per word with FB words of `fb_word_bytes` (2 or 4) bytes.
    pub fn word_bytes_for(self, fb_word_bytes: u32) -> u32 {
        match self {
            DmaKind::MemToCtx => 4,
            _ => fb_word_bytes,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            DmaKind::MemToFb => "ldfb",
            DmaKind::FbToMem => "stfb",
            DmaKind::MemToCtx => "ldctxt",
        }
    }
}

/// One transfer as TinyRISC requests it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DmaRequest {
    pub kind: DmaKind,
    /// Byte address in main memory.
    pub mem: u32,
    /// FB word address or context-memory address.
    pub local: u32,
    pub words: u32,
}

impl DmaRequest {
    /// Range and alignment check, at issue (16-bit chip).
    pub fn validate(&self, mem_size: usize) -> Result<(), String> {
        self.validate_for(mem_size, 2)
    }

    /// Range and alignment check, at issue, with FB words of
    /// `fb_word_bytes` bytes.
    pub fn validate_for(&self, mem_size: usize, fb_word_bytes: u32) -> Result<(), String> {
        let wb = self.kind.word_bytes_for(fb_word_bytes);
        if !self.mem.is_multiple_of(wb) {
            return Err(format!(
                "{}: main-memory address 0x{:08x} not {wb}-byte aligned",
                self.kind.name(),
                self.mem
            ));
        }
        let bytes = self.words as u64 * wb as u64;
        if self.mem as u64 + bytes > mem_size as u64 {
            return Err(format!(
                "{}: main memory 0x{:08x}+{bytes} bytes outside main memory (0..0x{mem_size:x})",
                self.kind.name(),
                self.mem
            ));
        }
        let limit = match self.kind {
            DmaKind::MemToCtx => context_memory::WORDS,
            _ => fb::WORDS,
        } as u64;
        if self.local as u64 + self.words as u64 > limit {
            let what = if self.kind == DmaKind::MemToCtx {
                "context memory"
            } else {
                "frame buffer"
            };
            return Err(format!(
                "{}: {what} address 0x{:04x}+{} words outside the {what} (0..0x{limit:x})",
                self.kind.name(),
                self.local,
                self.words
            ));
        }
        Ok(())
    }

    /// Banks touched: (FB bank mask, context bank mask).
    fn banks(&self) -> (u8, u8) {
        if self.words == 0 {
            return (0, 0);
        }
        let (first, last) = (self.local, self.local + self.words - 1);
        let mut m = 0u8;
        match self.kind {
            DmaKind::MemToCtx => {
                for b in first as usize / context_memory::BANK_WORDS
                    ..=last as usize / context_memory::BANK_WORDS
                {
                    m |= 1 << b;
                }
                (0, m)
            }
            _ => {
                for b in first as usize / fb::BANK_WORDS..=last as usize / fb::BANK_WORDS {
                    m |= 1 << b;
                }
                (m, 0)
            }
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Active {
    req: DmaRequest,
    done: u32,
    setup_left: u32,
    credit: u32,
    /// PC of the instruction that issued it (for fault messages).
    pc: u32,
}

#[derive(Default)]
pub struct Dma {
    pub timing: DmaTiming,
    active: Option<Active>,
    fb_banks: u8,
    ctx_banks: u8,
    /// Cycles the channel was busy.
    pub busy_cycles: u64,
    /// Words moved (FB and context words).
    pub words_moved: u64,
    pub transfers: u64,
}

impl Dma {
    pub fn new(timing: DmaTiming) -> Dma {
        Dma {
            timing,
            ..Dma::default()
        }
    }

    #[inline(always)]
    pub fn idle(&self) -> bool {
        self.active.is_none()
    }

    /// FB banks (bit `b` for bank `b`, 0..3) the current transfer owns.
    #[inline(always)]
    pub fn owned_fb_banks(&self) -> u8 {
        self.fb_banks
    }

    /// Context-memory banks (bits 0, 1) the current transfer owns.
    #[inline(always)]
    pub fn owned_ctx_banks(&self) -> u8 {
        self.ctx_banks
    }

    /// The current transfer and the PC that issued it.
    pub fn current(&self) -> Option<(DmaRequest, u32)> {
        self.active.map(|a| (a.req, a.pc))
    }

    /// Words still to move in the current transfer.
    pub fn remaining(&self) -> u32 {
        self.active.map_or(0, |a| a.req.words - a.done)
    }

    /// Start a validated transfer (at the clock edge of its issue cycle).
    pub fn start(&mut self, req: DmaRequest, pc: u32) {
        debug_assert!(self.active.is_none());
        self.transfers += 1;
        if req.words == 0 {
            return;
        }
        (self.fb_banks, self.ctx_banks) = req.banks();
        self.active = Some(Active {
            req,
            done: 0,
            setup_left: self.timing.setup_cycles,
            credit: 0,
            pc,
        });
    }

    /// One clock edge of the channel.
    #[inline]
    pub fn tick<W: Word>(
        &mut self,
        mem: &mut MainMemory,
        fbm: &mut FrameBuffer<W>,
        cm: &mut ContextMemory,
    ) {
        let Some(a) = &mut self.active else {
            return;
        };
        self.busy_cycles += 1;
        if a.setup_left > 0 {
            a.setup_left -= 1;
            return;
        }
        let wb = a.req.kind.word_bytes_for(W::BITS / 8);
        a.credit += self.timing.bytes_per_cycle.max(1);
        while a.credit >= wb && a.done < a.req.words {
            a.credit -= wb;
            let m = a.req.mem + a.done * wb;
            let l = a.req.local + a.done;
            match a.req.kind {
                DmaKind::MemToFb => fbm.write(l as u16, W::wrap(mem.read(m, wb) as i64)),
                DmaKind::FbToMem => mem.write(m, wb, fbm.read(l as u16).to_i64() as u32),
                DmaKind::MemToCtx => cm.write(l as u16, mem.read(m, 4)),
            }
            a.done += 1;
            self.words_moved += 1;
        }
        if a.done == a.req.words {
            self.active = None;
            self.fb_banks = 0;
            self.ctx_banks = 0;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(t: DmaTiming, req: DmaRequest) -> (u64, MainMemory, FrameBuffer, ContextMemory) {
        run_w::<i16>(t, req)
    }

    fn run_w<W: Word>(
        t: DmaTiming,
        req: DmaRequest,
    ) -> (u64, MainMemory, FrameBuffer<W>, ContextMemory) {
        let mut mem = MainMemory::new(1 << 16);
        for i in 0..4096u32 {
            mem.write(i * 4, 4, i.wrapping_mul(0x9E37_79B9));
        }
        let mut fbm = FrameBuffer::default();
        let mut cm = ContextMemory::default();
        let mut d = Dma::new(t);
        req.validate_for(mem.size(), W::BITS / 8).unwrap();
        d.start(req, 0);
        let mut cycles = 0;
        while !d.idle() {
            d.tick(&mut mem, &mut fbm, &mut cm);
            cycles += 1;
            assert!(cycles < 100_000);
        }
        (cycles, mem, fbm, cm)
    }

    #[test]
    fn transfer_time_follows_the_documented_formula() {
        for (setup, bpc) in [(10, 4), (0, 2), (3, 8), (7, 1)] {
            let t = DmaTiming {
                setup_cycles: setup,
                bytes_per_cycle: bpc,
            };
            for (kind, words) in [
                (DmaKind::MemToFb, 37),
                (DmaKind::MemToCtx, 20),
                (DmaKind::FbToMem, 64),
            ] {
                let req = DmaRequest {
                    kind,
                    mem: 0x100,
                    local: 0x10,
                    words,
                };
                let (cycles, ..) = run(t, req);
                // independent formula: setup + ceil(bytes / bpc)
                let bytes = words as u64 * if kind == DmaKind::MemToCtx { 4 } else { 2 };
                assert_eq!(cycles, setup as u64 + bytes.div_ceil(bpc as u64));
                assert_eq!(cycles, t.cycles(words, kind.word_bytes()));
            }
        }
    }

    #[test]
    fn data_arrives_where_it_should() {
        let t = DmaTiming::default();
        let (_, mem, fbm, _) = run(
            t,
            DmaRequest {
                kind: DmaKind::MemToFb,
                mem: 8,
                local: 0x4002,
                words: 5,
            },
        );
        for k in 0..5u32 {
            assert_eq!(
                fbm.read(0x4002 + k as u16) as u16 as u32,
                mem.read(8 + 2 * k, 2)
            );
        }
        let (_, mem, _, cm) = run(
            t,
            DmaRequest {
                kind: DmaKind::MemToCtx,
                mem: 64,
                local: 4097,
                words: 3,
            },
        );
        for k in 0..3u32 {
            assert_eq!(cm.word(4097 + k as u16), mem.read(64 + 4 * k, 4));
        }
    }

    #[test]
    fn ranges_are_checked_and_banks_owned() {
        let r = DmaRequest {
            kind: DmaKind::MemToFb,
            mem: 0,
            local: 0x3FFF,
            words: 2,
        };
        assert_eq!(r.banks(), (0b11, 0));
        assert!(r.validate(1 << 16).is_ok());
        let bad = DmaRequest { local: 0xFFFF, ..r };
        assert!(bad.validate(1 << 16).is_err());
        let bad = DmaRequest { mem: 1, ..r };
        assert!(bad.validate(1 << 16).is_err());
        let bad = DmaRequest { mem: 0xFFFE, ..r };
        assert!(bad.validate(1 << 16).is_err());
        let c = DmaRequest {
            kind: DmaKind::MemToCtx,
            mem: 0,
            local: 4000,
            words: 200,
        };
        assert_eq!(c.banks(), (0, 0b11));
        assert!(DmaRequest { local: 8100, ..c }.validate(1 << 16).is_err());
    }
}
