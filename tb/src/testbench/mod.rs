//! Testbenches: each drives a block of the chip, checks it against an
//! independent reference model and writes a waveform.

pub mod cosim;
pub mod rc;
pub mod rc_ref;
