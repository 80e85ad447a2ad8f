//! The RC arithmetic the kernels share: normalisation, square root,
//! division and powers in fixed point, from the tables in every RC's RAM
//! and Newton-Raphson steps.
//!
//! Register convention in every RC (the "ray registers" live across
//! kernels, the rest are temporaries of one kernel):
//!
//! | reg | holds |
//! |---|---|
//! | r0 | 0 (set once at start) |
//! | r1..r3 | ray origin, scene format `Qm.n` |
//! | r4..r6 | ray direction, unit, Q1.14 |
//! | r7 | `tbest`: distance to the closest hit so far (scene format), `C_INF` = none |
//! | r8..r15 | temporaries |
//!
//! Arithmetic never wraps silently: differences of coordinates fit by the
//! two guard bits of the scene format, products go through the 32-bit
//! accumulator and are saturated when scaled back to 16 bits, and a
//! saturated value always fails the test it feeds (a saturated
//! perpendicular distance is a miss, a saturated `t` is beyond `tbest`).
//!
//! Formats are written for the 16-bit chip as `Qn` (the program's header
//! makes them `n + X`, `X` = 16 on the 32-bit chip): one text serves both
//! datapaths. The tables' index shifts are the header's `RSQ_SHIFT`,
//! `RCP_SHIFT` and `RCP_MASK`, fitted to the table size.

use super::emit::{define, K};
use super::memory_map::ram;

/// Entries of the reciprocal and reciprocal square root tables by default.
pub const TABLE_ENTRIES: u32 = 128;
/// Table sizes the RC RAM map has room for (each table has a 128-word
/// slot; two of 256 would fill the whole 512-word RAM).
pub const TABLE_SIZES: [u32; 4] = [16, 32, 64, 128];

/// How the kernels approximate reciprocals and reciprocal square roots:
/// table entries ([`TABLE_SIZES`]) and Newton-Raphson steps after the
/// lookup.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Approx {
    pub newton_steps: u32,
    pub table_entries: u32,
}

impl Default for Approx {
    /// Two Newton-Raphson steps after the 128-entry tables.
    fn default() -> Approx {
        Approx {
            newton_steps: 2,
            table_entries: TABLE_ENTRIES,
        }
    }
}

impl Approx {
    /// Right shift of the table index against the 128-entry table.
    fn coarse(self) -> u32 {
        (TABLE_ENTRIES / self.table_entries.clamp(1, TABLE_ENTRIES)).trailing_zeros()
    }

    /// The header's table constants: `RSQ_SHIFT` (X in Q.11 to an RSQ
    /// index), `RCP_SHIFT` and `RCP_MASK` (a divisor normalised into
    /// [2^14, 2^15) to an RCP index), for tables of this size.
    pub fn header(self) -> Vec<String> {
        vec![
            define(
                "TABLE_ENTRIES",
                self.table_entries,
                "entries of the RSQ and RCP tables",
            ),
            define(
                "RSQ_SHIFT",
                format!("Q8 + {}", self.coarse()),
                "X (Q.11) >> RSQ_SHIFT indexes RSQ",
            ),
            define(
                "RCP_SHIFT",
                format!("Q7 + {}", self.coarse()),
                "a divisor in [2^Q14, 2^Q15) >> RCP_SHIFT ...",
            ),
            define(
                "RCP_MASK",
                self.table_entries - 1,
                "... & RCP_MASK indexes RCP",
            ),
        ]
    }
}

fn r(k: u8) -> String {
    format!("r{k}")
}

/// Normalise the vector in registers `v` (2 or 3 components) in place to a
/// unit Q1.14 vector; with `len`, also its length (in the input's units)
/// into `t[0]`. Temporaries `t` (5 registers). Method: halve (so the
/// largest component is below 2^14), shift left by `clz(max) - 2` (largest
/// component in [2^13, 2^14)), `X = |v'|^2 >> 15` in Q.11 (range [1, 12)),
/// reciprocal square root from the RSQ table (index X >> 8) and two
/// Newton-Raphson steps `y += y (1 - X y^2) / 2`. A 2D vector gives what
/// the 3D one with a zero third component would, without the instructions
/// on that component.
pub fn normalize(k: &mut K, v: &[u8], t: [u8; 5], len: bool, nr: Approx) {
    assert!(matches!(v.len(), 2 | 3), "normalize: 2 or 3 components");
    let v: Vec<String> = v.iter().map(|&x| r(x)).collect();
    let [t0, t1, t2, t3, t4] = t.map(r);
    k.comment("normalize");
    for x in &v {
        k.c(format!("sra {x}, {x}, #1"));
    }
    k.c(format!("abs {t0}, {}", v[0]));
    for x in &v[1..] {
        k.c(format!("abs {t1}, {x}"))
            .c(format!("max {t0}, {t0}, {t1}"));
    }
    k.c(format!("clz {t0}, {t0}"))
        .c(format!("sub {t0}, {t0}, #2"))
        .note("shift to the top of the word");
    for x in &v {
        k.c(format!("sll {x}, {x}, {t0}"));
    }
    let last = v.len() - 1;
    k.c(format!("mul out, {}, {}", v[0], v[0]));
    for x in &v[1..last] {
        k.c(format!("mac out, {x}, {x}"));
    }
    k.c(format!("mac {t1}, {}, {}, >>Q15", v[last], v[last]))
        .note("X = |v|^2, Q.11")
        .c(format!("srl {t2}, {t1}, #RSQ_SHIFT"))
        .c(format!("ld {t2}, [{t2} + #{}]", ram::RSQ))
        .note("y = 1/sqrt(X) from the table")
        .c(format!("ld {t4}, [r0 + #{}]", ram::C_ONE));
    for _ in 0..nr.newton_steps {
        k.c(format!("mul {t3}, {t2}, {t2}, >>Q14"))
            .note("Newton: y += y (1 - X y^2) / 2")
            .c(format!("mul {t3}, {t3}, {t1}, >>Q11"))
            .c(format!("sub {t3}, {t3}, {t4}"))
            .c(format!("ldacc {t2}, <<Q15"))
            .c(format!("msu {t2}, {t2}, {t3}, >>Q15"));
    }
    if len {
        // |v'| = X * y in units of v' (>> 12), then undo the shifts.
        k.c(format!("mul {t1}, {t1}, {t2}, >>Q12"))
            .note("|v| = X y, the shifts undone")
            .c(format!("sra {t1}, {t1}, {t0}"))
            .c(format!("adds {t0}, {t1}, {t1}"));
    }
    for x in &v {
        k.c(format!("mul {x}, {x}, {t2}, >>Q13"));
    }
}

/// `out = sqrt(s)` for `s` in Q.14 (0, 1], result Q.14. Method: clamp to
/// 16383, shift left by an odd `e = (clz(s) - 2) | 1` so that `X = s << e`
/// is in [2^13, 2^15), reciprocal square root of X (Q.11) from the RSQ
/// table and two Newton-Raphson steps, `sqrt(X) = X * y` (Q.12), then
/// shift right by `(e - 1) / 2` (since `s = X 2^-(3 + e)` in Q.11 units).
/// Clobbers `t` (4 registers); `s` is kept.
pub fn sqrt_q14(k: &mut K, s: u8, out: u8, t: [u8; 4], nr: Approx) {
    let (s, o) = (r(s), r(out));
    let [e, x, y, w] = t.map(r);
    k.comment("sqrt");
    k.c(format!("ld {w}, [r0 + #{}]", ram::C_ONE))
        .c(format!("add {w}, {w}, #-1"))
        .c(format!("min {o}, {s}, {w}"))
        .c(format!("clz {e}, {o}"))
        .c(format!("sub {e}, {e}, #2"))
        .c(format!("or {e}, {e}, #1"))
        .note("an odd shift e")
        .c(format!("sll {x}, {o}, {e}"))
        .c(format!("srl {y}, {x}, #RSQ_SHIFT"))
        .c(format!("ld {y}, [{y} + #{}]", ram::RSQ))
        .note("y = 1/sqrt(X) from the table")
        .c(format!("ld {w}, [r0 + #{}]", ram::C_ONE));
    for _ in 0..nr.newton_steps {
        k.c(format!("mul {o}, {y}, {y}, >>Q14"))
            .note("Newton: y += y (1 - X y^2) / 2")
            .c(format!("mul {o}, {o}, {x}, >>Q11"))
            .c(format!("sub {o}, {o}, {w}"))
            .c(format!("ldacc {y}, <<Q15"))
            .c(format!("msu {y}, {y}, {o}, >>Q15"));
    }
    k.c(format!("mul {o}, {x}, {y}, >>Q13"))
        .note("sqrt(X) = X y, Q.12")
        .c(format!("sub {e}, {e}, #1"))
        .c(format!("sra {e}, {e}, #1"))
        .c(format!("sra {o}, {o}, {e}"));
}

/// `q = num * 2^14 / den` for `num >= 0`, `den` in (0, 16384] (Q.14), the
/// caller having checked that the quotient is below 32768. Method:
/// normalise `den` by `clz` into [2^14, 2^15), reciprocal `2^29 / den'` from
/// the RCP table (index bits 13..7) and two Newton-Raphson steps
/// `r -= r (den' r / 2^29 - 1)`, then `q = (num * r) >> (15 - sh)` from the
/// two accumulator halves. Result into `num`'s register `out`; clobbers `t`.
pub fn divide(k: &mut K, num: u8, den: u8, out: u8, t: [u8; 5], nr: Approx) {
    divide_as(k, num, den, out, t, nr, false)
}

/// [`divide`] with one more bit of range: `q = num * 2^13 / den` for `num >= 0`,
/// `den` in (0, 32767], the caller having checked `num < 4 den`.
pub fn divide_q13(k: &mut K, num: u8, den: u8, out: u8, t: [u8; 5], nr: Approx) {
    divide_as(k, num, den, out, t, nr, true)
}

fn divide_as(k: &mut K, num: u8, den: u8, out: u8, t: [u8; 5], nr: Approx, q13: bool) {
    let (n, d, o) = (r(num), r(den), r(out));
    let [sh, dn, rc, w, one] = t.map(r);
    k.comment(if q13 {
        "divide (Q.13 quotient)"
    } else {
        "divide"
    });
    k.c(format!("clz {sh}, {d}"))
        .c(format!("sub {sh}, {sh}, #1"))
        .c(format!("sll {dn}, {d}, {sh}"))
        .note("the divisor normalised")
        .c(format!("srl {rc}, {dn}, #RCP_SHIFT"))
        .c(format!("and {rc}, {rc}, #RCP_MASK"))
        .c(format!("ld {rc}, [{rc} + #{}]", ram::RCP))
        .note("r = 1/den from the table")
        .c(format!("ld {one}, [r0 + #{}]", ram::C_ONE));
    for _ in 0..nr.newton_steps {
        k.c(format!("mul {w}, {dn}, {rc}, >>Q15"))
            .note("Newton: r -= r (den r - 1)")
            .c(format!("sub {w}, {w}, {one}"))
            .c(format!("ldacc {rc}, <<Q14"))
            .c(format!("msu {rc}, {rc}, {w}, >>Q14"));
    }
    k.c(format!("mul out, {n}, {rc}"))
        .note("num r in the accumulator, scaled back")
        .c(format!("acch {w}"))
        .c(format!("accl {dn}"));
    if q13 {
        k.c(format!("sll {w}, {w}, {sh}"))
            .c(format!("rsb {one}, {sh}, #Q16"));
    } else {
        k.c(format!("add {one}, {sh}, #1"))
            .c(format!("sll {w}, {w}, {one}"))
            .c(format!("rsb {one}, {sh}, #Q15"));
    }
    k.c(format!("srl {dn}, {dn}, {one}"))
        .c(format!("or {o}, {w}, {dn}"));
}

/// `x^n` for `x` in Q.14 [0, 1] by square-and-multiply: `out = base^n`.
pub fn pow_q14(k: &mut K, base: u8, out: u8, tmp: u8, n: u32) {
    let (b, o, t) = (r(base), r(out), r(tmp));
    k.comment(&format!("pow ^{n}"));
    k.c(format!("ld {o}, [r0 + #{}]", ram::C_ONE));
    if n == 0 {
        return;
    }
    k.c(format!("mov {t}, {b}"));
    let mut e = n;
    loop {
        if e & 1 == 1 {
            k.c(format!("mul {o}, {o}, {t}, >>Q14"));
        }
        e >>= 1;
        if e == 0 {
            break;
        }
        k.c(format!("mul {t}, {t}, {t}, >>Q14"));
    }
}

/// Remove from the vector in registers `p` its component along the unit
/// vector in registers `d` (the ray direction r4..r6, or the cylinder's 2D
/// direction): `p -= (p.d) d`, with `t` a temporary. The perpendicular
/// vector `(c - o) - b d` of the sphere and cylinder tests is
/// perpendicular to `d` only in exact arithmetic: `b` is rounded to an
/// LSB and the Q1.14 direction is not quite unit (`|d|^2 - 1` of a few
/// 2^-14), and the distance `b` multiplies that. Far from the eye (`b`
/// thousands of LSB) the leftover along `d` reaches an LSB or more, and
/// divided by a radius of a few dozen LSB it tilts the normal by a
/// hundredth of a radian, which a Phong highlight or a reflection shows.
pub fn perpendicular_to(k: &mut K, p: &[u8], d: &[u8], t: u8) {
    let n = p.len();
    k.comment("p made perpendicular to d: p -= (p.d) d");
    for (i, (x, e)) in p.iter().zip(d).enumerate() {
        match i {
            0 => k.c(format!("mul out, r{x}, r{e}")),
            _ if i + 1 < n => k.c(format!("mac out, r{x}, r{e}")),
            _ => k.c(format!("mac r{t}, r{x}, r{e}, >>Q14")),
        };
    }
    for (x, e) in p.iter().zip(d) {
        k.c(format!("ldacc r{x}, <<Q14"))
            .c(format!("msu r{x}, r{t}, r{e}, >>Q14"));
    }
}

/// `rem` = what the accumulator holds below `hi`, the rounded result a
/// multiplier operation just wrote with `>> shift`: the accumulator's
/// lower word less `hi << shift` (exact while the remainder is below
/// 2^15 in magnitude; the wrap of the shifted word is intended). `t` a
/// temporary.
pub fn remainder(k: &mut K, rem: u8, hi: u8, t: u8, shift: &str) {
    k.c(format!("accl r{rem}"))
        .c(format!("sll r{t}, r{hi}, #{shift}"))
        .c(format!("sub r{rem}, r{rem}, r{t}"));
}

/// Reciprocal square root table of `n` entries (a power of two up to 128):
/// entry k = 1/sqrt(X) for X = (k + 0.5) 2^(15 - log2 n) in Q.11, Q1.14
/// (saturated at the bottom, where it is never used).
pub fn rsq_table(n: usize) -> Vec<i32> {
    rsq_table_for(n, 0)
}

/// [`rsq_table`] with `x` extra fraction bits (16 on the 32-bit chip: the
/// same entries in Q1.30, indexed by X in Q.27).
pub fn rsq_table_for(n: usize, x: u32) -> Vec<i32> {
    let w = 32768.0 / n as f64;
    let one = ((14 + x) as f64).exp2();
    (0..n)
        .map(|k| {
            let v = (k as f64 + 0.5) * w / 2048.0;
            ((1.0 / v.sqrt()) * one).round().min(word_max(x)) as i32
        })
        .collect()
}

/// Reciprocal table of `n` entries: entry k = 2^29 / d for
/// d = 2^14 + (k + 0.5) 2^14 / n.
pub fn rcp_table(n: usize) -> Vec<i32> {
    rcp_table_for(n, 0)
}

/// [`rcp_table`] with `x` extra fraction bits: `2^(29 + 2x) / d` for
/// `d = 2^(14 + x) + (k + 0.5) 2^(14 + x) / n`.
pub fn rcp_table_for(n: usize, x: u32) -> Vec<i32> {
    let w = 16384.0 / n as f64;
    (0..n)
        .map(|k| {
            let d = 16384.0 + (k as f64 + 0.5) * w;
            (((29 + x) as f64).exp2() / d).round().min(word_max(x)) as i32
        })
        .collect()
}

/// The two 128-word table slots at the start of the init stream (RC RAM
/// `RSQ` and `RCP`): tables of `n` entries, the rest of each slot zero.
pub fn table_slots(n: usize) -> Vec<i32> {
    table_slots_for(n, 0)
}

/// [`table_slots`] with `x` extra fraction bits (the 32-bit chip: 16).
pub fn table_slots_for(n: usize, x: u32) -> Vec<i32> {
    let mut v = vec![0i32; 256];
    v[..n].copy_from_slice(&rsq_table_for(n, x));
    v[128..128 + n].copy_from_slice(&rcp_table_for(n, x));
    v
}

/// The largest word value with `x` extra bits (16-bit: 32767).
pub(crate) fn word_max(x: u32) -> f64 {
    ((15 + x) as f64).exp2() - 1.0
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The tables against the functions they sample.
    #[test]
    fn tables_match_their_definitions() {
        let rsq = rsq_table(128);
        for (k, &y) in rsq.iter().enumerate().skip(8) {
            let x = (k as f64 + 0.5) * 256.0 / 2048.0;
            assert!((y as f64 / 16384.0 - 1.0 / x.sqrt()).abs() < 1e-4);
        }
        let rcp = rcp_table(128);
        for (k, &r) in rcp.iter().enumerate() {
            assert!(r > 16384 && r < 32768, "{k}");
        }
    }
}
