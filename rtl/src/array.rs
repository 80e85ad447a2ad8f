//! The 8x8 RC array: 64 [`RcArray`] lanes, the [`Interconnect`] that feeds
//! their operand A, and the three broadcast modes.
//!
//! * **SIMD** (`cbcast`, `sbcb`, `dbcb`): one context drives all 64 RCs.
//! * **Row mode** (`cbcr`): row `i` executes word `i` of an 8-word context
//!   group; **column mode** (`cbcc`): column `j` executes word `j`.
//!
//! Guarded execution and sleep are the RCs' own (a guarded context executes
//! only where the flag F matches; a sleeping RC executes only `wake`).
//! [`Array::active_now`] is the number of RCs that executed in the cycle.
//!
//! Row and column modes are evaluated one row (column) at a time with the
//! operand A of every lane computed first from the start-of-cycle outputs;
//! since a lane reads other lanes only through operand A this is the same as
//! executing all rows at once. The clock edge of those rows is applied during
//! `eval`, so in a waveform the RC state of a row-/column-mode cycle already
//! shows its result.

use crate::interconnect::Interconnect;
use crate::kernel::{Clocked, Fault};
use crate::rc::context::{ASrc, Context};
use crate::rc::lanes::Mask;
use crate::rc::{LaneNames, RcArray, Word, CTX_FILTER};
use crate::trace::{Display, Probe, Traced};

/// How a context (group) is broadcast.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Mode {
    /// One context to all 64 RCs.
    Simd = 0,
    /// Row `i` gets word `i` of the group.
    Row = 1,
    /// Column `j` gets word `j` of the group.
    Col = 2,
}

pub(crate) const ROW_MASK: Mask = 0xFF;
pub(crate) const COL_MASK: Mask = 0x0101_0101_0101_0101;

/// Lanes of row `i` (mode Row) or column `i` (mode Col).
#[inline(always)]
pub(crate) fn group_mask(mode: Mode, i: usize) -> Mask {
    match mode {
        Mode::Row => ROW_MASK << (8 * i),
        _ => COL_MASK << i,
    }
}

pub struct Array<W: Word = i16> {
    pub rc: RcArray<64, W>,
    ic: Interconnect,
    // ---- inputs of this cycle ----
    active: bool,
    mode: Mode,
    ctx: [Context; 8],
    words: [u32; 8],
    fb: [W; 2],
    /// RCs that executed in the cycle just evaluated.
    pub active_now: u32,
}

impl<W: Word> Default for Array<W> {
    fn default() -> Self {
        Self::new()
    }
}

impl<W: Word> Array<W> {
    pub fn new() -> Array<W> {
        Array {
            rc: RcArray::new(LaneNames::Grid),
            ic: Interconnect::new(),
            active: false,
            mode: Mode::Simd,
            ctx: [Context::NOP; 8],
            words: [Context::NOP.encode(); 8],
            fb: [W::ZERO; 2],
            active_now: 0,
        }
    }

    /// Drive one SIMD context this cycle, with the FB broadcast data: the
    /// context goes straight to the RCs and the interconnect computes their
    /// operand A now, from the start-of-cycle outputs (call during `eval`).
    #[inline(always)]
    pub fn drive_simd(&mut self, word: u32, ctx: &Context, fb: [W; 2]) {
        self.active = true;
        self.mode = Mode::Simd;
        self.words[0] = word;
        self.fb = fb;
        self.ic
            .drive(ctx.asrc, ctx.ra, &self.rc.out, fb, &mut self.rc.ext);
        self.rc.set_context(word, *ctx);
        self.rc.lane_enable = u64::MAX;
    }

    /// A whole SIMD cycle: [`Array::drive_simd`] and [`Array::step`] in
    /// one (the untraced streaming loop). Returns the RCs that executed.
    #[inline(always)]
    pub fn step_simd(&mut self, word: u32, ctx: &Context, fb: [W; 2]) -> Result<u32, Fault> {
        self.drive_simd(word, ctx, fb);
        self.rc.step()?;
        self.active_now = self.rc.executed().count_ones();
        Ok(self.active_now)
    }

    /// Drive an 8-word group in row or column mode.
    pub fn drive_group(&mut self, mode: Mode, words: [u32; 8], ctx: [Context; 8], fb: [W; 2]) {
        self.active = true;
        self.mode = mode;
        self.ctx = ctx;
        self.words = words;
        self.fb = fb;
    }

    /// No context this cycle.
    #[inline(always)]
    pub fn idle(&mut self) {
        self.active = false;
        self.active_now = 0;
    }

    pub fn is_active(&self) -> bool {
        self.active
    }

    /// Does some awake RC have F (what `rcany` reads, and a cut)?
    #[inline(always)]
    pub fn any_awake_f(&self) -> bool {
        self.rc.flags.f & !self.rc.flags.sleep != 0
    }

    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Refuse two drivers on one lane bus (row/column mode, see
    /// [`crate::interconnect`]).
    fn check_lanes(&self) -> Result<(), Fault> {
        // In row mode the vertical lanes are shared by the rows; in column
        // mode the horizontal lanes by the columns.
        let (short, express) = match self.mode {
            Mode::Row => (ASrc::QCol, ASrc::XCol),
            Mode::Col => (ASrc::QRow, ASrc::XRow),
            Mode::Simd => return Ok(()),
        };
        let mut xsel: Option<(usize, u8)> = None;
        let mut qsel: [Option<(usize, u8)>; 2] = [None, None];
        for (i, c) in self.ctx.iter().enumerate() {
            let clash = if c.asrc == express {
                let k = c.ra & 7;
                match xsel {
                    Some((j, kk)) if kk != k => Some((j, kk, k)),
                    _ => {
                        xsel = Some((i, k));
                        None
                    }
                }
            } else if c.asrc == short {
                let k = c.ra & 3;
                match qsel[i / 4] {
                    Some((j, kk)) if kk != k => Some((j, kk, k)),
                    _ => {
                        qsel[i / 4] = Some((i, k));
                        None
                    }
                }
            } else {
                None
            };
            if let Some((j, kk, k)) = clash {
                let what = if self.mode == Mode::Row {
                    "row"
                } else {
                    "column"
                };
                return Err(Fault::new(
                    "array",
                    format!(
                        "lane conflict in {what} mode: {what} {j} reads lane index {kk} and {what} {i} index {k} of the same {} bus (`{}` vs `{}`)",
                        if c.asrc == express { "express" } else { "short" },
                        self.ctx[j],
                        c
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl<W: Word> Array<W> {
    /// [`Clocked::eval`] and [`Clocked::commit`] in one call (the
    /// untraced fast path: nothing samples between the two).
    #[inline(always)]
    pub fn step(&mut self) -> Result<(), Fault> {
        self.eval()?;
        self.commit();
        Ok(())
    }
}

impl<W: Word> Clocked for Array<W> {
    #[inline]
    fn eval(&mut self) -> Result<(), Fault> {
        if !self.active {
            self.active_now = 0;
            return Ok(());
        }
        if self.mode == Mode::Simd {
            self.rc.eval()?;
            self.active_now = self.rc.executed().count_ones();
            return Ok(());
        }
        self.check_lanes()?;
        // Operand A of every lane from the start-of-cycle outputs.
        let out = self.rc.out;
        for g in 0..8 {
            let lanes: [usize; 8] = std::array::from_fn(|k| match self.mode {
                Mode::Row => g * 8 + k,
                _ => k * 8 + g,
            });
            let c = self.ctx[g];
            self.ic
                .drive_lanes(c.asrc, c.ra, &lanes, &out, self.fb, &mut self.rc.ext);
        }
        let mut n = 0;
        for g in 0..8 {
            self.rc.set_context(self.words[g], self.ctx[g]);
            self.rc.lane_enable = group_mask(self.mode, g);
            self.rc.step()?;
            n += self.rc.executed().count_ones();
        }
        self.rc.lane_enable = u64::MAX;
        self.active_now = n;
        Ok(())
    }

    #[inline]
    fn commit(&mut self) {
        if self.active && self.mode == Mode::Simd {
            self.rc.commit();
        }
    }
}

impl<W: Word> Traced for Array<W> {
    fn trace<P: Probe>(&self, p: &mut P) {
        // Asked once which of these are traced: a trace of one RC computes
        // none of them.
        const NAMES: [&str; 13] = [
            "active",
            "mode",
            "active_rcs",
            "ctx_g0",
            "ctx_g1",
            "ctx_g2",
            "ctx_g3",
            "ctx_g4",
            "ctx_g5",
            "ctx_g6",
            "ctx_g7",
            "fb0",
            "fb1",
        ];
        let on = p.traced_signals(&NAMES);
        if on & 1 != 0 {
            p.signal("active", 1, Display::Bin, self.active as u64);
        }
        if on & 2 != 0 {
            p.signal("mode", 2, Display::Hex, self.mode as u64);
        }
        if on & 4 != 0 {
            p.signal("active_rcs", 7, Display::Hex, self.active_now as u64);
        }
        for (g, w) in self.words.iter().enumerate() {
            if on >> (3 + g) & 1 == 0 {
                continue;
            }
            let v = if self.active && (g == 0 || self.mode != Mode::Simd) {
                *w
            } else {
                Context::NOP.encode()
            };
            p.signal(NAMES[3 + g], 32, Display::Translate(&CTX_FILTER), v as u64);
        }
        let bits = W::BITS;
        let m = u64::MAX >> (64 - bits);
        if on >> 11 & 1 != 0 {
            p.signal("fb0", bits, Display::Signed, self.fb[0].to_i64() as u64 & m);
        }
        if on >> 12 & 1 != 0 {
            p.signal("fb1", bits, Display::Signed, self.fb[1].to_i64() as u64 & m);
        }
        self.rc.trace(p);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rc::context::{BSrc, Guard, Op};

    fn ctx(op: Op, rd: u8, asrc: ASrc, ra: u8, b: BSrc) -> Context {
        Context {
            op,
            we: op.has_result(),
            rd,
            asrc,
            ra,
            b,
            ..Context::NOP
        }
    }

    fn step(a: &mut Array, c: Context) {
        a.drive_simd(c.encode(), &c, [0, 0]);
        a.eval().unwrap();
        a.commit();
    }

    /// out[i] = value via `movb out, #v` per lane is impossible in SIMD, so
    /// poke registers and move them to out.
    fn load_out(a: &mut Array, vals: &[i16; 64]) {
        for (i, v) in vals.iter().enumerate() {
            a.rc.regs.poke(i, 1, *v);
        }
        step(a, ctx(Op::Mov, 1, ASrc::Reg, 1, BSrc::Reg(0)));
    }

    #[test]
    fn simd_broadcast_reaches_every_rc_and_counts_them() {
        let mut a = Array::new();
        let v: [i16; 64] = std::array::from_fn(|i| i as i16 * 3 - 50);
        load_out(&mut a, &v);
        step(&mut a, ctx(Op::Add, 2, ASrc::Out, 0, BSrc::Imm(7)));
        assert_eq!(a.active_now, 64);
        for i in 0..64 {
            assert_eq!(a.rc.out[i], v[i] + 7);
        }
    }

    #[test]
    fn guarded_and_sleeping_rcs_do_not_execute() {
        let mut a = Array::new();
        let v: [i16; 64] = std::array::from_fn(|i| i as i16);
        load_out(&mut a, &v);
        // f = out < 20
        let mut cmp = ctx(Op::Cmp, 2, ASrc::Out, 0, BSrc::Imm(20)); // rd=2: lt
        cmp.we = false;
        step(&mut a, cmp);
        // lanes >= 20 sleep
        let mut sl = ctx(Op::Sleep, 0, ASrc::Reg, 0, BSrc::Reg(0));
        sl.guard = Guard::IfNotF;
        step(&mut a, sl);
        assert_eq!(a.active_now, 44);
        // then: (f) add out, out, #100 ; only lanes < 20 run
        let mut add = ctx(Op::Add, 0, ASrc::Out, 0, BSrc::Imm(100));
        add.we = false;
        add.guard = Guard::IfF;
        step(&mut a, add);
        assert_eq!(a.active_now, 20);
        // unguarded add still skips the 44 sleepers
        step(&mut a, ctx(Op::Add, 3, ASrc::Out, 0, BSrc::Imm(1)));
        assert_eq!(a.active_now, 20);
        for i in 0..64 {
            let want = if i < 20 { i as i16 + 101 } else { i as i16 };
            assert_eq!(a.rc.out[i], want, "lane {i}");
        }
        step(&mut a, ctx(Op::Wake, 0, ASrc::Reg, 0, BSrc::Reg(0)));
        assert_eq!(a.rc.flags.sleep, 0);
    }

    #[test]
    fn row_mode_gives_each_row_its_word_and_column_mode_each_column() {
        for mode in [Mode::Row, Mode::Col] {
            let mut a = Array::new();
            let ctxs: [Context; 8] = std::array::from_fn(|g| {
                ctx(Op::Movb, 4, ASrc::Reg, 0, BSrc::Imm(10 * g as i16 + 1))
            });
            a.drive_group(mode, ctxs.map(|c| c.encode()), ctxs, [0, 0]);
            a.eval().unwrap();
            a.commit();
            assert_eq!(a.active_now, 64);
            for r in 0..8 {
                for c in 0..8 {
                    let g = if mode == Mode::Row { r } else { c };
                    assert_eq!(a.rc.out[r * 8 + c], 10 * g as i16 + 1, "{mode:?} ({r},{c})");
                }
            }
        }
    }

    #[test]
    fn row_mode_reads_start_of_cycle_outputs() {
        // Every row reads its north neighbour; if rows ran in order, row 1
        // would see row 0's new value.
        let mut a = Array::new();
        let v: [i16; 64] = std::array::from_fn(|i| (i / 8) as i16);
        load_out(&mut a, &v);
        let c = ctx(Op::Add, 5, ASrc::Nbr, 0, BSrc::Imm(100));
        a.drive_group(Mode::Row, [c.encode(); 8], [c; 8], [0, 0]);
        a.eval().unwrap();
        a.commit();
        for r in 0..8 {
            assert_eq!(a.rc.out[r * 8], ((r + 7) % 8) as i16 + 100);
        }
    }

    #[test]
    fn two_drivers_on_a_vertical_express_lane_in_row_mode_fault() {
        let mut a = Array::new();
        let mut ctxs = [ctx(Op::Mov, 1, ASrc::XCol, 2, BSrc::Reg(0)); 8];
        ctxs[5].ra = 3;
        a.drive_group(Mode::Row, ctxs.map(|c| c.encode()), ctxs, [0, 0]);
        let e = a.eval().unwrap_err();
        assert!(e.message.contains("lane conflict"), "{e}");
        // the same selection everywhere is fine, and so are horizontal lanes
        let ctxs = [ctx(Op::Mov, 1, ASrc::XCol, 2, BSrc::Reg(0)); 8];
        a.drive_group(Mode::Row, ctxs.map(|c| c.encode()), ctxs, [0, 0]);
        a.eval().unwrap();
        let ctxs: [Context; 8] =
            std::array::from_fn(|g| ctx(Op::Mov, 1, ASrc::XRow, g as u8, BSrc::Reg(0)));
        a.drive_group(Mode::Row, ctxs.map(|c| c.encode()), ctxs, [0, 0]);
        a.eval().unwrap();
        // column mode: horizontal short lanes of one half must agree
        let mut ctxs = [ctx(Op::Mov, 1, ASrc::QRow, 1, BSrc::Reg(0)); 8];
        ctxs[6].ra = 2;
        a.drive_group(Mode::Col, ctxs.map(|c| c.encode()), ctxs, [0, 0]);
        assert!(a.eval().is_err());
        ctxs[6].ra = 1;
        ctxs[2].ra = 0; // other half: a different bus
        ctxs[0].ra = 0;
        ctxs[1].ra = 0;
        ctxs[3].ra = 0;
        a.drive_group(Mode::Col, ctxs.map(|c| c.encode()), ctxs, [0, 0]);
        a.eval().unwrap();
    }

    #[test]
    fn every_interconnect_path_through_the_array() {
        // Each path against a coordinate reference, executed by the RCs.
        let mut a = Array::new();
        let v: [i16; 64] = std::array::from_fn(|i| (i / 8 * 10 + i % 8) as i16);
        let sources: &[(ASrc, u8)] = &[
            (ASrc::Nbr, 0),
            (ASrc::Nbr, 1),
            (ASrc::Nbr, 2),
            (ASrc::Nbr, 3),
            (ASrc::QRow, 2),
            (ASrc::QCol, 3),
            (ASrc::XRow, 6),
            (ASrc::XCol, 1),
        ];
        for &(s, k) in sources {
            load_out(&mut a, &v);
            step(&mut a, ctx(Op::Mov, 6, s, k, BSrc::Reg(0)));
            for r in 0..8usize {
                for c in 0..8usize {
                    let (sr, sc) = match (s, k) {
                        (ASrc::Nbr, 0) => ((r + 7) % 8, c),
                        (ASrc::Nbr, 1) => ((r + 1) % 8, c),
                        (ASrc::Nbr, 2) => (r, (c + 7) % 8),
                        (ASrc::Nbr, _) => (r, (c + 1) % 8),
                        (ASrc::QRow, k) => (r, (c / 4) * 4 + k as usize),
                        (ASrc::QCol, k) => ((r / 4) * 4 + k as usize, c),
                        (ASrc::XRow, k) => (r, k as usize),
                        (_, k) => (k as usize, c),
                    };
                    assert_eq!(
                        a.rc.out[r * 8 + c],
                        (sr * 10 + sc) as i16,
                        "{s:?}{k} ({r},{c})"
                    );
                }
            }
        }
        // the FB datum
        let c = ctx(Op::Add, 6, ASrc::Fb, 1, BSrc::Imm(1));
        a.drive_simd(c.encode(), &c, [5, 40]);
        a.eval().unwrap();
        a.commit();
        assert!(a.rc.out.iter().all(|&x| x == 41));
    }
}
