//! Testbenches, the float reference renderer, metrics, charts, and the
//! pieces of the `morphosys` command.

pub mod charts;
pub mod cli;
pub mod cmd_fuzz;
pub mod fuzz;
pub mod cmd_asm;
pub mod cmd_run;
pub mod testbench;
pub mod reference;
pub mod cmd_scene;
pub mod metrics;
