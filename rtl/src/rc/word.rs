//! The datapath word: the RC is generic over [`Word`], implemented by `i16`
//! (the paper's 16-bit chip) and `i32` (the 32-bit variant the paper
//! announces for the next chip). Every unit's operations are monomorphised,
//! so the 16-bit datapath compiles to code of its own width, with nothing of
//! the 32-bit one in it.
//!
//! | | `i16` | `i32` |
//! |---|---|---|
//! | registers, ALU, shifter, `out`, RAM words, FB words | 16 bits | 32 bits |
//! | accumulator | 32 bits | 64 bits |
//! | shift amount of `sll srl sra asl` | `B & 31` | `B & 63` |
//! | multiplier shift `sh` | 0..=31 | 0..=63 (`f[10]` is bit 5) |

use std::fmt;
use std::ops::{BitAnd, BitOr, BitXor, Not};

use super::alu::{self, Flagged};
use super::context::Cond;
use super::lanes::{full, select, Mask, SignBits};
use super::{multiplier, shifter};

/// Which datapath a chip has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Datapath {
    /// 16-bit RCs (the paper's chip, the default).
    #[default]
    W16,
    /// 32-bit RCs with a 64-bit accumulator.
    W32,
}

impl Datapath {
    pub fn bits(self) -> u32 {
        match self {
            Datapath::W16 => 16,
            Datapath::W32 => 32,
        }
    }

    /// The extra fraction bits every number format gets on this datapath
    /// over the paper's 16-bit chip: 0, or 16 on the 32-bit chip.
    pub fn extra_bits(self) -> u32 {
        self.bits() - 16
    }

    /// From a bit count (16 or 32).
    pub fn from_bits(bits: u32) -> Option<Datapath> {
        match bits {
            16 => Some(Datapath::W16),
            32 => Some(Datapath::W32),
            _ => None,
        }
    }

    /// Bytes of one FB word (and of a DMA transfer's FB word).
    pub fn fb_word_bytes(self) -> u32 {
        self.bits() / 8
    }
}

impl fmt::Display for Datapath {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}-bit", self.bits())
    }
}

/// A datapath word and every RC unit operation on it.
pub trait Word:
    SignBits
    + Copy
    + Default
    + Eq
    + Ord
    + fmt::Debug
    + fmt::Display
    + Send
    + Sync
    + 'static
    + BitAnd<Output = Self>
    + BitOr<Output = Self>
    + BitXor<Output = Self>
    + Not<Output = Self>
{
    /// The accumulator (twice the word).
    type Acc: Copy + Default + Eq + fmt::Debug + Send + Sync + 'static + SignBits;
    const DATAPATH: Datapath;
    const BITS: u32;
    const ZERO: Self;

    /// Two's-complement truncation of `v` to the word.
    fn wrap(v: i64) -> Self;
    /// The value, sign-extended.
    fn to_i64(self) -> i64;
    /// The accumulator's value.
    fn acc_i128(a: Self::Acc) -> i128;
    /// A context immediate (11-bit signed), sign-extended.
    fn imm(v: i16) -> Self;
    /// The 0 / -1 lanes of one mask byte (guarded writes by bit blending).
    fn expand8(byte: usize) -> &'static [Self; 8];
    /// `dst[i] = src[i]` for the accumulators of the lanes in `mask`,
    /// blended with a 0 / -1 lane mask (the generic `select` went through
    /// an array of bools: a guarded `mac` ran at 23 M contexts/s against
    /// 38 M unguarded).
    fn select_acc<const N: usize>(dst: &mut [Self::Acc; N], mask: u64, src: &[Self::Acc; N]);

    fn add(a: Self, b: Self, cin: bool) -> Flagged<Self>;
    fn sub(a: Self, b: Self, bin: bool) -> Flagged<Self>;
    fn adds(a: Self, b: Self) -> (Self, bool);
    fn subs(a: Self, b: Self) -> (Self, bool);
    fn abs(a: Self) -> (Self, bool);
    fn absd(a: Self, b: Self) -> (Self, bool);
    fn clz(a: Self) -> Self;
    fn cond(c: Cond, a: Self, b: Self, cf: bool, vf: bool) -> bool;

    fn amount(b: Self) -> u32;
    fn sll(a: Self, n: u32) -> Self;
    fn srl(a: Self, n: u32) -> Self;
    fn sra(a: Self, n: u32) -> Self;
    fn asl(a: Self, n: u32) -> (Self, bool);

    fn product(a: Self, b: Self) -> Self::Acc;
    fn accumulate(acc: Self::Acc, p: Self::Acc, sub: bool) -> (Self::Acc, bool);
    fn scale(acc: Self::Acc, sh: u32, trunc: bool) -> (Self, bool);
    fn ldacc(a: Self, sh: u32) -> Self::Acc;
    /// `ldacc` for `sh < BITS` (no saturation possible).
    fn ldacc_narrow(a: Self, sh: u32) -> Self::Acc;
    fn acch(acc: Self::Acc) -> Self;
    fn accl(acc: Self::Acc) -> Self;

    /// RAM address `a + b` (saturated to i32: any out-of-range sum faults).
    fn addr(a: Self, b: Self) -> i32;
    /// RAM address `b`.
    fn addr1(b: Self) -> i32;
}

const fn expand_table<T: Copy>(zero: T, ones: T) -> [[T; 8]; 256] {
    let mut t = [[zero; 8]; 256];
    let mut b = 0;
    while b < 256 {
        let mut k = 0;
        while k < 8 {
            if b >> k & 1 != 0 {
                t[b][k] = ones;
            }
            k += 1;
        }
        b += 1;
    }
    t
}

static EXPAND16: [[i16; 8]; 256] = expand_table(0i16, -1i16);
static EXPAND32: [[i32; 8]; 256] = expand_table(0i32, -1i32);

macro_rules! impl_word {
    ($t:ty, $acc:ty, $m:ident, $dp:expr, $table:ident, $addr:expr) => {
        impl Word for $t {
            type Acc = $acc;
            const DATAPATH: Datapath = $dp;
            const BITS: u32 = <$t>::BITS;
            const ZERO: Self = 0;

            #[inline(always)]
            fn wrap(v: i64) -> Self {
                v as $t
            }
            #[inline(always)]
            fn to_i64(self) -> i64 {
                self as i64
            }
            #[inline(always)]
            fn acc_i128(a: $acc) -> i128 {
                a as i128
            }
            #[inline(always)]
            fn imm(v: i16) -> Self {
                v as $t
            }
            #[inline(always)]
            fn expand8(byte: usize) -> &'static [Self; 8] {
                &$table[byte & 255]
            }
            #[inline(always)]
            fn select_acc<const N: usize>(dst: &mut [$acc; N], mask: u64, src: &[$acc; N]) {
                if N <= 64 && mask == u64::MAX >> (64 - N) {
                    *dst = *src;
                } else if let Some(m) = <$acc as SignBits>::from_mask::<N>(mask) {
                    for i in 0..N {
                        dst[i] = (src[i] & m[i]) | (dst[i] & !m[i]);
                    }
                } else if mask != 0 {
                    for i in 0..N {
                        let m = (((mask >> i) & 1) as $acc).wrapping_neg();
                        dst[i] = (src[i] & m) | (dst[i] & !m);
                    }
                }
            }

            #[inline(always)]
            fn add(a: Self, b: Self, cin: bool) -> Flagged<Self> {
                alu::$m::add(a, b, cin)
            }
            #[inline(always)]
            fn sub(a: Self, b: Self, bin: bool) -> Flagged<Self> {
                alu::$m::sub(a, b, bin)
            }
            #[inline(always)]
            fn adds(a: Self, b: Self) -> (Self, bool) {
                alu::$m::adds(a, b)
            }
            #[inline(always)]
            fn subs(a: Self, b: Self) -> (Self, bool) {
                alu::$m::subs(a, b)
            }
            #[inline(always)]
            fn abs(a: Self) -> (Self, bool) {
                alu::$m::abs(a)
            }
            #[inline(always)]
            fn absd(a: Self, b: Self) -> (Self, bool) {
                alu::$m::absd(a, b)
            }
            #[inline(always)]
            fn clz(a: Self) -> Self {
                alu::$m::clz(a)
            }
            #[inline(always)]
            fn cond(c: Cond, a: Self, b: Self, cf: bool, vf: bool) -> bool {
                alu::$m::cond(c, a, b, cf, vf)
            }

            #[inline(always)]
            fn amount(b: Self) -> u32 {
                shifter::$m::amount(b)
            }
            #[inline(always)]
            fn sll(a: Self, n: u32) -> Self {
                shifter::$m::sll(a, n)
            }
            #[inline(always)]
            fn srl(a: Self, n: u32) -> Self {
                shifter::$m::srl(a, n)
            }
            #[inline(always)]
            fn sra(a: Self, n: u32) -> Self {
                shifter::$m::sra(a, n)
            }
            #[inline(always)]
            fn asl(a: Self, n: u32) -> (Self, bool) {
                shifter::$m::asl(a, n)
            }

            #[inline(always)]
            fn product(a: Self, b: Self) -> $acc {
                multiplier::$m::product(a, b)
            }
            #[inline(always)]
            fn accumulate(acc: $acc, p: $acc, sub: bool) -> ($acc, bool) {
                multiplier::$m::accumulate(acc, p, sub)
            }
            #[inline(always)]
            fn scale(acc: $acc, sh: u32, trunc: bool) -> (Self, bool) {
                multiplier::$m::scale(acc, sh, trunc)
            }
            #[inline(always)]
            fn ldacc(a: Self, sh: u32) -> $acc {
                multiplier::$m::load(a, sh)
            }
            #[inline(always)]
            fn ldacc_narrow(a: Self, sh: u32) -> $acc {
                multiplier::$m::load_narrow(a, sh)
            }
            #[inline(always)]
            fn acch(acc: $acc) -> Self {
                multiplier::$m::high(acc)
            }
            #[inline(always)]
            fn accl(acc: $acc) -> Self {
                multiplier::$m::low(acc)
            }

            #[inline(always)]
            fn addr(a: Self, b: Self) -> i32 {
                $addr(a, b)
            }
            #[inline(always)]
            fn addr1(b: Self) -> i32 {
                b as i32
            }
        }
    };
}

impl_word!(i16, i32, w16, Datapath::W16, EXPAND16, |a: i16, b: i16| a
    as i32
    + b as i32);
impl_word!(i32, i64, w32, Datapath::W32, EXPAND32, |a: i32, b: i32| a
    .saturating_add(b));

/// `select` for datapath words: the mask is expanded to 0 / -1 lanes by
/// table ([`Word::expand8`]) and blended with bit operations, which
/// vectorises.
#[inline(always)]
pub(crate) fn select_word<W: Word, const N: usize>(dst: &mut [W; N], mask: Mask, src: &[W; N]) {
    if mask == full(N) {
        *dst = *src;
    } else if mask != 0 {
        if !N.is_multiple_of(8) {
            return select(dst, mask, src);
        }
        blend(dst, &expand(mask), src);
    }
}

/// The 0 / -1 lanes of `mask` (`N` a multiple of 8), by table
/// ([`Word::expand8`]), for [`blend`]: one expansion serves every array
/// a commit writes under the same mask.
#[inline(always)]
pub fn expand<W: Word, const N: usize>(mask: Mask) -> [W; N] {
    if let Some(m) = W::from_mask(mask) {
        return m;
    }
    let mut m = [W::ZERO; N];
    for c in 0..N / 8 {
        m[c * 8..c * 8 + 8].copy_from_slice(W::expand8((mask >> (c * 8)) as usize & 255));
    }
    m
}

/// `dst[i] = src[i]` where `m[i]` is -1 (bit operations: vectorises).
#[inline(always)]
pub fn blend<W: Word, const N: usize>(dst: &mut [W; N], m: &[W; N], src: &[W; N]) {
    for i in 0..N {
        dst[i] = (src[i] & m[i]) | (dst[i] & !m[i]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rc::lanes::pack_bools;

    /// Words selected, masks expanded and accumulators selected under
    /// random masks, against the masks' bits.
    #[test]
    fn selects_and_expansions_follow_the_mask_bits() {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..200 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let b: [bool; 64] = std::array::from_fn(|i| x >> i & 1 == 1);
            let b12: [bool; 12] = std::array::from_fn(|i| b[i]);
            assert_eq!(pack_bools(&b12), x & 0xFFF);
            let mut d = [7i16; 64];
            let src: [i16; 64] = std::array::from_fn(|i| i as i16 - 20);
            select_word(&mut d, x, &src);
            for i in 0..64 {
                assert_eq!(d[i], if x >> i & 1 == 1 { src[i] } else { 7 });
            }
            let mut d = [7i32; 64];
            let src: [i32; 64] = std::array::from_fn(|i| i as i32 * 100_000 - 2_000_000);
            select_word(&mut d, x, &src);
            for i in 0..64 {
                assert_eq!(d[i], if x >> i & 1 == 1 { src[i] } else { 7 });
            }
            // Masks expanded to 0 / -1 lanes of every width (by AVX-512 on
            // the AVX-512 path, else by table), against the bits.
            let e16 = expand::<i16, 64>(x);
            let e32 = expand::<i32, 64>(x);
            let e8 = expand::<i16, 8>(x);
            for i in 0..64 {
                let want = -((x >> i & 1) as i64);
                assert_eq!((e16[i] as i64, e32[i] as i64), (want, want));
                if i < 8 {
                    assert_eq!(e8[i] as i64, want);
                }
            }
            if let Some(e64) = i64::from_mask::<64>(x) {
                assert!((0..64).all(|i| e64[i] == -((x >> i & 1) as i64)));
            }
            // The accumulators of both datapaths (i32 and i64 lanes).
            let mut d = [7i32; 64];
            <i16 as Word>::select_acc(&mut d, x, &src);
            for i in 0..64 {
                assert_eq!(d[i], if x >> i & 1 == 1 { src[i] } else { 7 });
            }
            let mut d = [-7i64; 64];
            let src64: [i64; 64] = std::array::from_fn(|i| (i as i64 - 30) << 40);
            <i32 as Word>::select_acc(&mut d, x, &src64);
            for i in 0..64 {
                assert_eq!(d[i], if x >> i & 1 == 1 { src64[i] } else { -7 });
            }
            let mut d = [7i32; 12];
            <i16 as Word>::select_acc(&mut d, x, &b12.map(|b| b as i32 - 5));
            for i in 0..12 {
                assert_eq!(
                    d[i],
                    if x >> i & 1 == 1 {
                        b12[i] as i32 - 5
                    } else {
                        7
                    }
                );
            }
        }
    }
}
