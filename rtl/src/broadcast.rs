//! The context broadcast unit: streams a run of contexts from the context
//! memory to the array, one context (SIMD) or one 8-word group (row or
//! column mode) per cycle, with the frame-buffer data of each set.
//!
//! TinyRISC issues a [`Run`] (`cbcast`, `sbcb`, `dbcb`, `cbcr`, `cbcc`) in
//! one cycle; the run's first context executes in the next cycle and the
//! run occupies the array for `count` consecutive cycles. The unit holds the
//! run in progress and **one queued run**: TinyRISC can issue the next run
//! while the current one streams (it stalls only when the queue is full), so
//! back-to-back runs execute without a bubble.
//!
//! **FB streams.** A run may stream one FB set (`sbcb`) or both (`dbcb`).
//! The stream of set `s` starts at the run's FB address; each cycle the
//! array reads `fbs` it sees the word at the stream pointer, and the pointer
//! advances by one after every context that reads `fbs` (contexts that do
//! not read the FB leave it). A context that reads `fbs` in a run that does
//! not stream set `s`, a stream that runs out of its set, and a read of a
//! bank the DMA owns are faults.
//!
//! **Cuts.** A run ends early after a `cut` context ([`Context::CUT`], a
//! `nop` to the RCs) where no awake RC has F: the unit reads the 64 flags
//! as `rcany` does, in the cut's own cycle, and the queued run, if any,
//! starts in the next. A kernel that knows early that no ray can go on (an
//! object test whose rays all miss) thus stops without TinyRISC's status
//! read; a cut where some awake RC has F costs its one cycle. Row and
//! column runs have no cuts (a `cut` word there is a `nop`).

use crate::array::{Array, Mode};
use crate::context_memory::{self, ContextMemory};
use crate::fb::{self, FrameBuffer};
use crate::kernel::Fault;
use crate::rc::context::{ASrc, Context};
use crate::rc::Word;

/// A run of contexts, as TinyRISC issues it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Run {
    pub mode: Mode,
    /// First context-memory address (8-aligned in row/column mode).
    pub ctx: u16,
    /// Number of contexts (SIMD) or of 8-word groups (row/column mode).
    pub count: u16,
    /// FB stream start address of each set, if the run streams it.
    pub fb: [Option<u16>; 2],
    /// PC of the issuing instruction.
    pub pc: u32,
}

impl Run {
    /// Context-memory words the run reads.
    pub fn words(&self) -> u32 {
        self.count as u32 * if self.mode == Mode::Simd { 1 } else { 8 }
    }

    /// Range and form check, at issue.
    pub fn validate(&self) -> Result<(), String> {
        if self.ctx as u32 + self.words() > context_memory::WORDS as u32 {
            return Err(format!(
                "context run 0x{:04x}+{} words past the end of context memory (0..0x{:x})",
                self.ctx,
                self.words(),
                context_memory::WORDS
            ));
        }
        if self.mode != Mode::Simd && !self.ctx.is_multiple_of(8) {
            return Err(format!(
                "row/column-mode run at context address 0x{:04x} is not 8-aligned",
                self.ctx
            ));
        }
        for s in 0..2 {
            if let Some(a) = self.fb[s] {
                if fb::set(a) != s {
                    return Err(format!(
                        "FB stream of set {s} starts at 0x{a:04x}, which is in set {}",
                        fb::set(a)
                    ));
                }
            }
        }
        Ok(())
    }
}

#[derive(Clone, Copy, Debug)]
struct Current {
    run: Run,
    k: u16,
    ptr: [u16; 2],
}

#[derive(Default)]
pub struct Broadcast {
    cur: Option<Current>,
    queued: Option<Run>,
    // next state of `cur`, computed by eval
    d_ptr: [u16; 2],
    /// The run ends at this clock edge: a cut with no awake RC's F.
    d_cut: bool,
    /// Context words driven this cycle (for waveforms).
    pub word: u32,
    /// Contexts (SIMD) or groups executed.
    pub steps: u64,
}

impl Broadcast {
    /// Can TinyRISC issue a run this cycle?
    #[inline(always)]
    pub fn can_issue(&self) -> bool {
        self.queued.is_none()
    }

    /// Nothing running and nothing queued.
    #[inline(always)]
    pub fn idle(&self) -> bool {
        self.cur.is_none() && self.queued.is_none()
    }

    /// The run in progress, its step and FB pointers.
    pub fn current(&self) -> Option<(Run, u16, [u16; 2])> {
        self.cur.map(|c| (c.run, c.k, c.ptr))
    }

    /// Issue a validated run (clock edge of the issuing cycle).
    pub fn issue(&mut self, run: Run) {
        if run.count == 0 {
            return;
        }
        if self.cur.is_none() {
            self.cur = Some(Self::start(run));
        } else {
            debug_assert!(self.queued.is_none());
            self.queued = Some(run);
        }
    }

    fn start(run: Run) -> Current {
        Current {
            run,
            k: 0,
            ptr: [run.fb[0].unwrap_or(0), run.fb[1].unwrap_or(0x8000)],
        }
    }

    fn fault(run: &Run, addr: u16, msg: String) -> Fault {
        Fault::new(
            "broadcast",
            format!(
                "{msg} (context 0x{addr:04x} of the run issued at pc 0x{:08x})",
                run.pc
            ),
        )
    }

    /// Drive the array for this cycle: fetch the context(s) and FB data.
    #[inline(always)]
    pub fn eval<W: Word>(
        &mut self,
        cm: &ContextMemory,
        fbm: &FrameBuffer<W>,
        dma_fb_banks: u8,
        dma_ctx_banks: u8,
        array: &mut Array<W>,
    ) -> Result<(), Fault> {
        let Some(cur) = &self.cur else {
            array.idle();
            return Ok(());
        };
        // The fields the cycle needs first, read from the unit itself
        // rather than from the copy of the run (a narrow load from a wide
        // store just made stalls the forwarding).
        let (mode, first, k) = (cur.run.mode, cur.run.ctx, cur.k);
        let run = cur.run;
        let simd = mode == Mode::Simd;
        let addr = first + if simd { k } else { k * 8 };
        if dma_ctx_banks >> context_memory::bank(addr) & 1 != 0 {
            return Err(Self::fault(
                &run,
                addr,
                format!(
                    "DMA conflict: the array reads context bank {} while DMA loads it",
                    context_memory::bank(addr)
                ),
            ));
        }
        let get = |a: u16| -> Result<&Context, Fault> {
            cm.context(a).map_err(|e| {
                Self::fault(
                    &run,
                    a,
                    format!("{e} in context memory (word 0x{:08x})", cm.word(a)),
                )
            })
        };
        if simd {
            // the hot path: one context
            let c = get(addr)?;
            self.d_ptr = cur.ptr;
            self.word = cm.word(addr);
            self.d_cut = self.word == Context::CUT_WORD && !array.any_awake_f();
            // Built whole from the datum (a store into one half of the pair
            // read back at once as the whole pair stalls the forwarding).
            let fbd = if c.asrc == ASrc::Fb {
                let s = (c.ra & 1) as usize;
                let v = self.stream(s, &run, addr, fbm, dma_fb_banks)?;
                if s == 0 {
                    [v, W::ZERO]
                } else {
                    [W::ZERO, v]
                }
            } else {
                [W::ZERO; 2]
            };
            array.drive_simd(self.word, c, fbd);
            return Ok(());
        }
        let mut reads = 0u8;
        let mut group = [Context::NOP; 8];
        for (g, c) in group.iter_mut().enumerate() {
            *c = *get(addr + g as u16)?;
            if c.asrc == ASrc::Fb {
                reads |= 1 << (c.ra & 1);
            }
        }
        let mut fbd = [W::ZERO; 2];
        self.d_ptr = cur.ptr;
        self.d_cut = false;
        for (s, d) in fbd.iter_mut().enumerate() {
            if reads >> s & 1 != 0 {
                *d = self.stream(s, &run, addr, fbm, dma_fb_banks)?;
            }
        }
        let words: [u32; 8] = std::array::from_fn(|g| cm.word(addr + g as u16));
        self.word = words[0];
        array.drive_group(run.mode, words, group, fbd);
        Ok(())
    }

    /// The untraced streaming loop of SIMD runs, with the DMA idle and
    /// nothing sampled between a cycle's evaluation and its clock edge:
    /// whole cycles ([`Broadcast::eval`], [`Array::step`],
    /// [`Broadcast::commit`]) without the checks that cannot fail then (no
    /// bank is the DMA's). Stops before a cycle it does not run this way (a
    /// row or column run, a context word that does not decode, an FB read
    /// that faults: the unit's own evaluation reports those), when nothing
    /// streams, with `until_issue` when the queue empties, after `limit`
    /// cycles, or at a fault. `on_start`, if any, is called after the
    /// first context of each run with its address and the RCs that
    /// executed it (where the chip's cycle counts it). Returns the cycles
    /// run and the RCs that executed in them.
    #[inline(always)]
    pub fn stream_simd<W: Word>(
        &mut self,
        cm: &ContextMemory,
        fbm: &FrameBuffer<W>,
        array: &mut Array<W>,
        limit: u64,
        until_issue: bool,
        mut on_start: Option<impl FnMut(u16, u32)>,
    ) -> (u64, u64, Result<(), Fault>) {
        let (mut n, mut active) = (0, 0u64);
        while n < limit {
            let Some(cur) = &mut self.cur else { break };
            if cur.run.mode != Mode::Simd || (until_issue && self.queued.is_none()) {
                break;
            }
            let addr = cur.run.ctx + cur.k;
            let Ok(c) = cm.context(addr) else { break };
            // written before the FB stream's check, as `eval` writes them
            self.d_ptr = cur.ptr;
            let word = cm.word(addr);
            self.word = word;
            let r = if c.asrc == ASrc::Fb {
                let s = (c.ra & 1) as usize;
                let p = cur.ptr[s];
                if cur.run.fb[s].is_none() || fb::set(p) != s {
                    break;
                }
                let p1 = p.wrapping_add(1);
                self.d_ptr[s] = p1;
                cur.ptr[s] = p1;
                let v = fbm.read(p);
                array.step_simd(word, c, if s == 0 { [v, W::ZERO] } else { [W::ZERO, v] })
            } else {
                array.step_simd(word, c, [W::ZERO; 2])
            };
            match r {
                Ok(k) => {
                    active += k as u64;
                    if let Some(f) = on_start.as_mut().filter(|_| cur.k == 0) {
                        f(cur.run.ctx, k);
                    }
                }
                Err(f) => return (n, active, Err(f)),
            }
            self.steps += 1;
            cur.k += 1;
            if cur.k == cur.run.count || word == Context::CUT_WORD && !array.any_awake_f() {
                self.cur = self.queued.take().map(Self::start);
            }
            n += 1;
        }
        (n, active, Ok(()))
    }

    /// Read the next datum of FB stream `s` (and advance its pointer in the
    /// next state). The checks in one test; their messages out of line.
    #[inline(always)]
    fn stream<W: Word>(
        &mut self,
        s: usize,
        run: &Run,
        addr: u16,
        fbm: &FrameBuffer<W>,
        dma_fb_banks: u8,
    ) -> Result<W, Fault> {
        let p = self.d_ptr[s];
        if run.fb[s].is_none() || fb::set(p) != s || dma_fb_banks >> fb::bank(p) & 1 != 0 {
            return Err(Self::stream_fault(s, run, addr, p, dma_fb_banks));
        }
        self.d_ptr[s] = p.wrapping_add(1);
        Ok(fbm.read(p))
    }

    /// Why stream `s` cannot give its next datum at `p`.
    #[cold]
    #[inline(never)]
    fn stream_fault(s: usize, run: &Run, addr: u16, p: u16, dma_fb_banks: u8) -> Fault {
        if run.fb[s].is_none() {
            return Self::fault(
                run,
                addr,
                format!("context reads fb{s} but the run streams no data of FB set {s}"),
            );
        }
        if fb::set(p) != s {
            return Self::fault(
                run,
                addr,
                format!("FB stream of set {s} ran past the end of the set"),
            );
        }
        debug_assert!(dma_fb_banks >> fb::bank(p) & 1 != 0);
        Self::fault(
            run,
            addr,
            format!(
                "DMA conflict: the array reads FB bank {} (address 0x{p:04x}) while DMA transfers it",
                fb::bank(p)
            ),
        )
    }

    /// Clock edge: advance the run; start the queued one when it ends
    /// (its last context, or a cut that ends it).
    #[inline]
    pub fn commit(&mut self) {
        if let Some(cur) = &mut self.cur {
            self.steps += 1;
            cur.ptr = self.d_ptr;
            cur.k += 1;
            let cut = std::mem::take(&mut self.d_cut);
            if cur.k == cur.run.count || cut {
                self.cur = self.queued.take().map(Self::start);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::Clocked;
    use crate::rc::context::{BSrc, Op};

    fn ctx(op: Op, asrc: ASrc, ra: u8, b: BSrc) -> Context {
        Context {
            op,
            we: true,
            rd: 1,
            asrc,
            ra,
            b,
            ..Context::NOP
        }
    }

    fn run(mode: Mode, ctx: u16, count: u16, fb: [Option<u16>; 2]) -> Run {
        Run {
            mode,
            ctx,
            count,
            fb,
            pc: 0x40,
        }
    }

    /// Step the unit and the array once.
    fn step(
        b: &mut Broadcast,
        cm: &ContextMemory,
        fbm: &FrameBuffer,
        a: &mut Array<i16>,
        dma_fb: u8,
    ) -> Result<(), Fault> {
        b.eval(cm, fbm, dma_fb, 0, a)?;
        a.eval()?;
        a.commit();
        b.commit();
        Ok(())
    }

    #[test]
    fn the_stream_advances_only_after_contexts_that_read_it_and_runs_queue() {
        let mut cm = ContextMemory::default();
        let mut fbm = FrameBuffer::default();
        fbm.fill(0x0010, &[5, 7, 11]);
        // add r1, fb0, r1 ; nop ; add r1, fb0, r1 ; add r1, fb0, r1
        let k = [
            ctx(Op::Add, ASrc::Fb, 0, BSrc::Reg(1)),
            Context::NOP,
            ctx(Op::Add, ASrc::Fb, 0, BSrc::Reg(1)),
            ctx(Op::Add, ASrc::Fb, 0, BSrc::Reg(1)),
        ];
        for (i, c) in k.iter().enumerate() {
            cm.write(i as u16, c.encode());
        }
        let mut a = Array::new();
        let mut b = Broadcast::default();
        assert!(b.idle() && b.can_issue());
        b.issue(run(Mode::Simd, 0, 4, [Some(0x0010), None]));
        b.issue(run(Mode::Simd, 0, 1, [Some(0x0012), None]));
        assert!(!b.can_issue());
        for _ in 0..5 {
            step(&mut b, &cm, &fbm, &mut a, 0).unwrap();
        }
        assert!(b.idle());
        // 5 + 7 + 11, then + 11 from the queued run
        assert_eq!(a.rc.regs.read(1)[0], 34);
        assert_eq!(b.steps, 5);
    }

    #[test]
    fn stream_faults() {
        let mut cm = ContextMemory::default();
        let fbm = FrameBuffer::default();
        cm.write(0, ctx(Op::Add, ASrc::Fb, 1, BSrc::Reg(1)).encode());
        let mut a = Array::new();
        // reads fb1, the run streams set 0 only
        let mut b = Broadcast::default();
        b.issue(run(Mode::Simd, 0, 1, [Some(0), None]));
        let e = step(&mut b, &cm, &fbm, &mut a, 0).unwrap_err();
        assert!(e.message.contains("streams no data of FB set 1"), "{e}");
        assert!(e.message.contains("pc 0x00000040"), "{e}");
        // the stream of set 1 at its last word, read twice
        cm.write(1, ctx(Op::Add, ASrc::Fb, 1, BSrc::Reg(1)).encode());
        let mut b = Broadcast::default();
        b.issue(run(Mode::Simd, 0, 2, [None, Some(0xFFFF)]));
        step(&mut b, &cm, &fbm, &mut a, 0).unwrap();
        let e = step(&mut b, &cm, &fbm, &mut a, 0).unwrap_err();
        assert!(e.message.contains("ran past the end of the set"), "{e}");
        // a bank the DMA owns
        let mut b = Broadcast::default();
        b.issue(run(Mode::Simd, 0, 1, [None, Some(0xC000)]));
        let e = step(&mut b, &cm, &fbm, &mut a, 0b1000).unwrap_err();
        assert!(e.message.contains("DMA conflict"), "{e}");
        // validation at issue
        assert!(run(Mode::Row, 4, 1, [None, None]).validate().is_err());
        assert!(run(Mode::Simd, 8190, 3, [None, None]).validate().is_err());
        assert!(run(Mode::Simd, 0, 1, [Some(0x8000), None])
            .validate()
            .is_err());
    }
}
