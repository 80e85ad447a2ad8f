//! The walks of the chip: [`Declaring`] once, then [`Sampler`] each traced
//! cycle, comparing each 64 calls' values with the last ones written.

use std::io;

use super::super::format::{Decl, SigId, SigInfo, NOT_TRACED};
use super::super::handoff::MSG_CHUNK;
use super::super::sink::changed_mask;
use super::super::{scope_runs, Display, Field, Probe};
use super::Tracer;
use std::fmt;

/// The declaration's walk ([`Tracer::create`]): each [`Probe`] call
/// declares what it reports and records in the tracer's tables what the
/// sampled walks ([`Sampler`]) replay.
pub(in crate::trace) struct Declaring<'a>(pub(in crate::trace) &'a mut Tracer);

impl Probe for Declaring<'_> {
    fn block_versioned(
        &mut self,
        version: u64,
        fields: &dyn Fn() -> Vec<Field>,
        _fill: &mut dyn FnMut(&mut [u64]),
    ) {
        self.0.declare_versioned(version, fields);
    }

    fn block(&mut self, fields: &dyn Fn() -> Vec<Field>, values: &[u64]) {
        let n = self.0.declare_block(fields, values);
        self.0.block_n.push(n as u32);
    }

    fn signal_row(&mut self, names: &[&str], width: u32, display: Display, _values: &[u64]) {
        for n in names {
            self.0.declare_signal(n, width, display);
        }
    }

    fn traced_signals(&mut self, names: &[&str]) -> u64 {
        self.0
            .declare_mask(names.len(), &mut |i| names[i].to_string(), true)
    }

    fn open_scopes(&mut self, n: usize, name: &mut dyn FnMut(usize) -> String) -> u64 {
        self.0.declare_mask(n, name, false)
    }

    fn scope(&mut self, name: fmt::Arguments<'_>) -> bool {
        self.0.declare_scope(name)
    }

    fn end(&mut self) {
        self.0.declare_end();
    }

    fn section(&mut self, _unchanged: bool) -> bool {
        self.0.declare_section();
        true
    }

    fn end_section(&mut self) {
        self.0.declare_end_section();
    }

    fn signal(&mut self, name: &str, width: u32, display: Display, _value: u64) {
        self.0.declare_signal(name, width, display);
    }
}

/// A sampled cycle's walk ([`Tracer::sample`]): each [`Probe`] call only
/// moves on through the tables the declaration made and copies the
/// values it reports, with no test of a phase. A section skipped moves
/// on to where it ends, a copy: when it added its counts, the compiler
/// added the six indices with vector instructions that loaded them right
/// after the calls before had stored them one by one, a store the
/// processor cannot forward; the copy avoids it (docs/performance.md).
pub(in crate::trace) struct Sampler<'a> {
    pub(in crate::trace) scope_on: &'a [bool],
    pub(in crate::trace) open_masks: &'a [u64],
    /// Per [`Probe::block_versioned`]: the version last sampled and the
    /// block's size.
    pub(in crate::trace) versions: &'a mut [(u64, usize)],
    pub(in crate::trace) block_n: &'a [u32],
    pub(in crate::trace) sections: &'a [Progress],
    /// A word per signal call: the value reported in this cycle (a block
    /// or section skipped leaves the last one).
    pub(in crate::trace) cur: &'a mut [u64],
    /// Every call counts as changed (the first cycle sampled).
    pub(in crate::trace) first: bool,
    /// The calls of each table so far.
    pub(in crate::trace) at: Progress,
    /// A block reported that was not declared.
    pub(in crate::trace) undeclared: bool,
    /// [`Probe::unchanged`] of this sample.
    pub(in crate::trace) unchanged: u8,
}

impl Sampler<'_> {
    /// The next signal calls reported `values`.
    #[inline]
    pub(in crate::trace) fn calls(&mut self, values: &[u64]) {
        let start = self.at.slots;
        self.at.slots += values.len();
        if let Some(cur) = self.cur.get_mut(start..start + values.len()) {
            cur.copy_from_slice(values);
        } // else more calls than declared: reported after the walk
    }

    /// The next answer of [`Probe::open_scopes`] or
    /// [`Probe::traced_signals`], in the order they were declared.
    #[inline]
    pub(in crate::trace) fn next_mask(&mut self) -> u64 {
        let m = self.open_masks.get(self.at.masks).copied().unwrap_or(0);
        self.at.masks += 1;
        m
    }
}

impl Probe for Sampler<'_> {
    #[inline]
    fn unchanged(&self) -> u8 {
        self.unchanged
    }

    fn block_versioned(
        &mut self,
        version: u64,
        _fields: &dyn Fn() -> Vec<Field>,
        fill: &mut dyn FnMut(&mut [u64]),
    ) {
        let Some(v) = self.versions.get_mut(self.at.versions) else {
            self.undeclared = true;
            return;
        };
        let (last, n) = *v;
        v.0 = version;
        self.at.versions += 1;
        let start = self.at.slots;
        self.at.slots += n;
        if n == 0 || (version == last && !self.first) {
            // Nothing traced, or unchanged: the values last written still
            // hold.
            return;
        }
        if let Some(cur) = self.cur.get_mut(start..start + n) {
            fill(cur);
        }
    }

    fn block(&mut self, _fields: &dyn Fn() -> Vec<Field>, values: &[u64]) {
        let n = self.block_n.get(self.at.blocks).copied();
        self.at.blocks += 1;
        if n != Some(0) {
            self.calls(values);
        }
    }

    #[inline]
    fn block_with<const N: usize>(
        &mut self,
        _fields: &dyn Fn() -> Vec<Field>,
        fill: impl FnOnce(&mut [u64; N]),
    ) {
        let n = self.block_n.get(self.at.blocks).copied();
        self.at.blocks += 1;
        if n == Some(0) {
            return;
        }
        let start = self.at.slots;
        self.at.slots += N;
        if let Some(cur) = self
            .cur
            .get_mut(start..start + N)
            .and_then(|c| <&mut [u64; N]>::try_from(c).ok())
        {
            fill(cur);
        } // else more calls than declared: reported after the walk
    }

    fn signal_row(&mut self, names: &[&str], _width: u32, _display: Display, values: &[u64]) {
        self.calls(&values[..names.len()]);
    }

    fn traced_signals(&mut self, _names: &[&str]) -> u64 {
        self.next_mask()
    }

    fn open_scopes(&mut self, _n: usize, _name: &mut dyn FnMut(usize) -> String) -> u64 {
        self.next_mask()
    }

    fn scope(&mut self, _name: fmt::Arguments<'_>) -> bool {
        let on = self.scope_on.get(self.at.scopes).copied().unwrap_or(false);
        self.at.scopes += 1;
        on
    }

    fn end(&mut self) {}

    fn section(&mut self, unchanged: bool) -> bool {
        let end = self.sections.get(self.at.sections).copied();
        match end {
            Some(end) if unchanged && !self.first => {
                // The values of its calls are those in `cur` already: on
                // to where it ends.
                self.at = end;
                false
            }
            _ => {
                self.at.sections += 1;
                true
            }
        }
    }

    fn end_section(&mut self) {}

    #[inline]
    fn signal(&mut self, _name: &str, _width: u32, _display: Display, value: u64) {
        self.calls(&[value]);
    }
}

/// The declaring halves of the [`Probe`] calls.
impl Tracer {
    #[cold]
    #[inline(never)]
    pub(in crate::trace) fn declare_versioned(
        &mut self,
        version: u64,
        fields: &dyn Fn() -> Vec<Field>,
    ) {
        let n = self.declare_block(fields, &vec![0; fields().len()]);
        self.versions.push((version, n));
    }

    /// The scopes and signals [`Probe::block`] describes, with a slot for
    /// every field (those of scopes left out untraced), as the sampled
    /// cycles report every value; a block none of whose fields is traced
    /// takes no slot (its values are not kept, and the comparison after
    /// the walk has fewer to look at: a trace of the default scope went
    /// from 68 calls to 52, two chunks of 64 to one). The slots it takes.
    #[cold]
    #[inline(never)]
    pub(in crate::trace) fn declare_block(
        &mut self,
        fields: &dyn Fn() -> Vec<Field>,
        values: &[u64],
    ) -> usize {
        let fields = fields();
        let (slots, decls) = (self.masks.len(), self.decls.len());
        for (scope, run) in scope_runs(&fields) {
            let open = scope.is_empty() || self.enter_scope(scope.to_string());
            for f in &fields[run] {
                if open {
                    self.declare_signal(f.name, f.width, f.display);
                } else {
                    self.untraced_slot();
                }
            }
            if open && !scope.is_empty() {
                self.declare_end();
            }
        }
        if values.len() != fields.len() {
            self.err.get_or_insert(io::Error::other(format!(
                "a block of {} signals reported {} values",
                fields.len(),
                values.len()
            )));
        }
        if self.decls.len() == decls {
            self.masks.truncate(slots);
            self.slot_decl.truncate(slots);
            return 0;
        }
        fields.len()
    }

    /// The calls of each table declared so far.
    pub(in crate::trace) fn progress(&self) -> Progress {
        Progress {
            scopes: self.scope_on.len(),
            slots: self.masks.len(),
            blocks: self.block_n.len(),
            masks: self.open_masks.len(),
            versions: self.versions.len(),
            sections: self.sections.len(),
        }
    }

    #[cold]
    #[inline(never)]
    pub(in crate::trace) fn declare_section(&mut self) {
        self.sections.push(Progress::default());
        self.open_sections.push(self.sections.len() - 1);
    }

    #[cold]
    #[inline(never)]
    pub(in crate::trace) fn declare_end_section(&mut self) {
        let Some(i) = self.open_sections.pop() else {
            self.err.get_or_insert(io::Error::other(
                "a module ended a section it did not begin",
            ));
            return;
        };
        self.sections[i] = self.progress();
    }

    #[cold]
    #[inline(never)]
    pub(in crate::trace) fn declare_scope(&mut self, name: fmt::Arguments<'_>) -> bool {
        let on = self.enter_scope(name.to_string());
        self.scope_on.push(on);
        on
    }

    /// Enter scope `name` while declaring if the patterns may take in
    /// something under it (then the caller leaves it with
    /// [`Tracer::declare_end`]); whether it did.
    pub(in crate::trace) fn enter_scope(&mut self, name: String) -> bool {
        self.stack.push(name);
        if self.stack.len() == 1 && !self.top_scopes.contains(&self.stack[0]) {
            self.top_scopes.push(self.stack[0].clone());
        }
        let on = self.matches_prefix(&self.stack, false);
        if on {
            if let Err(e) = self.w.add_module(self.stack.last().unwrap()) {
                self.err.get_or_insert(e);
            }
        } else {
            self.stack.pop();
        }
        on
    }

    #[cold]
    #[inline(never)]
    pub(in crate::trace) fn declare_end(&mut self) {
        self.stack.pop();
        if let Err(e) = self.w.upscope() {
            self.err.get_or_insert(e);
        }
    }
}

impl Tracer {
    /// Which of `n` names under the current scope the patterns take in
    /// (`complete`: as signals, else as scopes that may hold some):
    /// computed while declaring, replayed in the same order while sampling
    /// ([`Sampler::next_mask`]).
    #[cold]
    #[inline(never)]
    pub(in crate::trace) fn declare_mask(
        &mut self,
        n: usize,
        name: &mut dyn FnMut(usize) -> String,
        complete: bool,
    ) -> u64 {
        let mut mask = 0u64;
        for i in 0..n.min(64) {
            let mut path = self.stack.clone();
            path.push(name(i));
            if path.len() == 1 && !self.top_scopes.contains(&path[0]) {
                self.top_scopes.push(path[0].clone());
            }
            if self.matches_prefix(&path, complete) {
                mask |= 1 << i;
            }
        }
        self.open_masks.push(mask);
        mask
    }

    #[cold]
    #[inline(never)]
    pub(in crate::trace) fn declare_signal(&mut self, name: &str, width: u32, display: Display) {
        let mut path = self.stack.clone();
        path.push(name.to_string());
        if self.matches_prefix(&path, true) {
            let id = match self.w.add_wire(width, name) {
                Ok(id) => id,
                Err(e) => {
                    self.err.get_or_insert(e);
                    SigId::Vcd(0)
                }
            };
            self.masks.push(u64::MAX >> (64 - width.clamp(1, 64)));
            self.slot_decl.push(self.decls.len() as u32);
            self.decls.push(Decl {
                path,
                info: SigInfo { id, width, display },
            });
        } else {
            self.untraced_slot();
        }
    }

    /// A signal call that is not traced: its value is masked to 0.
    pub(in crate::trace) fn untraced_slot(&mut self) {
        self.masks.push(0);
        self.slot_decl.push(NOT_TRACED);
    }

    crate::simd::versions! {
        /// Write the values of the cycle's walk that changed (all traced
        /// ones the first time): per chunk of 64 calls, the mask of those that
        /// changed and their values queued as one message ([`MSG_CHUNK`]).
        pub(in crate::trace) fn write_changes(&mut self) -> ();
        versions write_changes_portable write_changes_avx2 write_changes_avx512;
        {
            let first = std::mem::take(&mut self.first_sample);
            let padded = self.n_slots.next_multiple_of(64);
            let hot = self.hot.get_mut(self.hot_at..).unwrap_or_default();
            let (cur, rest) = hot.split_at_mut(padded.min(hot.len()));
            let (masks, lasts) = rest.split_at_mut(padded.min(rest.len()));
            let (cur, _) = cur.as_chunks::<64>();
            let (masks, _) = masks.as_chunks::<64>();
            let (lasts, _) = lasts.as_chunks_mut::<64>();
            let (costs, _) = self.costs.as_chunks::<64>();
            // Indexed, not zipped: the zip's length (the least of four) took
            // a chain of vector instructions in front of every sample.
            let mut left = self.n_slots;
            let mut j = 0;
            while left > 0 {
                // The groups of 8 calls that hold declared ones (the padding
                // after the last holds none).
                let groups = left.min(64).div_ceil(8);
                left = left.saturating_sub(64);
                let chunk = Chunk {
                    c: &cur[j],
                    m: &masks[j],
                    l: &mut lasts[j],
                    cost: &costs[j],
                };
                self.bytes += chunk.changes(&mut self.batch, j as u64, first, groups);
                j += 1;
            }
    }
    }
}

/// The calls of each of the tracer's per-call tables made so far in a
/// walk (or by the end of a [`Probe::section`]).
#[derive(Clone, Copy, Default)]
pub(in crate::trace) struct Progress {
    pub(in crate::trace) scopes: usize,
    pub(in crate::trace) slots: usize,
    pub(in crate::trace) blocks: usize,
    pub(in crate::trace) masks: usize,
    pub(in crate::trace) versions: usize,
    pub(in crate::trace) sections: usize,
}

/// A chunk of 64 signal calls in a sampled cycle: the values the walk
/// reported, the masks of their widths (0 for a call not traced), the
/// values last written, and the bytes a change of each adds (about).
pub(in crate::trace) struct Chunk<'a> {
    pub(in crate::trace) c: &'a [u64; 64],
    pub(in crate::trace) m: &'a [u64; 64],
    pub(in crate::trace) l: &'a mut [u64; 64],
    pub(in crate::trace) cost: &'a [u8; 64],
}

impl Chunk<'_> {
    /// Queue the chunk's changes (every traced call if `first`) as chunk
    /// `j`'s message, if any, and keep the new values; the bytes they add.
    ///
    /// With AVX-512 eight calls at a time, without a branch per change:
    /// the values compared into a mask register, those that changed
    /// packed together by one instruction (`vpcompressq`) and stored as 8
    /// words wherever the last ones ended (the batch keeps room beyond a
    /// cycle's most for the last store), their costs summed by two more.
    /// One change at a time (`changes_portable`, what other CPUs run) is
    /// slower, and comparing first and packing in a second pass is no
    /// faster than that.
    #[inline(always)]
    pub(in crate::trace) fn changes(
        self,
        batch: &mut Vec<u64>,
        j: u64,
        first: bool,
        groups: usize,
    ) -> u64 {
        #[cfg(target_arch = "x86_64")]
        if crate::simd::avx512() {
            // SAFETY: the AVX-512 path runs only on a CPU that has it.
            return unsafe { self.changes_avx512(batch, j, first, groups) };
        }
        let _ = groups;
        self.changes_portable(batch, j, first)
    }

    /// [`Chunk::changes`] with AVX-512.
    #[cfg(target_arch = "x86_64")]
    #[inline]
    #[target_feature(enable = "avx512f,avx512bw")]
    fn changes_avx512(self, batch: &mut Vec<u64>, j: u64, first: bool, groups: usize) -> u64 {
        use std::arch::x86_64::*;
        let Chunk { c, m, l, cost } = self;
        let len = batch.len();
        let spare = batch.spare_capacity_mut();
        // Reserved: the message, the mask and 64 values, the last 8
        // stored whole.
        assert!(spare.len() >= 66, "the batch keeps room for a chunk");
        let dst = spare.as_mut_ptr().cast::<u64>();
        let mut n = 2;
        let mut bits = 0u64;
        // SAFETY: every load and store of the 8 groups lies inside the
        // 64 words of `c`, `m` or `l`, or inside the batch's spare
        // capacity (`n` <= 58 before a store of 8 words, 66 checked
        // above); the first `n` words after `len` are all written
        // before `set_len`.
        unsafe {
            for g in 0..groups.min(8) {
                let mg = _mm512_loadu_si512(m.as_ptr().add(8 * g).cast());
                let v = _mm512_and_si512(_mm512_loadu_si512(c.as_ptr().add(8 * g).cast()), mg);
                let k = if first {
                    _mm512_test_epi64_mask(mg, mg)
                } else {
                    _mm512_cmpneq_epi64_mask(v, _mm512_loadu_si512(l.as_ptr().add(8 * g).cast()))
                };
                _mm512_mask_storeu_epi64(l.as_mut_ptr().add(8 * g).cast(), k, v);
                _mm512_storeu_si512(dst.add(n).cast(), _mm512_maskz_compress_epi64(k, v));
                n += k.count_ones() as usize;
                bits |= u64::from(k) << (8 * g);
            }
            if bits == 0 {
                return 0;
            }
            dst.write(MSG_CHUNK << 48 | j);
            dst.add(1).write(bits);
            batch.set_len(len + n);
            let costs = _mm512_maskz_mov_epi8(bits, _mm512_loadu_si512(cost.as_ptr().cast()));
            _mm512_reduce_add_epi64(_mm512_sad_epu8(costs, _mm512_setzero_si512())) as u64
        }
    }

    /// [`Chunk::changes`] one change at a time (what other CPUs run).
    #[inline(always)]
    pub(in crate::trace) fn changes_portable(
        self,
        batch: &mut Vec<u64>,
        j: u64,
        first: bool,
    ) -> u64 {
        let Chunk { c, m, l, cost } = self;
        let mut bits = if first {
            changed_mask(m, &[u64::MAX; 64], &[0; 64])
        } else {
            changed_mask(c, m, l)
        };
        if bits == 0 {
            return 0;
        }
        batch.push(MSG_CHUNK << 48 | j);
        batch.push(bits);
        let mut bytes = 0;
        while bits != 0 {
            // Below 64: no bounds checks.
            let k = bits.trailing_zeros() as usize & 63;
            bits &= bits - 1;
            let v = c[k] & m[k];
            l[k] = v;
            bytes += u64::from(cost[k]);
            batch.push(v);
        }
        bytes
    }
}
