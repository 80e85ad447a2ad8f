//! The RC's units over every lane: each operation's lanes as one loop
//! (or one per rounding choice or condition, chosen outside the lanes),
//! the flags gathered into masks; [`super::RcArray`]'s evaluation calls
//! them once per context, the operation matched there.

use super::alu;
use super::context::{BSrc, Cond, Context, Op};
use super::lanes::{full, Mask, SignBits};
use super::ram::Ram;
use super::word::{expand, Word};

/// Run a flag-producing ALU function over every lane. The flags are
/// gathered as 0 / -1 lanes of the loop's own width and packed by their
/// sign bits ([`SignBits::sign_mask`]).
#[inline(always)]
pub(super) fn cv<W: Word, const N: usize>(
    res: &mut [W; N],
    f: impl Fn(usize) -> alu::Flagged<W>,
) -> (Mask, Mask) {
    let mut c = [W::ZERO; N];
    let mut v = [W::ZERO; N];
    for i in 0..N {
        let r = f(i);
        res[i] = r.value;
        c[i] = W::flag(r.c);
        v[i] = W::flag(r.v);
    }
    (W::sign_mask(&c), W::sign_mask(&v))
}

/// Is every lane of `x` alike? (An OR of differences: it vectorises,
/// where a comparison that stops at the first difference did not.)
#[inline(always)]
pub(super) fn same<W: Word, const N: usize>(x: &[W; N]) -> bool {
    let x0 = x[0];
    x.iter().fold(W::ZERO, |m, &v| m | (v ^ x0)) == W::ZERO
}

/// Run a multiplier lane function (lane `i`'s new accumulator, result and
/// saturation) over every lane; returns the saturation mask. 32 lanes at a
/// time, each chunk's flags gathered into the mask at once (faster than
/// one loop over all the lanes with the flags stored as a lane array and
/// gathered after it).
#[inline(always)]
fn mul_lanes<W: Word, const N: usize>(
    res: &mut [W; N],
    acc_d: &mut [W::Acc; N],
    f: impl Fn(usize) -> (W::Acc, W, bool),
) -> Mask {
    const C: usize = 32;
    if N.is_multiple_of(C) {
        let mut m = 0;
        for k in 0..N / C {
            let mut r = [W::ZERO; C];
            let mut s = [W::Acc::default(); C];
            for j in 0..C {
                let (n, x, v) = f(k * C + j);
                acc_d[k * C + j] = n;
                r[j] = x;
                s[j] = W::Acc::flag(v);
            }
            res[k * C..k * C + C].copy_from_slice(&r);
            m |= W::Acc::sign_mask(&s) << (k * C);
        }
        return m;
    }
    let mut s = [W::Acc::default(); N];
    for i in 0..N {
        let (n, x, v) = f(i);
        acc_d[i] = n;
        res[i] = x;
        s[i] = W::Acc::flag(v);
    }
    W::Acc::sign_mask(&s)
}

/// Run a saturating function over every lane; returns the saturation mask.
#[inline(always)]
fn sat<W: Word, const N: usize>(res: &mut [W; N], f: impl Fn(usize) -> (W, bool)) -> Mask {
    let mut v = [W::ZERO; N];
    for i in 0..N {
        let (r, s) = f(i);
        res[i] = r;
        v[i] = W::flag(s);
    }
    W::sign_mask(&v)
}

/// The multiplier's output stage over every lane: the accumulator shifted
/// right by `sh` (rounded unless `trunc`) and saturated to the word;
/// returns the saturated lanes. The rounding choice is made once, outside
/// the lane loop (`sh = 0` has no rounding bit either way).
#[inline(always)]
pub(super) fn scale_lanes<W: Word, const N: usize>(
    acc: &[W::Acc; N],
    sh: u32,
    trunc: bool,
    res: &mut [W; N],
) -> Mask {
    if trunc || sh & (2 * W::BITS - 1) == 0 {
        sat(res, |i| W::scale(acc[i], sh, true))
    } else {
        sat(res, |i| W::scale(acc[i], sh, false))
    }
}

/// The flag F of every lane for `cmp` (before the merge with the executing
/// lanes): the condition chosen once, each arm a loop over the lanes (the
/// condition inside the loop kept it from vectorising).
#[inline(always)]
pub(super) fn cmp_mask<W: Word, const N: usize>(
    cond: Cond,
    a: &[W; N],
    b: &[W; N],
    cf: Mask,
    vf: Mask,
) -> Mask {
    macro_rules! by {
        ($k:expr) => {{
            let mut f = [W::ZERO; N];
            for i in 0..N {
                f[i] = W::flag(W::cond($k, a[i], b[i], false, false));
            }
            W::sign_mask(&f)
        }};
    }
    match cond {
        Cond::Eq => by!(Cond::Eq),
        Cond::Ne => by!(Cond::Ne),
        Cond::Lt => by!(Cond::Lt),
        Cond::Ge => by!(Cond::Ge),
        Cond::Le => by!(Cond::Le),
        Cond::Gt => by!(Cond::Gt),
        Cond::Ltu => by!(Cond::Ltu),
        Cond::Geu => by!(Cond::Geu),
        Cond::Leu => by!(Cond::Leu),
        Cond::Gtu => by!(Cond::Gtu),
        Cond::Bit => by!(Cond::Bit),
        Cond::Nbit => by!(Cond::Nbit),
        Cond::Cs => cf & full(N),
        Cond::Vs => vf & full(N),
        Cond::True => full(N),
        Cond::False => 0,
    }
}

/// `add adc sub sbc rsb neg`: the results, and the carry (borrow) and
/// overflow masks (`cin`: the carry flag).
#[inline(always)]
pub(super) fn add_sub<W: Word, const N: usize>(
    op: Op,
    a: &[W; N],
    b: &[W; N],
    cin: Mask,
    res: &mut [W; N],
) -> (Mask, Mask) {
    match op {
        Op::Add => cv(res, |i| W::add(a[i], b[i], false)),
        Op::Adc => cv(res, |i| W::add(a[i], b[i], cin >> i & 1 != 0)),
        Op::Sub => cv(res, |i| W::sub(a[i], b[i], false)),
        Op::Sbc => cv(res, |i| W::sub(a[i], b[i], cin >> i & 1 != 0)),
        Op::Rsb => cv(res, |i| W::sub(b[i], a[i], false)),
        _ => cv(res, |i| W::sub(W::ZERO, a[i], false)),
    }
}

/// `adds subs abs absd asl`: the results and the saturated lanes.
#[inline(always)]
pub(super) fn saturating<W: Word, const N: usize>(
    op: Op,
    a: &[W; N],
    b: &[W; N],
    res: &mut [W; N],
) -> Mask {
    match op {
        Op::Adds => sat(res, |i| W::adds(a[i], b[i])),
        Op::Subs => sat(res, |i| W::subs(a[i], b[i])),
        Op::Abs => sat(res, |i| W::abs(a[i])),
        Op::Absd => sat(res, |i| W::absd(a[i], b[i])),
        _ => sat(res, |i| W::asl(a[i], W::amount(b[i]))),
    }
}

/// `and or xor not min max clz`.
#[inline(always)]
pub(super) fn logic<W: Word, const N: usize>(op: Op, a: &[W; N], b: &[W; N], res: &mut [W; N]) {
    match op {
        Op::And => map!(res, |i| a[i] & b[i]),
        Op::Or => map!(res, |i| a[i] | b[i]),
        Op::Xor => map!(res, |i| a[i] ^ b[i]),
        Op::Not => map!(res, |i| !a[i]),
        Op::Min => map!(res, |i| a[i].min(b[i])),
        Op::Max => map!(res, |i| a[i].max(b[i])),
        _ => map!(res, |i| W::clz(a[i])),
    }
}

/// `sll srl sra`: the shifter.
#[inline(always)]
pub(super) fn shift<W: Word, const N: usize>(op: Op, a: &[W; N], b: &[W; N], res: &mut [W; N]) {
    match op {
        Op::Sll => map!(res, |i| W::sll(a[i], W::amount(b[i]))),
        Op::Srl => map!(res, |i| W::srl(a[i], W::amount(b[i]))),
        _ => map!(res, |i| W::sra(a[i], W::amount(b[i]))),
    }
}

/// `sel`: A where F (`f`), else B.
#[inline(always)]
pub(super) fn select<W: Word, const N: usize>(f: Mask, a: &[W; N], b: &[W; N], res: &mut [W; N]) {
    if N.is_multiple_of(8) {
        // F expanded to 0 / -1 lanes and blended (the bit tested lane by
        // lane did not vectorise).
        let m = expand::<W, N>(f);
        map!(res, |i| (a[i] & m[i]) | (b[i] & !m[i]))
    } else {
        map!(res, |i| if f >> i & 1 != 0 { a[i] } else { b[i] })
    }
}

/// `mul mac msu`: the new accumulators (`acc_d`) and results, scaled by
/// `sh` (rounded unless `trunc`); returns the saturated lanes. One loop
/// per operation and rounding choice (chosen once, outside the lanes;
/// `sh = 0` has no rounding bit either way): the product is scaled while
/// it is in a register, not stored and loaded back.
#[inline(always)]
pub(super) fn multiply<W: Word, const N: usize>(
    op: Op,
    a: &[W; N],
    b: &[W; N],
    acc: &[W::Acc; N],
    acc_d: &mut [W::Acc; N],
    res: &mut [W; N],
    (sh, trunc): (u32, bool),
) -> Mask {
    macro_rules! lanes {
        ($trunc:expr) => {
            match op {
                Op::Mul => mul_lanes(res, acc_d, |i| {
                    let p = W::product(a[i], b[i]);
                    let (r, s2) = W::scale(p, sh, $trunc);
                    (p, r, s2)
                }),
                _ => {
                    let sub = op == Op::Msu;
                    mul_lanes(res, acc_d, |i| {
                        let p = W::product(a[i], b[i]);
                        let (n, s1) = W::accumulate(acc[i], p, sub);
                        let (r, s2) = W::scale(n, sh, $trunc);
                        (n, r, s1 | s2)
                    })
                }
            }
        };
    }
    if trunc || sh & (2 * W::BITS - 1) == 0 {
        lanes!(true)
    } else {
        lanes!(false)
    }
}

/// `ldacc`: A shifted left by `sh` into the accumulators. The shift the
/// tracer uses (a Q.14 or Q.30 product's scale) cannot saturate: no clamp
/// in a wider type.
#[inline(always)]
pub(super) fn load_acc<W: Word, const N: usize>(a: &[W; N], sh: u32, acc_d: &mut [W::Acc; N]) {
    let sh = sh & (2 * W::BITS - 1);
    if sh < W::BITS {
        for i in 0..N {
            acc_d[i] = W::ldacc_narrow(a[i], sh);
        }
    } else {
        for i in 0..N {
            acc_d[i] = W::ldacc(a[i], sh);
        }
    }
}

/// A `ld`'s (`A + B`) or `st`'s (`B`) RAM addresses, checked for the
/// executing lanes `en`: one address in every lane (constants, the stack,
/// the hit record: a whole RAM row, one address to check and keep, in
/// `addr0`), else one word per lane (in `addr`). Operands alike in every
/// lane (an immediate, one base) give one address without computing 64;
/// otherwise the addresses are compared. Returns whether the address is
/// one, or the first faulting lane and why.
#[inline(always)]
pub(super) fn ram_address<W: Word, const N: usize>(
    c: &Context,
    a: &[W; N],
    b: &[W; N],
    en: Mask,
    store: bool,
    (addr, addr0): (&mut [u16; N], &mut u16),
) -> Result<bool, (usize, String)> {
    // lane 0's address from its operands
    let a0 = if store {
        W::addr1(b[0])
    } else {
        W::addr(a[0], b[0])
    };
    let b_same = matches!(c.b, BSrc::Imm(_)) || same(b);
    let uniform = if b_same && (store || same(a)) {
        true
    } else {
        let mut each = [0i32; N];
        if store {
            map!(each, |i| W::addr1(b[i]));
        } else {
            map!(each, |i| W::addr(a[i], b[i]));
        }
        let uniform = each.iter().fold(true, |u, &x| u & (x == a0));
        if !uniform {
            let mut bad = [false; N];
            for i in 0..N {
                bad[i] = !Ram::<N, W>::valid(each[i]);
            }
            let bad = super::lanes::pack_bools(&bad) & en;
            if bad != 0 {
                let i = bad.trailing_zeros() as usize;
                return Err((i, format!("RAM address {} outside 0..=511", each[i])));
            }
            for i in 0..N {
                addr[i] = each[i].clamp(0, 511) as u16;
            }
        }
        uniform
    };
    if uniform {
        if !Ram::<N, W>::valid(a0) {
            let i = en.trailing_zeros() as usize;
            return Err((i, format!("RAM address {a0} outside 0..=511")));
        }
        *addr0 = a0 as u16;
    }
    Ok(uniform)
}

/// `ld`'s data: the RAM row at `addr0` where the address is one
/// (`uniform`), else each lane's word at its `addr`.
#[inline(always)]
pub(super) fn load<W: Word, const N: usize>(
    ram: &Ram<N, W>,
    uniform: bool,
    addr0: u16,
    addr: &[u16; N],
    res: &mut [W; N],
) {
    if uniform {
        *res = *ram.row(addr0 as usize);
    } else {
        for i in 0..N {
            res[i] = ram.read(i, addr[i] as usize);
        }
    }
}

/// `acch accl`: the accumulator's high or low word.
#[inline(always)]
pub(super) fn acc_part<W: Word, const N: usize>(op: Op, acc: &[W::Acc; N], res: &mut [W; N]) {
    match op {
        Op::Acch => map!(res, |i| W::acch(acc[i])),
        _ => map!(res, |i| W::accl(acc[i])),
    }
}
