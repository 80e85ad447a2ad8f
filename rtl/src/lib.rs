//! The MorphoSys chip, cycle by cycle. Knows nothing of ray tracing.
//!
//! * [`kernel`]: two-phase clocking (`eval` then `commit`), the cycle counter.
//! * [`trace`]: VCD waveforms with GTKWave save files and translate filters.
//! * [`rc`]: the Reconfigurable Cell datapath, lane-wise for up to 64 RCs.

pub mod kernel;
pub mod rc;
pub mod trace;

pub use kernel::{Clocked, Fault, Sim};
