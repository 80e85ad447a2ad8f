//! The fast paths: loops that run many cycles of the chip with less work
//! than [`Clocked::eval`] + [`Clocked::commit`] per cycle, each exactly the
//! cycles, states and statistics the plain model gives.
//! `tb/tests/conformance.rs` holds every one against plain stepping
//! (`Sim::step`) on every conformance program on both datapaths, and
//! `tb/tests/render.rs` on a tracer render per traversal
//! (`morphosys render --plain` runs the plain model).

use super::*;

impl<W: Word> Chip<W> {
    crate::simd::versions! {
        /// The fast path of a stall: while TinyRISC retries an instruction
        /// that waits for the array or the DMA (`rcany`, `wfb`, `dwait`, a full
        /// broadcast queue...), only the broadcast unit, the array and the DMA
        /// change, so their cycles are run without evaluating TinyRISC. Exactly
        /// the cycles [`Clocked::eval`] + [`Clocked::commit`] would give (the
        /// stall counters included); stops when the wait is over, the
        /// instruction word changed (a DMA store into the program), or after
        /// `limit` cycles. Returns the cycles run.
        pub fn run_stalled(&mut self, limit: u64) -> (u64, Result<(), Fault>);
        versions run_stalled_portable run_stalled_avx2 run_stalled_avx512;
        { self.run_stalled_sampled(limit, |_, _| true) }
    }

    /// The untraced fast path, tried by the cycle loop before a plain
    /// cycle. While the DMA is idle (main memory, the FB and the context
    /// memory then change only by TinyRISC's own writes) whole cycles run
    /// in [`Chip::run_local`]; otherwise stalled cycles run in
    /// [`Chip::run_stalled`]. Exactly the cycles [`Clocked::eval`] +
    /// [`Clocked::commit`] would give (tested against plain stepping on
    /// every conformance program); returns the cycles run (0: step one
    /// cycle).
    #[inline(always)]
    pub fn run_fast(&mut self, limit: u64) -> (u64, Result<(), Fault>) {
        if self.dma.idle() {
            return self.run_local(limit);
        }
        self.run_stalled(limit)
    }

    /// [`Chip::run_fast`] with a waveform: `sample` is called between
    /// each cycle's evaluation and its commit (`false`: stop before the
    /// commit). While the DMA is idle the cycles run in
    /// [`Chip::run_local`]'s loops, sampled one by one (multi-cycle
    /// instructions' busy cycles evaluated one at a time); otherwise in
    /// [`Chip::run_stalled_sampled`].
    #[inline(always)]
    pub fn run_fast_sampled(
        &mut self,
        limit: u64,
        sample: &mut dyn FnMut(&Self, u8) -> bool,
    ) -> (u64, Result<(), Fault>) {
        if self.dma.idle() {
            return self.run_local_sampled(limit, sample);
        }
        self.run_stalled_sampled(limit, sample)
    }

    crate::simd::versions! {
        /// Cycles while the DMA is idle, until it starts, TinyRISC halts, a
        /// fault, `limit`, or before a cycle at the stop PC of
        /// [`run_to_pc`]; three kinds, each with less to do than a plain
        /// cycle:
        ///
        /// * TinyRISC waits for the array while a run streams: the broadcast
        ///   unit and the array cycle alone, the stall counted at the end (a
        ///   stalled evaluation changes nothing, and nothing can change the
        ///   waiting instruction's word);
        /// * the array is idle and nothing is queued: TinyRISC alone, and its
        ///   multi-cycle instructions' busy cycles pass at once;
        /// * both work: TinyRISC, then the broadcast unit and the array (its
        ///   evaluation and clock edge in one call), in the order of
        ///   [`Clocked::eval`] and [`Clocked::commit`], without the DMA.
        fn run_local(&mut self, limit: u64) -> (u64, Result<(), Fault>);
        versions run_local_portable run_local_avx2 run_local_avx512;
        { self.local_cycles::<false, _>(limit, &mut |_: &Self, _| true) }
    }

    crate::simd::versions! {
        /// [`Chip::run_local`] sampled cycle by cycle (see
        /// [`Chip::run_fast_sampled`]).
        fn run_local_sampled(
            &mut self,
            limit: u64,
            sample: &mut dyn FnMut(&Self, u8) -> bool,
        ) -> (u64, Result<(), Fault>);
        versions run_local_sampled_portable run_local_sampled_avx2 run_local_sampled_avx512;
        { self.local_cycles::<true, _>(limit, sample) }
    }

    /// The loops of [`Chip::run_local`]; when `SAMPLED`, `sample` is
    /// called between every cycle's evaluation and its commit, and busy
    /// cycles are evaluated one by one.
    #[inline(always)]
    fn local_cycles<const SAMPLED: bool, S: FnMut(&Self, u8) -> bool + ?Sized>(
        &mut self,
        limit: u64,
        sample: &mut S,
    ) -> (u64, Result<(), Fault>) {
        use crate::tinyrisc::{State, Wait};
        let mut n = 0;
        // A stall evaluated before this call may wait on a word the DMA
        // has just rewritten: then it is evaluated again.
        let mut word_ok = self.mem.word(self.risc.pc) == Some(self.risc.ir);
        // The cycle before was one of TinyRISC alone, in this loop.
        let mut alone = false;
        while n < limit && !self.risc.halted() && self.risc.pc != self.stop_pc {
            let alone_before = std::mem::take(&mut alone);
            if self.bcast.idle() {
                // TinyRISC alone.
                let busy = self.risc.busy();
                if !SAMPLED && busy > 0 {
                    let b = (busy as u64).min(limit - n);
                    self.risc.skip_busy(b as u32);
                    self.idle_control += b;
                    self.cycles += b;
                    n += b;
                    continue;
                }
                if let Err(f) = self.eval_risc() {
                    return (n, Err(f));
                }
                word_ok = true;
                self.array.idle();
                if SAMPLED {
                    // Nothing but TinyRISC works in this cycle and did in
                    // the one before: the broadcast unit and the DMA were
                    // idle in both, nothing issued a run or a transfer
                    // between them (either ends TinyRISC's time alone),
                    // and the array, idle in both, was neither evaluated
                    // nor clocked since the last sample.
                    let go_on = sample(
                        self,
                        if alone_before {
                            super::UNCHANGED_ARRAY_SIDE
                        } else {
                            0
                        },
                    );
                    if !go_on {
                        break;
                    }
                }
                alone = true;
                if self.risc.state != State::StallDma {
                    self.idle_control += 1;
                }
            } else if word_ok
                && self.risc.state == State::StallArray
                && match self.risc.wait {
                    Wait::ArrayIdle => true,
                    Wait::Issue => !self.bcast.can_issue(),
                    _ => false,
                }
            {
                // The array streams while TinyRISC waits.
                let (k, r, stopped) = self.stream::<SAMPLED, S>(limit - n, sample);
                n += k;
                if r.is_err() {
                    return (n, r);
                }
                if SAMPLED && stopped {
                    break; // by the waveform
                }
                continue;
            } else {
                // Both.
                if let Err(f) = self.eval_risc() {
                    return (n, Err(f));
                }
                word_ok = true;
                match self.stream_one::<SAMPLED, S>(sample) {
                    Ok(Some(k)) => {
                        self.array_busy += 1;
                        self.active_rc += k;
                    }
                    Ok(None) => break,
                    Err(f) => return (n, Err(f)),
                }
            }
            let cmd = self.risc.cmd;
            self.apply(cmd);
            self.risc.commit();
            self.cycles += 1;
            n += 1;
            if matches!(cmd, Command::Dma(_)) {
                break;
            }
        }
        (n, Ok(()))
    }

    /// The array streams while TinyRISC waits for it (the stall of the
    /// last evaluation, `Wait::ArrayIdle` or `Wait::Issue`) and the DMA is
    /// idle: until the wait is over, `limit`, or (`SAMPLED`) `sample`
    /// stops it (the third value: whether it did).
    #[inline(always)]
    fn stream<const SAMPLED: bool, S: FnMut(&Self, u8) -> bool + ?Sized>(
        &mut self,
        limit: u64,
        sample: &mut S,
    ) -> (u64, Result<(), Fault>, bool) {
        use crate::tinyrisc::Wait;
        let wait = self.risc.wait;
        let mut n = 0;
        let mut active = 0u64;
        let mut err = None;
        let mut stopped = false;
        while n < limit
            && match wait {
                Wait::ArrayIdle => !self.bcast.idle(),
                _ => !self.bcast.can_issue(),
            }
        {
            if !SAMPLED {
                let (k, a, r) = self.bcast.stream_simd(
                    &self.ctx_mem,
                    &self.fb,
                    &mut self.array,
                    limit - n,
                    wait != Wait::ArrayIdle,
                    self.watch
                        .any
                        .then_some(|ctx, rcs| self.watch.count(ctx, rcs)),
                );
                n += k;
                active += a;
                if let Err(f) = r {
                    err = Some(self.locate(f));
                    break;
                }
                if k > 0 {
                    continue;
                }
            }
            // TinyRISC waits through the whole stream, neither evaluated
            // nor clocked: after the stream's first cycle it shows what
            // it showed in the cycle before.
            let unchanged = if n > 0 { super::UNCHANGED_RISC } else { 0 };
            let r = self.stream_cycle::<SAMPLED, S>(sample, unchanged);
            match r {
                Ok(Some(k)) => active += k as u64,
                Ok(None) => {
                    stopped = true;
                    break;
                }
                Err(f) => {
                    err = Some(f);
                    break;
                }
            }
            n += 1;
        }
        self.array_busy += n;
        self.active_rc += active;
        self.risc.add_stalled(n);
        self.cycles += n;
        match err {
            None => (n, Ok(()), stopped),
            Some(f) => (n, Err(f), stopped),
        }
    }

    /// One cycle of the broadcast unit and the array with the DMA idle:
    /// [`Broadcast::stream_simd`]'s when it runs it (untraced), else
    /// [`Chip::stream_cycle`]'s.
    #[inline(always)]
    fn stream_one<const SAMPLED: bool, S: FnMut(&Self, u8) -> bool + ?Sized>(
        &mut self,
        sample: &mut S,
    ) -> Result<Option<u64>, Fault> {
        if !SAMPLED {
            let (k, a, r) = self.bcast.stream_simd(
                &self.ctx_mem,
                &self.fb,
                &mut self.array,
                1,
                false,
                self.watch
                    .any
                    .then_some(|ctx, rcs| self.watch.count(ctx, rcs)),
            );
            if let Err(f) = r {
                return Err(self.locate(f));
            }
            if k == 1 {
                return Ok(Some(a));
            }
        }
        Ok(self.stream_cycle::<SAMPLED, S>(sample, 0)?.map(u64::from))
    }

    /// One cycle of the broadcast unit and the array with the DMA idle,
    /// evaluation and clock edge (the run's statistics to the caller):
    /// the RCs that executed; `None` when (`SAMPLED`) `sample`, called
    /// between the two, stopped it before the clock edge.
    #[inline(always)]
    fn stream_cycle<const SAMPLED: bool, S: FnMut(&Self, u8) -> bool + ?Sized>(
        &mut self,
        sample: &mut S,
        unchanged: u8,
    ) -> Result<Option<u32>, Fault> {
        if let Err(f) = self
            .bcast
            .eval(&self.ctx_mem, &self.fb, 0, 0, &mut self.array)
        {
            return Err(self.locate(f));
        }
        if SAMPLED {
            if let Err(f) = self.array.eval() {
                return Err(self.locate(f));
            }
            if !sample(self, unchanged) {
                return Ok(None);
            }
            self.array.commit();
        } else if let Err(f) = self.array.step() {
            return Err(self.locate(f));
        }
        if self.watch.any {
            self.count_watched();
        }
        self.bcast.commit();
        Ok(Some(self.array.active_now))
    }

    /// [`Chip::run_stalled`], calling `sample` between each cycle's
    /// evaluation and its commit (a waveform samples the cycle; `false`
    /// stops before the commit).
    #[inline(always)]
    pub fn run_stalled_sampled(
        &mut self,
        limit: u64,
        mut sample: impl FnMut(&Self, u8) -> bool,
    ) -> (u64, Result<(), Fault>) {
        use crate::tinyrisc::{State, Wait};
        let mut n = 0;
        while n < limit
            && matches!(self.risc.state, State::StallArray | State::StallDma)
            && match self.risc.wait {
                Wait::ArrayIdle => !self.bcast.idle(),
                Wait::Issue => !self.bcast.can_issue(),
                Wait::Dma => !self.dma.idle(),
                Wait::None => false,
            }
            && self.mem.read(self.risc.pc, 4) == self.risc.ir
        {
            if let Err(f) = self.bcast.eval(
                &self.ctx_mem,
                &self.fb,
                self.dma.owned_fb_banks(),
                self.dma.owned_ctx_banks(),
                &mut self.array,
            ) {
                return (n, Err(self.locate(f)));
            }
            if let Err(f) = self.array.eval() {
                return (n, Err(self.locate(f)));
            }
            if !sample(self, 0) {
                break;
            }
            // TinyRISC's stalled eval left no command and no write-back.
            self.commit();
            n += 1;
        }
        (n, Ok(()))
    }
}

/// [`run_to_halt`] for the 16-bit chip.
pub(crate) fn run_to_halt16(sim: &mut Sim<Chip<i16>>, max_cycles: u64) -> Result<u64, RunError> {
    run_loop(sim, max_cycles)
}

/// [`run_to_halt`] for the 32-bit chip.
pub(crate) fn run_to_halt32(sim: &mut Sim<Chip<i32>>, max_cycles: u64) -> Result<u64, RunError> {
    run_loop(sim, max_cycles)
}

fn run_loop<W: Word>(sim: &mut Sim<Chip<W>>, max_cycles: u64) -> Result<u64, RunError> {
    if sim.tracing() {
        return run_loop_traced(sim, max_cycles);
    }
    cycles::<W, false>(sim, max_cycles)
}

/// [`run_loop`] with a waveform: out of line, so that the untraced loop
/// is compiled without the tracing's code in it (inlined together, the
/// inliner leaves the cycle's parts out of line, and the untraced loop
/// runs slower).
#[inline(never)]
fn run_loop_traced<W: Word>(sim: &mut Sim<Chip<W>>, max_cycles: u64) -> Result<u64, RunError> {
    cycles::<W, true>(sim, max_cycles)
}

/// The cycle loop, stalled cycles through the fast path (sampled when
/// `TRACED`).
#[inline(always)]
fn cycles<W: Word, const TRACED: bool>(
    sim: &mut Sim<Chip<W>>,
    max_cycles: u64,
) -> Result<u64, RunError> {
    while !sim.top.halted() && sim.top.risc.pc != sim.top.stop_pc {
        if sim.cycle() >= max_cycles {
            return Err(over_budget(sim));
        }
        let limit = max_cycles - sim.cycle();
        let stalled = if TRACED {
            sim.fast_forward_sampled(|c, sample| c.run_fast_sampled(limit, sample))
        } else {
            sim.fast_forward(|c| c.run_fast(limit))
        };
        if stalled.map_err(RunError::Step)? > 0 {
            continue;
        }
        sim.step().map_err(RunError::Step)?;
    }
    Ok(sim.cycle())
}
