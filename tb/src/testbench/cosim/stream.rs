//! The co-simulation's stimulus: the RC testbench's stream, random
//! streams of every legal operation for one RC, and random array streams
//! (SIMD, row and column modes, every interconnect source).

use rtl::array::Mode;
use rtl::rc::context::{ASrc, BSrc, Context, Guard, Op, ALL_OPS};
use rtl::rc::Datapath;

use super::super::rc::Rng;

/// One cycle of the stream: a context word (legal or not), the datum on
/// the external operand input, and the array's lane enable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Step {
    pub ctx: u32,
    pub ext: i64,
    pub lane_en: bool,
}

/// The RC testbench's stimulus ([`super::super::rc::stimulus`], its directed and
/// random parts) as a stream; on the 32-bit RC its data are sign-extended.
pub fn testbench_stream() -> Vec<Step> {
    super::super::rc::stimulus()
        .iter()
        .map(|s| Step {
            ctx: s.ctx.encode(),
            ext: s.ext as i64,
            lane_en: true,
        })
        .collect()
}

/// `n` random cycles from `seed` for the RC of width `dp`: any operation,
/// guard, operand source, destination, immediate and multiplier shift
/// (0..63 on the 32-bit RC), data at the word's edges, small and random;
/// one word in fifty entirely random (mostly illegal), one `ld` / `st` in
/// five at a random address (mostly a fault); the lane enable off one
/// cycle in twenty; sleeps kept short.
pub fn random_stream(dp: Datapath, n: usize, seed: u64) -> Vec<Step> {
    let bits = dp.bits();
    let mut g = Rng(seed | 1);
    let mut s = Vec::with_capacity(n);
    let mut asleep = false;
    for _ in 0..n {
        let lane_en = !g.chance(5);
        if g.chance(2) {
            s.push(Step {
                ctx: g.next() as u32,
                ext: value(&mut g, bits),
                lane_en,
            });
            continue;
        }
        let mut op = ALL_OPS[g.below(ALL_OPS.len() as u64) as usize];
        if op == Op::Sleep && g.below(4) != 0 {
            op = Op::Mov;
        }
        if asleep && g.below(4) == 0 {
            op = Op::Wake;
        }
        let asrc = match g.below(10) {
            0..=3 => ASrc::Reg,
            4 | 5 => ASrc::Out,
            6 => ASrc::Nbr,
            7 => ASrc::XRow,
            8 => ASrc::QCol,
            _ => ASrc::Fb,
        };
        let ra = g.below(16) as u8;
        let mut ctx = context(&mut g, bits, op, asrc, ra);
        let mut ext = value(&mut g, bits);
        if matches!(op, Op::Ld | Op::St) && !g.chance(20) {
            if let Some(x) = address_in_range(&mut g, &mut ctx) {
                ext = x;
            }
        }
        if op == Op::Sleep && ctx.guard == Guard::Always && lane_en {
            asleep = true;
        }
        if op == Op::Wake {
            asleep = false;
        }
        s.push(Step {
            ctx: ctx.encode(),
            ext,
            lane_en,
        });
    }
    s
}

/// A datum of `bits` bits: at the word's edges, small, or any.
fn value(g: &mut Rng, bits: u32) -> i64 {
    let min = -(1i64 << (bits - 1));
    let max = (1i64 << (bits - 1)) - 1;
    match g.below(6) {
        0 | 1 => [min, -1, 0, 1, max, min + 1, max - 1][g.below(7) as usize],
        2 => g.below(81) as i64 - 40,
        _ => (g.next() as i64) >> (64 - bits),
    }
}

/// A context of `op` with operand A from `asrc` / `ra`, and at random its
/// guard, destination, operand B and multiplier shift (up to 2 `bits`).
fn context(g: &mut Rng, bits: u32, op: Op, asrc: ASrc, ra: u8) -> Context {
    let guard = [Guard::Always, Guard::Always, Guard::IfF, Guard::IfNotF][g.below(4) as usize];
    let b = if g.chance(50) {
        BSrc::Reg(g.below(16) as u8)
    } else {
        BSrc::Imm(g.below(2048) as i16 - 1024)
    };
    let mut ctx = Context {
        op,
        guard,
        we: g.below(4) != 0,
        rd: g.below(16) as u8,
        asrc,
        ra,
        b,
        shift: 0,
        trunc: false,
    };
    if matches!(b, BSrc::Reg(_)) {
        ctx.shift = g.below(2 * bits as u64) as u8;
        ctx.trunc = g.chance(50);
    }
    ctx
}

/// Make a `ld` / `st` address a valid one: `ld rd, [fbK + #i]` with the
/// FB datum returned (0..255 each), `st A, [#i]`.
fn address_in_range(g: &mut Rng, ctx: &mut Context) -> Option<i64> {
    ctx.shift = 0;
    ctx.trunc = false;
    if ctx.op == Op::St {
        ctx.b = BSrc::Imm(g.below(512) as i16);
        return None;
    }
    ctx.asrc = ASrc::Fb;
    ctx.ra = g.below(2) as u8;
    ctx.b = BSrc::Imm(g.below(256) as i16);
    Some(g.below(256) as i64)
}

/// One cycle of the array's stream: whether a context runs, the broadcast
/// mode, the 8 context words (SIMD: word 0) and the two FB data.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ArrayStep {
    pub active: bool,
    pub mode: Mode,
    pub words: [u32; 8],
    pub fb: [i64; 2],
}

/// `n` random cycles of the array from `seed`: one cycle in five in row
/// or column mode, any legal operation with every interconnect source
/// (neighbours, short and express lanes, FB data) often, RAM addresses in
/// range, and in each cycle one lane index per lane bus (two rows of a
/// row-mode group asking one vertical lane for different drivers is a
/// fault of the chip, not a cycle to compare).
///
/// With `simd_only` every cycle is SIMD (as nearly every cycle of the ray
/// tracer is; `tb cosim --bench` times that).
pub fn array_stream(dp: Datapath, n: usize, seed: u64, simd_only: bool) -> Vec<ArrayStep> {
    let bits = dp.bits();
    let mut g = Rng(seed | 1);
    let mut s = Vec::with_capacity(n);
    for _ in 0..n {
        let mode = match g.below(10) {
            _ if simd_only => Mode::Simd,
            0 => Mode::Row,
            1 => Mode::Col,
            _ => Mode::Simd,
        };
        let (kx, kq) = (g.below(8) as u8, g.below(4) as u8);
        let mut fb = [value(&mut g, bits), value(&mut g, bits)];
        let mut words = [0u32; 8];
        for w in words.iter_mut() {
            let mut op = ALL_OPS[g.below(ALL_OPS.len() as u64) as usize];
            // Sleep seldom and wake often: the array stays mostly awake.
            if op == Op::Sleep && g.below(4) != 0 {
                op = Op::Wake;
            }
            let asrc = [
                ASrc::Reg,
                ASrc::Out,
                ASrc::Nbr,
                ASrc::QRow,
                ASrc::QCol,
                ASrc::XRow,
                ASrc::XCol,
                ASrc::Fb,
            ][g.below(8) as usize];
            let ra = match asrc {
                ASrc::Nbr => g.below(4) as u8,
                ASrc::QRow | ASrc::QCol => kq,
                ASrc::XRow | ASrc::XCol => kx,
                ASrc::Fb => g.below(2) as u8,
                _ => g.below(16) as u8,
            };
            let mut ctx = context(&mut g, bits, op, asrc, ra);
            if matches!(op, Op::Ld | Op::St) {
                if let Some(x) = address_in_range(&mut g, &mut ctx) {
                    // both sets small: the group's other loads read them too
                    fb = [x, g.below(256) as i64];
                }
            }
            *w = ctx.encode();
        }
        s.push(ArrayStep {
            active: !g.chance(5),
            mode,
            words,
            fb,
        });
    }
    s
}
