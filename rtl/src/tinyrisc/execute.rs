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
        self.cmd = Command::None;
        self.d_reg = None;
        self.d_pc = self.pc;
        self.d_halt = self.halted;
        if self.halted {
            self.state = State::Halted;
            return Ok(());
        }
        if self.busy > 0 {
            self.d_busy = self.busy - 1;
            self.state = State::Busy;
            return Ok(());
        }
        let w = m.fetch(self.pc)?;
        self.ir = w;
        // Decoded-instruction cache: a stalled instruction is retried every
        // cycle, and loops run the same words again.
        // Decoded-instruction cache (the model's speed, not the chip's
        // timing): keyed by pc and checked against the fetched word, so a
        // store into the program is seen at once.
        let slot = (self.pc >> 2) as usize % super::ICACHE;
        let i = match self.icache.get(slot) {
            Some(&(pc, word, i)) if pc == self.pc && word == w && w != 0 => i,
            _ => {
                let i = Instr::decode(w).map_err(|e| fault(e.to_string()))?;
                if let Some(e) = self.icache.get_mut(slot) {
                    *e = (self.pc, w, i);
                }
                i
            }
        };
        use Opcode::*;
        // Stall conditions first: a stalled instruction changes nothing.
        if i.op as u8 >= Rcsl as u8 || i.op == Halt {
            let needs_array_idle = matches!(
                i.op,
                Wfb | Rcrisc | Rcany | Rcall | Rcfl | Rcfh | Rcsl | Rcsh | Rcst
            );
            let needs_issue = matches!(i.op, Cbcast | Sbcb | Dbcb | Cbcr | Cbcc);
            let needs_dma = matches!(i.op, Ldctxt | Ldfb | Stfb | Dwait);
            let wait = if (needs_array_idle || i.op == Halt) && !m.array_idle() {
                Wait::ArrayIdle
            } else if needs_issue && !m.array_can_issue() {
                Wait::Issue
            } else if (needs_dma || i.op == Halt) && !m.dma_idle() {
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
                return Ok(());
            }
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
            Add => wb = Some(b.wrapping_add(c)),
            Sub => wb = Some(b.wrapping_sub(c)),
            And => wb = Some(b & c),
            Or => wb = Some(b | c),
            Xor => wb = Some(b ^ c),
            Nor => wb = Some(!(b | c)),
            Sll => wb = Some(b << (c & 31)),
            Srl => wb = Some(b >> (c & 31)),
            Sra => wb = Some(((b as i32) >> (c & 31)) as u32),
            Slt => wb = Some(((b as i32) < (c as i32)) as u32),
            Sltu => wb = Some((b < c) as u32),
            Mul => {
                wb = Some(b.wrapping_mul(c));
                cost = t.mul;
            }
            Addi => wb = Some(b.wrapping_add(imm as u32)),
            Andi => wb = Some(b & imm as u32),
            Ori => wb = Some(b | imm as u32),
            Xori => wb = Some(b ^ imm as u32),
            Slti => wb = Some(((b as i32) < imm) as u32),
            Sltiu => wb = Some((b < imm as u32) as u32),
            Slli => wb = Some(b << (imm & 31)),
            Srli => wb = Some(b >> (imm & 31)),
            Srai => wb = Some(((b as i32) >> (imm & 31)) as u32),
            Lui => wb = Some((imm as u32) << 14),
            Lw | Lh | Lhu | Lb | Lbu => {
                let addr = b.wrapping_add(imm as u32);
                let size = match i.op {
                    Lw => 4,
                    Lh | Lhu => 2,
                    _ => 1,
                };
                let v = m.load(addr, size)?;
                wb = Some(match i.op {
                    Lh => v as u16 as i16 as i32 as u32,
                    Lb => v as u8 as i8 as i32 as u32,
                    _ => v,
                });
                cost = t.load;
            }
            Sw | Sh | Sb => {
                let addr = b.wrapping_add(imm as u32);
                let size = match i.op {
                    Sw => 4,
                    Sh => 2,
                    _ => 1,
                };
                m.check_store(addr, size)?;
                self.cmd = Command::Store {
                    addr,
                    size,
                    value: a,
                };
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
                self.cmd = Command::FbWrite {
                    addr,
                    value: a as i32,
                };
                cost = t.fb_store;
            }
            Beq | Bne | Blt | Bge | Bltu | Bgeu => {
                let taken = match i.op {
                    Beq => a == b,
                    Bne => a != b,
                    Blt => (a as i32) < (b as i32),
                    Bge => (a as i32) >= (b as i32),
                    Bltu => a < b,
                    _ => a >= b,
                };
                if taken {
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
                let kind = match i.op {
                    Ldctxt => DmaKind::MemToCtx,
                    Ldfb => DmaKind::MemToFb,
                    _ => DmaKind::FbToMem,
                };
                let words = c as u64 + imm as u64;
                let req = DmaRequest {
                    kind,
                    mem: a,
                    local: b,
                    words: u32::try_from(words).unwrap_or(u32::MAX),
                };
                req.validate_for(m.mem_size(), m.fb_word_bytes())
                    .map_err(|e| Fault::new("dma", e))?;
                self.cmd = Command::Dma(req);
                cost = t.dma_issue;
            }
            Dwait => cost = t.dwait,
            Cbcast | Sbcb | Dbcb | Cbcr | Cbcc => {
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
                        format!(
                            "context run at 0x{a:x} of {count} outside context memory (0..0x2000)"
                        ),
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
                    pc: self.pc,
                };
                run.validate().map_err(|e| Fault::new("broadcast", e))?;
                self.cmd = Command::Run(run);
                cost = match t.issue {
                    super::IssueModel::Run => t.broadcast_issue,
                    super::IssueModel::Instruction => t.broadcast_issue.max(count as u32),
                };
            }
            Wfb => {
                let addr = fb_addr(a as i64 + imm as i64, "wfb")?;
                if addr as u32 + 64 > 0x10000 {
                    return Err(Fault::new(
                        "fb",
                        format!("wfb of 64 words at 0x{addr:04x} runs past the end of the FB"),
                    ));
                }
                m.check_fb_write(addr, 64)?;
                self.cmd = Command::Wfb { addr };
                cost = t.wfb;
            }
            Rcrisc => {
                let lane = b as u64 + imm as u64;
                if lane >= 64 {
                    return Err(fault(format!("rcrisc: RC index {lane} outside 0..=63")));
                }
                wb = Some(m.rc_out(lane as usize) as u32);
                cost = t.rcrisc;
            }
            Rcany | Rcall | Rcfl | Rcfh | Rcsl | Rcsh | Rcst => {
                let (f, sleep) = m.rc_flags();
                let awake = !sleep;
                wb = Some(match i.op {
                    Rcany => (f & awake != 0) as u32,
                    Rcall => (awake & !f == 0) as u32,
                    Rcfl => f as u32,
                    Rcfh => (f >> 32) as u32,
                    Rcsl => sleep as u32,
                    Rcst => (f & awake != 0) as u32 | ((awake & !f == 0) as u32) << 1,
                    _ => (sleep >> 32) as u32,
                });
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
