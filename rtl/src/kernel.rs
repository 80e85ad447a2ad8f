//! The simulation kernel: two-phase clocking of register-transfer modules.
//!
//! Every module holds registered state `q`. Each cycle the kernel calls
//! [`Clocked::eval`] on the top module, which computes every next state `d`
//! from the current states and inputs only, and then [`Clocked::commit`],
//! the clock edge, which makes `d` the new `q` everywhere at once. Nothing a
//! module can see changes during `eval`, so the order in which a parent
//! evaluates its children never matters.
//!
//! Tracing samples a cycle between the two phases: registers show the state
//! during the cycle, combinational signals the values computed from it, and
//! a register's new value appears in the next cycle, as in any RTL waveform.

use std::fmt;
use std::io;

use crate::trace::{TraceConfig, Traced, Tracer};

/// A fault inside the model: the simulation stops with this message.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Fault {
    /// The block that detected it (`rc`, `array`, `tinyrisc`, `dma`...).
    pub block: String,
    pub message: String,
}

impl Fault {
    pub fn new(block: impl Into<String>, message: impl Into<String>) -> Fault {
        Fault {
            block: block.into(),
            message: message.into(),
        }
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.block, self.message)
    }
}

impl std::error::Error for Fault {}

/// A module with registered state.
pub trait Clocked {
    /// Compute the next state from the current state and the inputs. Must not
    /// change any state another module (or a waveform) can observe.
    fn eval(&mut self) -> Result<(), Fault>;
    /// The clock edge: next state becomes current state.
    fn commit(&mut self);
}

/// Why [`Sim::step`] stopped.
#[derive(Debug)]
pub enum StepError {
    Fault { cycle: u64, fault: Fault },
    Trace(io::Error),
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::Fault { cycle, fault } => write!(f, "cycle {cycle}: {fault}"),
            StepError::Trace(e) => write!(f, "writing waveform: {e}"),
        }
    }
}

impl std::error::Error for StepError {}

/// The kernel: a top module, a cycle counter and an optional tracer.
pub struct Sim<T> {
    pub top: T,
    cycle: u64,
    tracer: Option<Tracer>,
}

impl<T: Clocked + Traced> Sim<T> {
    pub fn new(top: T) -> Sim<T> {
        Sim {
            top,
            cycle: 0,
            tracer: None,
        }
    }

    /// Cycles completed so far.
    pub fn cycle(&self) -> u64 {
        self.cycle
    }

    /// Start writing a waveform of the top module, named `top_name`.
    pub fn trace(&mut self, cfg: TraceConfig, top_name: &str) -> io::Result<()> {
        self.tracer = Some(Tracer::create(cfg, top_name, &self.top)?);
        Ok(())
    }

    /// One clock cycle.
    #[inline(always)]
    pub fn step(&mut self) -> Result<(), StepError> {
        if let Err(fault) = self.top.eval() {
            if let Some(t) = &mut self.tracer {
                t.note(&format!(
                    "stopped by a fault at cycle {}: {fault}",
                    self.cycle
                ));
            }
            return Err(StepError::Fault {
                cycle: self.cycle,
                fault,
            });
        }
        if let Some(t) = &mut self.tracer {
            t.sample(self.cycle, &self.top, 0)
                .map_err(StepError::Trace)?;
        }
        self.top.commit();
        self.cycle += 1;
        Ok(())
    }

    /// Is a waveform being written?
    pub fn tracing(&self) -> bool {
        self.tracer.is_some()
    }

    /// Advance by a fast path of the top module that simulates whole
    /// cycles itself (`f` returns the cycles it completed and how it ended).
    /// Only without a waveform: the fast path samples nothing.
    #[inline(always)]
    pub fn fast_forward(
        &mut self,
        f: impl FnOnce(&mut T) -> (u64, Result<(), Fault>),
    ) -> Result<u64, StepError> {
        assert!(self.tracer.is_none(), "fast_forward while tracing");
        let (n, r) = f(&mut self.top);
        self.cycle += n;
        match r {
            Ok(()) => Ok(n),
            Err(fault) => Err(StepError::Fault {
                cycle: self.cycle,
                fault,
            }),
        }
    }

    /// [`Sim::fast_forward`] that also works with a waveform: `f` gets the
    /// top module and a function to call with it between the evaluation
    /// and the commit of every cycle it simulates (the waveform samples
    /// the cycle there; `false`: writing it failed, stop before the
    /// commit).
    pub fn fast_forward_sampled(
        &mut self,
        f: impl FnOnce(&mut T, &mut dyn FnMut(&T, u8) -> bool) -> (u64, Result<(), Fault>),
    ) -> Result<u64, StepError> {
        let mut cycle = self.cycle;
        let mut err = None;
        let (n, r) = match &mut self.tracer {
            None => f(&mut self.top, &mut |_, _| true),
            Some(t) => f(&mut self.top, &mut |top: &T, unchanged| match t
                .sample(cycle, top, unchanged)
            {
                Ok(()) => {
                    cycle += 1;
                    true
                }
                Err(e) => {
                    err = Some(e);
                    false
                }
            }),
        };
        self.cycle += n;
        if let Some(e) = err {
            return Err(StepError::Trace(e));
        }
        match r {
            Ok(()) => Ok(n),
            Err(fault) => {
                if let Some(t) = &mut self.tracer {
                    t.note(&format!(
                        "stopped by a fault at cycle {}: {fault}",
                        self.cycle
                    ));
                }
                Err(StepError::Fault {
                    cycle: self.cycle,
                    fault,
                })
            }
        }
    }

    /// Close the waveform, if any; returns the files written.
    pub fn finish_trace(&mut self) -> io::Result<Vec<std::path::PathBuf>> {
        match self.tracer.take() {
            Some(t) => t.finish(),
            None => Ok(Vec::new()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::Probe;

    /// Two registers that swap every cycle: `a <= b; b <= a`. With two-phase
    /// clocking the swap works whichever register is evaluated first.
    struct Swap {
        q: [u32; 2],
        d: [u32; 2],
        order_b_first: bool,
    }

    impl Clocked for Swap {
        fn eval(&mut self) -> Result<(), Fault> {
            if self.order_b_first {
                self.d[1] = self.q[0];
                self.d[0] = self.q[1];
            } else {
                self.d[0] = self.q[1];
                self.d[1] = self.q[0];
            }
            Ok(())
        }
        fn commit(&mut self) {
            self.q = self.d;
        }
    }

    impl Traced for Swap {
        fn trace<P: Probe>(&self, p: &mut P) {
            p.signal("a", 32, crate::trace::Display::Hex, self.q[0] as u64);
        }
    }

    #[test]
    fn evaluation_order_does_not_matter() {
        for order_b_first in [false, true] {
            let mut sim = Sim::new(Swap {
                q: [1, 2],
                d: [0; 2],
                order_b_first,
            });
            sim.step().unwrap();
            assert_eq!(sim.top.q, [2, 1]);
            sim.step().unwrap();
            assert_eq!(sim.top.q, [1, 2]);
            assert_eq!(sim.cycle(), 2);
        }
    }
}
