//! An independent reference model of one RC, for the RC testbench.
//!
//! Written from `docs/isa.md`, not from `rtl/src/rc`: plain scalar code in
//! i64 arithmetic with explicit clamping and wrapping, one match arm per
//! operation. It shares only the context decoder (whose fields are
//! round-trip tested in `rtl`).

use rtl::rc::context::{ASrc, BSrc, Cond, Context, Guard, Op};

/// State of one RC as the reference sees it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct RefRc {
    pub r: [i64; 16],
    pub out: i64,
    pub acc: i64,
    pub f: bool,
    pub c: bool,
    pub v: bool,
    pub sleep: bool,
    pub ram: Vec<i64>,
}

impl Default for RefRc {
    fn default() -> Self {
        RefRc {
            r: [0; 16],
            out: 0,
            acc: 0,
            f: false,
            c: false,
            v: false,
            sleep: false,
            ram: vec![0; 512],
        }
    }
}

const MIN16: i64 = -32768;
const MAX16: i64 = 32767;

fn wrap16(x: i64) -> i64 {
    let m = x.rem_euclid(65536);
    if m > MAX16 {
        m - 65536
    } else {
        m
    }
}

fn u16of(x: i64) -> i64 {
    x.rem_euclid(65536)
}

fn sat16(x: i64) -> (i64, bool) {
    let y = x.clamp(MIN16, MAX16);
    (y, y != x)
}

fn sat32(x: i64) -> (i64, bool) {
    let y = x.clamp(i32::MIN as i64, i32::MAX as i64);
    (y, y != x)
}

/// `acc / 2^sh`, rounded half up unless `trunc`, then saturated to 16 bits.
fn scale(acc: i64, sh: u32, trunc: bool) -> (i64, bool) {
    let num = if trunc || sh == 0 {
        acc
    } else {
        acc + (1 << (sh - 1))
    };
    sat16(num.div_euclid(1 << sh))
}

/// What one executed context changes, for the testbench to check.
#[derive(Debug)]
pub enum Outcome {
    /// The RC did not execute the context (guard or sleep).
    Skipped,
    Executed,
    /// The reference expects a fault (RAM address out of range).
    Fault(i64),
}

impl RefRc {
    /// Execute `c` with `ext` as operand A for the non-register sources.
    pub fn step(&mut self, c: &Context, ext: i64) -> Outcome {
        let pass = match c.guard {
            Guard::Always => true,
            Guard::IfF => self.f,
            Guard::IfNotF => !self.f,
        };
        if !pass || (self.sleep && c.op != Op::Wake) {
            return Outcome::Skipped;
        }
        let a = match c.asrc {
            ASrc::Reg => self.r[c.ra as usize],
            ASrc::Out => self.out,
            _ => ext,
        };
        let b = match c.b {
            BSrc::Reg(k) => self.r[k as usize],
            BSrc::Imm(i) => i as i64,
        };
        let n = (u16of(b) % 32) as u32;
        let sh = c.shift as u32;
        let mut result: Option<i64> = None;
        let set_cv = |s: &mut RefRc, cf: bool, vf: bool| {
            s.c = cf;
            s.v = vf;
        };
        match c.op {
            Op::Nop => {}
            Op::Add | Op::Adc => {
                let cin = (c.op == Op::Adc && self.c) as i64;
                let exact = a + b + cin;
                set_cv(self, u16of(a) + u16of(b) + cin > 0xFFFF, sat16(exact).1);
                result = Some(wrap16(exact));
            }
            Op::Sub | Op::Sbc | Op::Rsb | Op::Neg => {
                let (x, y, bin) = match c.op {
                    Op::Sub => (a, b, 0),
                    Op::Sbc => (a, b, self.c as i64),
                    Op::Rsb => (b, a, 0),
                    _ => (0, a, 0),
                };
                let exact = x - y - bin;
                set_cv(self, u16of(x) < u16of(y) + bin, sat16(exact).1);
                result = Some(wrap16(exact));
            }
            Op::Adds | Op::Subs | Op::Abs | Op::Absd | Op::Asl => {
                let exact = match c.op {
                    Op::Adds => a + b,
                    Op::Subs => a - b,
                    Op::Abs => a.abs(),
                    Op::Absd => (a - b).abs(),
                    _ => a * (1i64 << n),
                };
                let (y, s) = sat16(exact);
                set_cv(self, false, s);
                result = Some(y);
            }
            Op::And => result = Some(wrap16(a & b)),
            Op::Or => result = Some(wrap16(a | b)),
            Op::Xor => result = Some(wrap16(a ^ b)),
            Op::Not => result = Some(wrap16(-a - 1)),
            Op::Mov => result = Some(a),
            Op::Movb => result = Some(b),
            Op::Min => result = Some(a.min(b)),
            Op::Max => result = Some(a.max(b)),
            Op::Clz => {
                let u = u16of(a);
                result = Some((0..16).take_while(|k| u & (0x8000 >> k) == 0).count() as i64);
            }
            Op::Sel => result = Some(if self.f { a } else { b }),
            Op::Cmp => self.f = self.holds(c.cond(), a, b),
            Op::Sll => result = Some(if n >= 16 { 0 } else { wrap16(u16of(a) << n) }),
            Op::Srl => result = Some(if n >= 16 { 0 } else { wrap16(u16of(a) >> n) }),
            Op::Sra => result = Some(a.div_euclid(1i64 << n)),
            Op::Mul | Op::Mac | Op::Msu => {
                let p = a * b;
                let (acc, s1) = match c.op {
                    Op::Mul => (p, false),
                    Op::Mac => sat32(self.acc + p),
                    _ => sat32(self.acc - p),
                };
                self.acc = acc;
                let (y, s2) = scale(acc, sh, c.trunc);
                set_cv(self, false, s1 || s2);
                result = Some(y);
            }
            Op::Acc => {
                let (y, s) = scale(self.acc, sh, c.trunc);
                set_cv(self, false, s);
                result = Some(y);
            }
            Op::Acch => result = Some(wrap16(self.acc.rem_euclid(1 << 32) >> 16)),
            Op::Accl => result = Some(wrap16(self.acc)),
            Op::Ldacc => self.acc = sat32(a * (1i64 << sh)).0,
            Op::Ld => {
                let addr = a + b;
                if !(0..512).contains(&addr) {
                    return Outcome::Fault(addr);
                }
                result = Some(self.ram[addr as usize]);
            }
            Op::St => {
                if !(0..512).contains(&b) {
                    return Outcome::Fault(b);
                }
                self.ram[b as usize] = a;
            }
            Op::Sleep => self.sleep = true,
            Op::Wake => self.sleep = false,
        }
        if let Some(y) = result {
            self.out = y;
            if c.we {
                self.r[c.rd as usize] = y;
            }
        }
        Outcome::Executed
    }

    /// Whether `cmp`'s condition `cond` holds of `a` and `b`.
    fn holds(&self, cond: Cond, a: i64, b: i64) -> bool {
        let (ua, ub) = (u16of(a), u16of(b));
        match cond {
            Cond::Eq => a == b,
            Cond::Ne => a != b,
            Cond::Lt => a < b,
            Cond::Ge => a >= b,
            Cond::Le => a <= b,
            Cond::Gt => a > b,
            Cond::Ltu => ua < ub,
            Cond::Geu => ua >= ub,
            Cond::Leu => ua <= ub,
            Cond::Gtu => ua > ub,
            Cond::Cs => self.c,
            Cond::Vs => self.v,
            Cond::True => true,
            Cond::False => false,
            Cond::Bit => ua & ub != 0,
            Cond::Nbit => ua & ub == 0,
        }
    }
}
