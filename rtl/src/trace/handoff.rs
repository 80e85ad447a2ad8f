//! The hand-over between the simulating thread and the waveform's writing
//! thread: the packed messages and the batches they travel in.

/// What the sampling thread hands the writing thread, packed in 64-bit
/// words (the messages are most of the traffic between the two cores):
///
/// * a sampled cycle `c` begins, `MSG_CYCLE << 48 | c` (or, from 2^48 on,
///   `MSG_LONG << 48` and `c` in the next word): the falling edge of the
///   cycle sampled before it, if any (its timestamp and `clk` 0), then
///   this cycle's rising edge (its timestamp, `clk` 1 and the `cycle`
///   counter); the writing thread computes the times;
/// * signal calls `64 j` to `64 j + 63` (in call order) changed in the
///   cycle: `MSG_CHUNK << 48 | j`, the mask of those that did (bit `k`:
///   call `64 j + k`), and their new values, one word each, in call order.
pub(super) const MSG_CHUNK: u64 = 0xFFFD;
pub(super) const MSG_CYCLE: u64 = 0xFFFE;
pub(super) const MSG_LONG: u64 = 0xFFFF;
pub(super) const MSG_VALUE: u64 = (1 << 48) - 1;

/// Words per batch handed to the writing thread (128 KB: a batch stays in
/// the cores' second-level caches);
/// at most [`QUEUED_BATCHES`] wait, so memory stays bounded when the disk
/// is slower than the simulation.
pub(super) const BATCH: usize = 1 << 14;
pub(super) const QUEUED_BATCHES: usize = 8;
/// Emptied batches the writing thread makes ready before the first comes.
pub(super) const SPARE_BATCHES: usize = 3;

/// The batches between the two threads, handed over without a system
/// call while both are busy. A channel woke the writing thread at every
/// batch it waited for: a system call on the simulating thread each time.
/// Here the writing thread polls
/// every [`POLL`] while batches come, and only after [`IDLE_POLLS`] empty
/// polls says it is asleep and waits to be woken.
pub(super) struct Handoff {
    pub(super) full: std::sync::Mutex<std::collections::VecDeque<Vec<u64>>>,
    /// Emptied batches, for the simulating thread to fill again.
    pub(super) empty: std::sync::Mutex<Vec<Vec<u64>>>,
    /// The writing thread waits to be woken.
    pub(super) asleep: std::sync::atomic::AtomicBool,
    /// The simulating thread has handed over its last batch.
    pub(super) done: std::sync::atomic::AtomicBool,
    /// Set before `done`: the time the waveform ends at, and the note to
    /// leave in it ([`Tracer::note`]).
    pub(super) end: std::sync::Mutex<Option<(u64, Option<String>)>>,
    /// The writing thread takes no more batches (it ended or panicked).
    pub(super) gone: std::sync::atomic::AtomicBool,
}

pub(super) const POLL: std::time::Duration = std::time::Duration::from_micros(50);
pub(super) const IDLE_POLLS: u32 = 20;

impl Handoff {
    pub(super) fn new() -> Handoff {
        use std::sync::atomic::AtomicBool;
        Handoff {
            full: Default::default(),
            empty: Default::default(),
            asleep: AtomicBool::new(false),
            done: AtomicBool::new(false),
            end: Default::default(),
            gone: AtomicBool::new(false),
        }
    }

    /// Queue `batch` for the writing thread `writer`: at once while fewer
    /// than [`QUEUED_BATCHES`] wait, else once one is taken (the disk is
    /// slower than the simulation). `false`: the writing thread is gone.
    pub(super) fn send(&self, batch: Vec<u64>, writer: &std::thread::Thread) -> bool {
        use std::sync::atomic::{fence, Ordering::SeqCst};
        let mut batch = Some(batch);
        loop {
            if self.gone.load(SeqCst) {
                return false;
            }
            {
                let mut q = self.full.lock().unwrap_or_else(|e| e.into_inner());
                if q.len() < QUEUED_BATCHES {
                    q.extend(batch.take());
                }
            }
            // Seen asleep after the batch is queued: wake it (it said so
            // before it looked at the queue a last time).
            fence(SeqCst);
            if self.asleep.swap(false, SeqCst) || batch.is_some() {
                writer.unpark();
            }
            if batch.is_none() {
                return true;
            }
            std::thread::sleep(POLL);
        }
    }

    /// The next batch, waiting for it; `None` once the last is taken.
    pub(super) fn recv(&self) -> Option<Vec<u64>> {
        use std::sync::atomic::{fence, Ordering::SeqCst};
        let mut idle = 0;
        loop {
            let done = self.done.load(SeqCst);
            if let Some(b) = self
                .full
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .pop_front()
            {
                return Some(b);
            }
            if done {
                return None;
            }
            idle += 1;
            if idle < IDLE_POLLS {
                std::thread::park_timeout(POLL);
                continue;
            }
            self.asleep.store(true, SeqCst);
            fence(SeqCst);
            let empty = self
                .full
                .lock()
                .unwrap_or_else(|e| e.into_inner())
                .is_empty();
            if empty && !self.done.load(SeqCst) {
                std::thread::park();
            }
            self.asleep.store(false, SeqCst);
            idle = 0;
        }
    }

    /// An emptied batch for the simulating thread to fill again.
    pub(super) fn give_back(&self, mut batch: Vec<u64>) {
        batch.clear();
        let mut e = self.empty.lock().unwrap_or_else(|e| e.into_inner());
        if e.len() < QUEUED_BATCHES + 2 {
            e.push(batch);
        }
    }
}

/// Marks the [`Handoff`] gone when the writing thread ends, however.
pub(super) struct WriterGone(pub(super) std::sync::Arc<Handoff>);

impl Drop for WriterGone {
    fn drop(&mut self) {
        self.0.gone.store(true, std::sync::atomic::Ordering::SeqCst);
    }
}

/// Queue the start of cycle `c` for the writing thread.
#[inline(always)]
pub(super) fn queue_cycle(batch: &mut Vec<u64>, c: u64) {
    if c <= MSG_VALUE {
        batch.push(MSG_CYCLE << 48 | c);
    } else {
        batch.push(MSG_LONG << 48);
        batch.push(c);
    }
}

/// Append `src` to `dst`. With AVX-512 the whole cache lines are stored
/// by non-temporal stores, which go to memory without taking the lines
/// into this core's caches: the sampling thread writes its messages into
/// one batch of its own that stays in its caches, and the copies the
/// writing thread reads never come back to it.
pub(super) fn copy_streaming(dst: &mut Vec<u64>, src: &[u64]) {
    #[cfg(target_arch = "x86_64")]
    if crate::simd::avx512() {
        // SAFETY: the AVX-512 path runs only on a CPU that has it.
        unsafe { copy_streaming_avx512(dst, src) };
        return;
    }
    dst.extend_from_slice(src);
}

/// [`copy_streaming`] with AVX-512.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn copy_streaming_avx512(dst: &mut Vec<u64>, src: &[u64]) {
    use std::arch::x86_64::*;
    dst.reserve(src.len());
    let len = dst.len();
    let out = dst.spare_capacity_mut().as_mut_ptr().cast::<u64>();
    // Words before the first 64-byte boundary, stored plainly.
    let head = (out.align_offset(64)).min(src.len());
    let lines = (src.len() - head) / 8;
    // SAFETY: every store lies inside the `src.len()` words of spare
    // capacity reserved above (`head + 8 * lines` <= `src.len()`), the
    // streaming ones at 64-byte boundaries (`align_offset`; should it
    // not know, `head` takes every word); all `src.len()` words after
    // `len` are written before `set_len`; the fence orders the
    // streaming stores before the batch is handed over.
    unsafe {
        for k in 0..head {
            out.add(k).write(src[k]);
        }
        for k in 0..lines {
            let at = head + 8 * k;
            let v = _mm512_loadu_si512(src.as_ptr().add(at).cast());
            _mm512_stream_si512(out.add(at).cast(), v);
        }
        for k in head + 8 * lines..src.len() {
            out.add(k).write(src[k]);
        }
        _mm_sfence();
        dst.set_len(len + src.len());
    }
}
