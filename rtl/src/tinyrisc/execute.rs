//! TinyRISC execution: one instruction per issue, its effects as next state
//! and a [`Command`] the chip applies at the clock edge.
//!
//! TinyRISC sees the rest of the chip only through [`Machine`] (reads and
//! checks, no writes): every write leaves as a [`Command`]. Tests swap in a
//! small double for the machine.

use crate::array::Mode;
use crate::broadcast::Run;
use crate::dma::{DmaKind, DmaRequest};
use crate::kernel::Fault;

use super::decode::{Instr, Opcode};
use super::{RiscTiming, State, TinyRisc, Wait};

/// What TinyRISC may ask of the chip around it (all reads; the chip checks
/// ranges and DMA ownership and faults on a violation).
pub trait Machine {
    /// Instruction fetch (word-aligned).
    fn fetch(&self, pc: u32) -> Result<u32, Fault>;
    /// Data load of `size` bytes (1, 2, 4), zero-extended.
    fn load(&self, addr: u32, size: u32) -> Result<u32, Fault>;
    /// Would a store of `size` bytes at `addr` be legal?
    fn check_store(&self, addr: u32, size: u32) -> Result<(), Fault>;
    /// One FB word (TinyRISC's FB port), sign-extended to 32 bits.
    fn fb_read(&self, addr: u16) -> Result<i32, Fault>;
    /// Would writing `words` FB words from `addr` be legal (no DMA conflict)?
    fn check_fb_write(&self, addr: u16, words: u32) -> Result<(), Fault>;
    /// Output register of RC `lane` (row-major), sign-extended to 32 bits.
    fn rc_out(&self, lane: usize) -> i32;
    /// Bytes of an FB word: 2 on the 16-bit chip, 4 on the 32-bit chip.
    fn fb_word_bytes(&self) -> u32 {
        2
    }
    /// (flag F mask, sleep mask) of the 64 RCs.
    fn rc_flags(&self) -> (u64, u64);
    /// Can a run be issued (the broadcast queue has room)?
    fn array_can_issue(&self) -> bool;
    /// No run in progress or queued.
    fn array_idle(&self) -> bool;
    fn dma_idle(&self) -> bool;
    fn mem_size(&self) -> usize;
    /// The chip's cycle counter (`rdcyc`).
    fn cycle(&self) -> u64;
}

/// A write TinyRISC's instruction makes, applied at the clock edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Command {
    #[default]
    None,
    Store {
        addr: u32,
        size: u32,
        value: u32,
    },
    /// `sfb`: the chip keeps the low FB-word bits of `value`.
    FbWrite {
        addr: u16,
        value: i32,
    },
    /// Write the 64 RC outputs to FB words `addr..addr + 64`.
    Wfb {
        addr: u16,
    },
    Dma(DmaRequest),
    Run(Run),
}

fn fault(msg: String) -> Fault {
    Fault::new("tinyrisc", msg)
}

/// An FB address computed by TinyRISC must be 0..=0xFFFF.
fn fb_addr(v: i64, what: &str) -> Result<u16, Fault> {
    u16::try_from(v).map_err(|_| fault(format!("{what} FB address {v} outside 0..=0xffff")))
}

impl TinyRisc {
    /// Execute the instruction at `pc` (when not busy, stalled or halted):
    /// computes the next state and the command.
    #[inline(always)]
    pub fn eval<M: Machine>(&mut self, m: &M) -> Result<(), Fault> {
        if !self.issues() {
            return Ok(());
        }
        let w = m.fetch(self.pc)?;
        self.ir = w;
        let i = self.decoded(w)?;
        use Opcode::*;
        // Stall conditions first: a stalled instruction changes nothing.
        if (i.op as u8 >= Rcsl as u8 || i.op == Halt) && self.stalls(m, i.op) {
            return Ok(());
        }
        self.wait = Wait::None;
        let t = self.timing;
        let r = |k: u8| self.regs.read(k);
        let next = self.pc.wrapping_add(4);
        let mut pc = next;
        let mut wb: Option<u32> = None;
        let mut cost = t.alu;
        let (a, b, c) = (r(i.a), r(i.b), r(i.c));
        let imm = i.imm;
        match i.op {
            Nop => {}
            Rdcyc => wb = Some(m.cycle() as u32),
            Halt => {
                cost = t.halt;
                self.d_halt = true;
                pc = self.pc;
            }
            Add | Sub | And | Or | Xor | Nor | Sll | Srl | Sra | Slt | Sltu => {
                wb = Some(alu(i.op, b, c))
            }
            Mul => {
                wb = Some(b.wrapping_mul(c));
                cost = t.mul;
            }
            Addi | Andi | Ori | Xori | Slti | Sltiu | Slli | Srli | Srai => {
                wb = Some(alu(i.op, b, imm as u32))
            }
            Lui => wb = Some((imm as u32) << 14),
            Lw | Lh | Lhu | Lb | Lbu => {
                wb = Some(load(m, i, b)?);
                cost = t.load;
            }
            Sw | Sh | Sb => {
                self.cmd = store(m, i, a, b)?;
                cost = t.store;
            }
            Lfb => {
                let addr = fb_addr(b as i32 as i64 + imm as i64, "lfb")?;
                wb = Some(m.fb_read(addr)? as u32);
                cost = t.fb_load;
            }
            Sfb => {
                let addr = fb_addr(b as i32 as i64 + imm as i64, "sfb")?;
                m.check_fb_write(addr, 1)?;
                let value = a as i32;
                self.cmd = Command::FbWrite { addr, value };
                cost = t.fb_store;
            }
            Beq | Bne | Blt | Bge | Bltu | Bgeu => {
                if taken(i.op, a, b) {
                    pc = next.wrapping_add((imm as u32).wrapping_mul(4));
                    cost = t.branch_taken;
                } else {
                    cost = t.branch_not_taken;
                }
            }
            J | Jal => {
                pc = imm as u32;
                if i.op == Jal {
                    self.d_reg = Some((15, next));
                }
                cost = t.jump;
            }
            Jr => {
                pc = a;
                cost = t.jump;
            }
            Jalr => {
                pc = b;
                wb = Some(next);
                cost = t.jump;
            }
            Ldctxt | Ldfb | Stfb => {
                self.cmd = Command::Dma(dma(m, i, a, b, c)?);
                cost = t.dma_issue;
            }
            Dwait => cost = t.dwait,
            Cbcast | Sbcb | Dbcb | Cbcr | Cbcc => {
                let run = broadcast(i, a, b, c, self.pc)?;
                cost = match t.issue {
                    super::IssueModel::Run => t.broadcast_issue,
                    super::IssueModel::Instruction => t.broadcast_issue.max(run.count as u32),
                };
                self.cmd = Command::Run(run);
            }
            Wfb => {
                self.cmd = wfb(m, a, imm)?;
                cost = t.wfb;
            }
            Rcrisc => {
                wb = Some(rc_out(m, b, imm)?);
                cost = t.rcrisc;
            }
            Rcany | Rcall | Rcfl | Rcfh | Rcsl | Rcsh | Rcst => {
                wb = Some(status(m, i.op));
                cost = t.status;
            }
        }
        if let Some(v) = wb {
            self.d_reg = Some((i.a, v));
        }
        self.d_pc = pc;
        self.d_busy = cost.max(1) - 1;
        self.state = State::Issue;
        Ok(())
    }

    /// The cycle's next state cleared: nothing written, the pc kept;
    /// whether an instruction may issue (not halted, not busy).
    #[inline(always)]
    fn issues(&mut self) -> bool {
        self.cmd = Command::None;
        self.d_reg = None;
        self.d_pc = self.pc;
        self.d_halt = self.halted;
        if self.halted {
            self.state = State::Halted;
            return false;
        }
        if self.busy > 0 {
            self.d_busy = self.busy - 1;
            self.state = State::Busy;
            return false;
        }
        true
    }

    /// The decoded instruction of word `w` at `pc`, from the decoded-
    /// instruction cache where it holds it (a stalled instruction is
    /// retried every cycle, and loops run the same words again). The
    /// model's speed, not the chip's timing: keyed by pc and checked
    /// against the fetched word, so a store into the program is seen at
    /// once.
    #[inline(always)]
    fn decoded(&mut self, w: u32) -> Result<Instr, Fault> {
        let slot = (self.pc >> 2) as usize % super::ICACHE;
        Ok(match self.icache.get(slot) {
            Some(&(pc, word, i)) if pc == self.pc && word == w && w != 0 => i,
            _ => {
                let i = Instr::decode(w).map_err(|e| fault(e.to_string()))?;
                if let Some(e) = self.icache.get_mut(slot) {
                    *e = (self.pc, w, i);
                }
                i
            }
        })
    }

    /// Whether `op` (one that may wait: the array's and the DMA's
    /// instructions, `halt`) stalls this cycle: then the wait is set and
    /// nothing else changes.
    #[inline(always)]
    fn stalls<M: Machine>(&mut self, m: &M, op: Opcode) -> bool {
        use Opcode::*;
        let needs_array_idle = matches!(
            op,
            Wfb | Rcrisc | Rcany | Rcall | Rcfl | Rcfh | Rcsl | Rcsh | Rcst
        );
        let needs_issue = matches!(op, Cbcast | Sbcb | Dbcb | Cbcr | Cbcc);
        let needs_dma = matches!(op, Ldctxt | Ldfb | Stfb | Dwait);
        let wait = if (needs_array_idle || op == Halt) && !m.array_idle() {
            Wait::ArrayIdle
        } else if needs_issue && !m.array_can_issue() {
            Wait::Issue
        } else if (needs_dma || op == Halt) && !m.dma_idle() {
            Wait::Dma
        } else {
            Wait::None
        };
        if wait != Wait::None {
            if wait == Wait::Dma
                && self.wait != Wait::Dma
                && !self.dma_wait_watch.is_empty()
                && self.dma_wait_watch.contains(&self.pc)
            {
                self.dma_waits_watched += 1;
            }
            self.wait = wait;
            self.state = if wait == Wait::Dma {
                State::StallDma
            } else {
                State::StallArray
            };
            self.d_busy = 0;
            return true;
        }
        false
    }
}

/// The ALU's result of `op` on `b` and `x` (the register `c`, or the
/// immediate of the immediate forms: `addi` adds as `add`, `slti`
/// compares as `slt`, `slli` shifts as `sll`).
#[inline(always)]
fn alu(op: Opcode, b: u32, x: u32) -> u32 {
    use Opcode::*;
    match op {
        Add | Addi => b.wrapping_add(x),
        Sub => b.wrapping_sub(x),
        And | Andi => b & x,
        Or | Ori => b | x,
        Xor | Xori => b ^ x,
        Nor => !(b | x),
        Sll | Slli => b << (x & 31),
        Srl | Srli => b >> (x & 31),
        Sra | Srai => ((b as i32) >> (x & 31)) as u32,
        Slt | Slti => ((b as i32) < (x as i32)) as u32,
        _ => (b < x) as u32,
    }
}

/// `rcrisc`'s word: RC `b + imm`'s `out`.
#[inline(always)]
fn rc_out<M: Machine>(m: &M, b: u32, imm: i32) -> Result<u32, Fault> {
    let lane = b as u64 + imm as u64;
    if lane >= 64 {
        return Err(fault(format!("rcrisc: RC index {lane} outside 0..=63")));
    }
    Ok(m.rc_out(lane as usize) as u32)
}

/// A load's value (`lw lh lhu lb lbu` from `b + imm`).
#[inline(always)]
fn load<M: Machine>(m: &M, i: Instr, b: u32) -> Result<u32, Fault> {
    use Opcode::*;
    let addr = b.wrapping_add(i.imm as u32);
    let size = match i.op {
        Lw => 4,
        Lh | Lhu => 2,
        _ => 1,
    };
    let v = m.load(addr, size)?;
    Ok(match i.op {
        Lh => v as u16 as i16 as i32 as u32,
        Lb => v as u8 as i8 as i32 as u32,
        _ => v,
    })
}

/// A store's command (`sw sh sb` of `a` to `b + imm`).
#[inline(always)]
fn store<M: Machine>(m: &M, i: Instr, a: u32, b: u32) -> Result<Command, Fault> {
    use Opcode::*;
    let addr = b.wrapping_add(i.imm as u32);
    let size = match i.op {
        Sw => 4,
        Sh => 2,
        _ => 1,
    };
    m.check_store(addr, size)?;
    Ok(Command::Store {
        addr,
        size,
        value: a,
    })
}

/// Whether branch `op` of `a` and `b` is taken.
#[inline(always)]
fn taken(op: Opcode, a: u32, b: u32) -> bool {
    use Opcode::*;
    match op {
        Beq => a == b,
        Bne => a != b,
        Blt => (a as i32) < (b as i32),
        Bge => (a as i32) >= (b as i32),
        Bltu => a < b,
        _ => a >= b,
    }
}

/// A DMA instruction's request (`ldctxt ldfb stfb`: main memory at `a`,
/// local at `b`, `c + imm` words), checked.
#[inline(always)]
fn dma<M: Machine>(m: &M, i: Instr, a: u32, b: u32, c: u32) -> Result<DmaRequest, Fault> {
    use Opcode::*;
    let kind = match i.op {
        Ldctxt => DmaKind::MemToCtx,
        Ldfb => DmaKind::MemToFb,
        _ => DmaKind::FbToMem,
    };
    let words = c as u64 + i.imm as u64;
    let req = DmaRequest {
        kind,
        mem: a,
        local: b,
        words: u32::try_from(words).unwrap_or(u32::MAX),
    };
    req.validate_for(m.mem_size(), m.fb_word_bytes())
        .map_err(|e| Fault::new("dma", e))?;
    Ok(req)
}

/// A broadcast instruction's run (`cbcast sbcb dbcb cbcr cbcc`: contexts
/// from `a`; FB streams from `b`, and `c` for `dbcb`), checked (`pc`:
/// the instruction's address).
#[inline(always)]
fn broadcast(i: Instr, a: u32, b: u32, c: u32, pc: u32) -> Result<Run, Fault> {
    use Opcode::*;
    let imm = i.imm;
    let mode = match i.op {
        Cbcr => Mode::Row,
        Cbcc => Mode::Col,
        Dbcb if imm >> 12 == 1 => Mode::Row,
        Dbcb if imm >> 12 == 2 => Mode::Col,
        _ => Mode::Simd,
    };
    let count = if i.op == Dbcb {
        (imm & 4095) as u64
    } else {
        c as u64 + imm as u64
    };
    if a >= 8192 || count > 8192 {
        return Err(Fault::new(
            "broadcast",
            format!("context run at 0x{a:x} of {count} outside context memory (0..0x2000)"),
        ));
    }
    let mut fb = [None, None];
    match i.op {
        Sbcb | Cbcr | Cbcc => {
            let f = fb_addr(b as i64, "FB stream")?;
            fb[crate::fb::set(f)] = Some(f);
        }
        Dbcb => {
            fb[0] = Some(fb_addr(b as i64, "dbcb set 0")?);
            fb[1] = Some(fb_addr(c as i64, "dbcb set 1")?);
        }
        _ => {}
    }
    let run = Run {
        mode,
        ctx: a as u16,
        count: count as u16,
        fb,
        pc,
    };
    run.validate().map_err(|e| Fault::new("broadcast", e))?;
    Ok(run)
}

/// `wfb`'s command: the 64 RCs' `out` to the FB at `a + imm`, checked.
#[inline(always)]
fn wfb<M: Machine>(m: &M, a: u32, imm: i32) -> Result<Command, Fault> {
    let addr = fb_addr(a as i64 + imm as i64, "wfb")?;
    if addr as u32 + 64 > 0x10000 {
        return Err(Fault::new(
            "fb",
            format!("wfb of 64 words at 0x{addr:04x} runs past the end of the FB"),
        ));
    }
    m.check_fb_write(addr, 64)?;
    Ok(Command::Wfb { addr })
}

/// A status instruction's word (`rcany rcall rcfl rcfh rcsl rcsh rcst`)
/// from the array's F and sleep flags.
#[inline(always)]
fn status<M: Machine>(m: &M, op: Opcode) -> u32 {
    use Opcode::*;
    let (f, sleep) = m.rc_flags();
    let awake = !sleep;
    match op {
        Rcany => (f & awake != 0) as u32,
        Rcall => (awake & !f == 0) as u32,
        Rcfl => f as u32,
        Rcfh => (f >> 32) as u32,
        Rcsl => sleep as u32,
        Rcst => (f & awake != 0) as u32 | ((awake & !f == 0) as u32) << 1,
        _ => (sleep >> 32) as u32,
    }
}

/// The cycles of an instruction that issues (excluding stalls), for the
/// timing table in `docs/isa.md`; `taken` for branches.
pub fn cycles(t: &RiscTiming, op: Opcode, taken: bool) -> u32 {
    use Opcode::*;
    match op {
        Mul => t.mul,
        Lw | Lh | Lhu | Lb | Lbu => t.load,
        Sw | Sh | Sb => t.store,
        Lfb => t.fb_load,
        Sfb => t.fb_store,
        Beq | Bne | Blt | Bge | Bltu | Bgeu => {
            if taken {
                t.branch_taken
            } else {
                t.branch_not_taken
            }
        }
        J | Jal | Jr | Jalr => t.jump,
        Ldctxt | Ldfb | Stfb => t.dma_issue,
        Dwait => t.dwait,
        Cbcast | Sbcb | Dbcb | Cbcr | Cbcc => t.broadcast_issue,
        Wfb => t.wfb,
        Rcrisc => t.rcrisc,
        Rcany | Rcall | Rcfl | Rcfh | Rcsl | Rcsh | Rcst => t.status,
        Halt => t.halt,
        _ => t.alu,
    }
}
