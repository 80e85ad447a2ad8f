//! The MorphoSys chip, cycle by cycle. Knows nothing of ray tracing.
//!
//! * [`kernel`]: two-phase clocking (`eval` then `commit`), the cycle counter.
//! * [`trace`]: VCD waveforms with GTKWave save files and translate filters.
//! * [`rc`]: the Reconfigurable Cell datapath, lane-wise for up to 64 RCs.
//! * [`interconnect`], [`array`]: the 8x8 array, its lanes and broadcast modes.
//! * [`broadcast`]: streams context runs and FB data to the array.
//! * [`fb`], [`context_memory`], [`memory`], [`dma`]: the memories and the DMA.
//! * [`tinyrisc`]: the control processor.
//! * [`chip`]: the top module, its [`chip::Timing`] and [`chip::Stats`].
//! * [`simd`]: the instruction set the per-cycle path runs on, chosen at run time.

// Lane loops index several per-lane arrays by the lane number on purpose:
// that is the form the compiler vectorises.
#![allow(clippy::needless_range_loop)]

pub mod array;
pub mod broadcast;
pub mod chip;
pub mod context_memory;
pub mod dma;
pub mod fb;
pub mod interconnect;
pub mod kernel;
pub mod memory;
pub mod rc;
pub mod simd;
pub mod tinyrisc;
pub mod trace;

pub use chip::{Chip, Stats, Timing};
pub use kernel::{Clocked, Fault, Sim};
