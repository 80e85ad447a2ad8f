//! Formatting for the files: signal handles, the clock's edge times, binary
//! and decimal digits, and the VCD body written in large chunks.

use std::fs::File;
use std::io::{self, BufWriter, Seek, Write};

use super::Display;

/// A traced signal call's handle, width, whether its signal has a
/// translate filter, and its signal's index in declaration order.
pub(super) type Slot = (SigId, u32, bool, u32);

/// One signal's handle in the file.
#[derive(Clone, Copy)]
pub(super) enum SigId {
    /// Index into the VCD body's identifier codes.
    Vcd(u32),
    Fst(fst_writer::FstSignalId),
}

pub(super) fn fst_err(e: fst_writer::FstWriteError) -> io::Error {
    match e {
        fst_writer::FstWriteError::Io(e) => e,
        e => io::Error::other(e.to_string()),
    }
}

/// `Tracer::slot_decl` of a signal call that is not traced.
pub(super) const NOT_TRACED: u32 = u32::MAX;

/// A traced signal's identifier, width and display.
#[derive(Clone, Copy)]
pub(super) struct SigInfo {
    pub(super) id: SigId,
    pub(super) width: u32,
    pub(super) display: Display,
}

/// A traced signal's declaration: its scope path and what it is.
pub(super) struct Decl {
    pub(super) path: Vec<String>,
    pub(super) info: SigInfo,
}

/// The times of clock edges in picoseconds: the rising edge of cycle `c`
/// at `c * 1e12 / hz` rounded down. Consecutive cycles (the common case)
/// step by the period's quotient and remainder instead of dividing.
pub(super) struct Clock {
    pub(super) hz: u64,
    /// `1e12 / hz` and `1e12 % hz`.
    pub(super) q: u64,
    pub(super) r: u64,
    /// The last cycle asked for, its time and `c * 1e12 % hz`.
    pub(super) c: u64,
    pub(super) t: u64,
    pub(super) rem: u64,
}

impl Clock {
    pub(super) fn new(hz: u64) -> Clock {
        let hz = hz.max(1);
        Clock {
            hz,
            q: 1_000_000_000_000 / hz,
            r: 1_000_000_000_000 % hz,
            c: 0,
            t: 0,
            rem: 0,
        }
    }

    /// The time of cycle `c`'s rising edge.
    #[inline]
    pub(super) fn time(&mut self, c: u64) -> u64 {
        if c == self.c.wrapping_add(1) {
            self.c = c;
            self.rem += self.r;
            // Without a branch: the carry comes every few cycles, at a
            // rhythm the branch predictor missed.
            let carry = (self.rem >= self.hz) as u64;
            self.rem -= carry * self.hz;
            self.t += self.q + carry;
        } else if c != self.c {
            let ps = c as u128 * 1_000_000_000_000u128;
            self.c = c;
            self.t = (ps / self.hz as u128) as u64;
            self.rem = (ps % self.hz as u128) as u64;
        }
        self.t
    }

    /// The rising and falling edges of cycle `c` (the fall half a period,
    /// rounded down, after the rise).
    #[inline]
    pub(super) fn edges(&mut self, c: u64) -> (u64, u64) {
        let t = self.time(c);
        let next = self.time(c + 1);
        (t, t + (next - t) / 2)
    }
}

/// The 8 bits of `b` as ASCII `0`/`1`, most significant first, in the
/// bytes of a little-endian word: `b` copied into every byte, byte `j`
/// masked to bit `7 - j`, each nonzero byte turned into 1 (adding 0x7F
/// sets its top bit, with no carry out of the byte) and added to `'0'`.
#[inline(always)]
pub(super) fn bin8(b: u8) -> u64 {
    const ONES: u64 = 0x0101_0101_0101_0101;
    let x = (b as u64).wrapping_mul(ONES) & 0x0102_0408_1020_4080;
    (((x + 0x7F * ONES) >> 7) & ONES) | (b'0' as u64 * ONES)
}

/// The `bits` significant binary digits of `v` (1 to 64), most
/// significant first, in ASCII at the start of `dst`, which takes 64
/// bytes (those after the digits are left undefined).
///
/// With AVX-512 all at once: the digits as the bits of a mask, first
/// digit lowest (`v` shifted up to its top bit and its bits reversed),
/// which picks `1` or `0` for each of 64 bytes; one store. Otherwise 8
/// at a time ([`bin8`]) from the most significant byte; each loop's end,
/// at a count of bytes that varies from value to value, was a branch the
/// predictor often missed.
#[inline(always)]
pub(super) fn binary(dst: &mut [u8], v: u64, bits: usize) {
    let dst = &mut dst[..64];
    #[cfg(target_arch = "x86_64")]
    if crate::simd::avx512() {
        // SAFETY: the AVX-512 path runs only on a CPU that has it.
        unsafe { binary_avx512(dst, v, bits) };
        return;
    }
    binary_portable(dst, v, bits);
}

/// [`binary`] with AVX-512.
#[cfg(target_arch = "x86_64")]
#[inline]
#[target_feature(enable = "avx512f,avx512bw")]
fn binary_avx512(dst: &mut [u8], v: u64, bits: usize) {
    use std::arch::x86_64::*;
    let dst = &mut dst[..64];
    let digits = (v << (64 - bits)).reverse_bits();
    // SAFETY: a store of 64 bytes into the 64 of `dst`.
    unsafe {
        let ascii = _mm512_mask_blend_epi8(
            digits,
            _mm512_set1_epi8(b'0' as i8),
            _mm512_set1_epi8(b'1' as i8),
        );
        _mm512_storeu_si512(dst.as_mut_ptr().cast(), ascii);
    }
}

/// [`binary`] 8 digits at a time: the top byte's digits shifted down to
/// its significant ones, then whole bytes (the bytes stored past the
/// digits are overwritten by the next ones, or lie in the 64).
#[inline(always)]
pub(super) fn binary_portable(dst: &mut [u8], v: u64, bits: usize) {
    let bytes = bits.div_ceil(8);
    let top = bits - 8 * (bytes - 1);
    let first = bin8((v >> (8 * (bytes - 1))) as u8) >> (8 * (8 - top));
    dst[..8].copy_from_slice(&first.to_le_bytes());
    let mut k = top;
    for byte in (0..bytes - 1).rev() {
        dst[k..k + 8].copy_from_slice(&bin8((v >> (8 * byte)) as u8).to_le_bytes());
        k += 8;
    }
}

/// The 8 decimal digits of `x` < 10^8, most significant first, in the
/// bytes of a little-endian word (digit values, not ASCII): the halves
/// `x / 10^4` and `x % 10^4` in two 32-bit lanes, each split into
/// hundreds and the rest in 16-bit lanes, each of those into tens and
/// units in bytes; every division a multiplication by a reciprocal, exact
/// in its range.
#[inline(always)]
pub(super) fn digits8(x: u64) -> u64 {
    let abcd_efgh = (x / 10_000) | ((x % 10_000) << 32);
    let ab_ef = ((abcd_efgh * 10_486) >> 20) & 0x0000_007F_0000_007F;
    let ab_cd_ef_gh = ab_ef | (abcd_efgh - ab_ef * 100) << 16;
    let a_c_e_g = ((ab_cd_ef_gh * 103) >> 10) & 0x000F_000F_000F_000F;
    a_c_e_g | (ab_cd_ef_gh - a_c_e_g * 10) << 8
}

/// The 16 decimal digits of `x` < 10^16 as byte values, the units in the
/// lowest byte.
#[inline(always)]
pub(super) fn digits16(x: u64) -> u128 {
    (digits8(x / 100_000_000) as u128 | (digits8(x % 100_000_000) as u128) << 64).swap_bytes()
}

/// The times of a VCD (they only grow, mostly by the same few steps: half
/// a clock period, rounded down or up) in decimal, each the one before
/// plus the step, added 16 digits at once: the step's digits from a
/// table of four (refilled around a step not in it), the carries between
/// digits made by the addition itself (each digit biased by 246, so that
/// 10 or more carries out of its byte; those that did not carry out lose
/// the bias again).
pub(super) struct Decimal {
    /// The last time, and its digits ([`digits16`]); `None` before the
    /// first one and after one of 10^16 or more.
    pub(super) last: Option<(u64, u128)>,
    /// The steps in the table: `base` to `base + 3`.
    pub(super) base: u64,
    pub(super) steps: [u128; 4],
}

/// 10^16: the times [`Decimal`] writes are below.
pub(super) const DECIMAL_LIMIT: u64 = 10_000_000_000_000_000;

impl Decimal {
    pub(super) fn new() -> Decimal {
        Decimal {
            last: None,
            // No step (below 10^16) is within 4 of this one: the first
            // step refills the table.
            base: DECIMAL_LIMIT,
            steps: [0; 4],
        }
    }

    /// `t` in ASCII without leading zeros, in the low bytes of the result
    /// (the first digit in the lowest), and its digit count; `None` from
    /// 10^16 on.
    #[inline(always)]
    pub(super) fn next(&mut self, t: u64) -> Option<(u128, usize)> {
        const BIAS: u128 = u128::from_le_bytes([246; 16]);
        const ONES: u128 = u128::from_le_bytes([1; 16]);
        const ZEROS: u128 = u128::from_le_bytes([b'0'; 16]);
        if t >= DECIMAL_LIMIT {
            self.last = None;
            return None;
        }
        let d = match self.last {
            Some((before, digits)) if t >= before => {
                let mut i = (t - before).wrapping_sub(self.base);
                if i >= 4 {
                    self.refill(t - before);
                    i = t - before - self.base;
                }
                let x = digits + self.steps[(i & 3) as usize] + BIAS;
                x - ((x >> 7) & ONES) * 246
            }
            _ => digits16(t),
        };
        self.last = Some((t, d));
        let n = 16 - ((d | 1).leading_zeros() / 8) as usize;
        Some(((d.swap_bytes() | ZEROS) >> (8 * (16 - n)), n))
    }

    /// The table around `step`: `step - 1` to `step + 2`.
    #[cold]
    #[inline(never)]
    pub(super) fn refill(&mut self, step: u64) {
        self.base = step.saturating_sub(1);
        for (k, s) in self.steps.iter_mut().enumerate() {
            *s = digits16((self.base + k as u64).min(DECIMAL_LIMIT - 1));
        }
    }
}

/// Bytes of VCD body gathered before they are handed to the file: 256 KB
/// (smaller writes cost the kernel more in all).
pub(super) const VCD_CHUNK: usize = 1 << 18;
/// Room after the chunk for the longest line (a 64-bit value, its code).
pub(super) const VCD_SLACK: usize = 128;
/// Room after the chunk for a cycle's edges (five lines between two checks
/// for a full chunk, [`vcd_batch`]).
pub(super) const VCD_ROOM: usize = 4 * VCD_SLACK;

/// The body of a VCD file: timestamps and value changes, formatted into a
/// buffer of its own and written to the file [`VCD_CHUNK`] bytes at a time.
pub(super) struct VcdBody {
    /// Each signal's identifier code, padded, and its length.
    pub(super) ids: Vec<([u8; 16], u8)>,
    pub(super) buf: Box<[u8]>,
    pub(super) len: usize,
    pub(super) time: Decimal,
    /// Bytes of body handed to the file so far.
    pub(super) written: u64,
    /// The file's blocks are allocated ahead of the writes up to here
    /// ([`VcdBody::reserve`]); `None` when the file cannot be (a device,
    /// a pipe, a file system without `fallocate`).
    pub(super) reserved: Option<u64>,
}

/// Bytes of a VCD file allocated at a time ahead of its writes.
pub(super) const VCD_RESERVE: u64 = 4 << 20;

impl VcdBody {
    /// A body with its buffer (the tests'; the tracer's is allocated by
    /// its writing thread).
    #[cfg(test)]
    pub(super) fn new(reserve: bool) -> VcdBody {
        let mut b = VcdBody::unallocated(reserve);
        b.allocate();
        b
    }

    /// `reserve`: allocate the file's blocks ahead of the writes (a
    /// regular file; trimmed by [`VcdBody::trim`]). Without its buffer,
    /// for the writing thread to allocate ([`VcdBody::allocate`]).
    pub(super) fn unallocated(reserve: bool) -> VcdBody {
        VcdBody {
            ids: Vec::new(),
            buf: Box::default(),
            len: 0,
            time: Decimal::new(),
            written: 0,
            reserved: reserve.then_some(0),
        }
    }

    /// Allocate the buffer, by the thread that writes it: its pages are
    /// then first touched there (allocated with the tracer, the
    /// simulating thread took the page faults of a quarter megabyte).
    pub(super) fn allocate(&mut self) {
        if self.buf.is_empty() {
            self.buf = vec![0; VCD_CHUNK + VCD_ROOM].into_boxed_slice();
        }
    }

    /// Allocate the file's blocks some megabytes ahead of the next `n`
    /// bytes (the header counted generously), without changing its
    /// length: the kernel then copies the writes into blocks it has
    /// instead of reserving space page by page, which takes it about half
    /// the time on ext4. Where the file system cannot allocate ahead, the
    /// file is simply written.
    pub(super) fn reserve(&mut self, out: &BufWriter<File>, n: usize) {
        let Some(r) = self.reserved else { return };
        let end = self.written + n as u64 + (1 << 16);
        if end <= r {
            return;
        }
        let to = end.next_multiple_of(VCD_RESERVE) + VCD_RESERVE;
        self.reserved = allocate_ahead(out.get_ref(), r, to - r).then_some(to);
    }

    /// Give back the blocks allocated past the end of the file.
    pub(super) fn trim(&self, out: &mut BufWriter<File>) -> io::Result<()> {
        if self.reserved.is_some_and(|r| r > 0) {
            out.flush()?;
            let f = out.get_mut();
            let len = f.stream_position()?;
            f.set_len(len)?;
        }
        Ok(())
    }

    pub(super) fn add_id(&mut self, code: &str) -> io::Result<u32> {
        let b = code.as_bytes();
        if b.len() > 16 {
            return Err(io::Error::other("VCD identifier code longer than 16 bytes"));
        }
        let mut id = [0u8; 16];
        id[..b.len()].copy_from_slice(b);
        self.ids.push((id, b.len() as u8));
        Ok(self.ids.len() as u32 - 1)
    }

    /// `#t`: below 10^16 (about three hours of simulated time in
    /// picoseconds) carried forward in decimal from the time written
    /// before ([`Decimal`]) and stored as one 16-byte word: cheaper than
    /// `itoa` and a copy of its digits (a call to `memcpy` of a length
    /// known only at run time), which were a large share of the writing
    /// thread.
    #[inline(always)]
    pub(super) fn timestamp(&mut self, t: u64) {
        let dst = &mut self.buf[self.len..self.len + VCD_SLACK];
        dst[0] = b'#';
        let n = match self.time.next(t) {
            Some((ascii, n)) => {
                dst[1..17].copy_from_slice(&ascii.to_le_bytes());
                n
            }
            None => {
                let mut digits = itoa::Buffer::new();
                let d = digits.format(t).as_bytes();
                dst[1..1 + d.len()].copy_from_slice(d);
                d.len()
            }
        };
        dst[1 + n] = b'\n';
        self.len += n + 2;
    }

    /// `0!` for one bit, `b1011 !` for a vector (no leading zeros).
    #[inline(always)]
    pub(super) fn change(&mut self, id: u32, width: u32, v: u64) {
        let (code, n) = self.ids[id as usize];
        let dst = &mut self.buf[self.len..self.len + VCD_SLACK];
        let mut k;
        if width == 1 {
            dst[0] = b'0' + (v & 1) as u8;
            k = 1;
        } else {
            dst[0] = b'b';
            let bits = 64 - (v | 1).leading_zeros() as usize;
            binary(&mut dst[1..], v, bits);
            k = 1 + bits;
            dst[k] = b' ';
            k += 1;
        }
        dst[k..k + 16].copy_from_slice(&code);
        k += n as usize;
        dst[k] = b'\n';
        self.len += k + 1;
    }

    /// Hand the gathered bytes to the file once a chunk is full (`all`:
    /// whatever is gathered).
    #[inline(always)]
    pub(super) fn flush(&mut self, out: &mut BufWriter<File>, all: bool) -> io::Result<()> {
        if self.len >= VCD_CHUNK || (all && self.len > 0) {
            return self.write_out(out);
        }
        Ok(())
    }

    #[inline(never)]
    pub(super) fn write_out(&mut self, out: &mut BufWriter<File>) -> io::Result<()> {
        let n = std::mem::take(&mut self.len);
        self.reserve(out, n);
        self.written += n as u64;
        out.write_all(&self.buf[..n])
    }
}

/// Allocate `len` bytes of `f`'s blocks from `offset` on, its length
/// unchanged; whether it could.
#[cfg(target_os = "linux")]
pub(super) fn allocate_ahead(f: &File, offset: u64, len: u64) -> bool {
    rustix::fs::fallocate(f, rustix::fs::FallocateFlags::KEEP_SIZE, offset, len).is_ok()
}

#[cfg(not(target_os = "linux"))]
pub(super) fn allocate_ahead(_: &File, _: u64, _: u64) -> bool {
    false
}
