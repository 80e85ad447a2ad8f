//! Testbenches, the float reference renderer, metrics, charts, and the
//! pieces of the `morphosys` command.
#![recursion_limit = "256"] // the `json!` of a render report

pub mod autotune;
pub mod charts;
pub mod cli;
pub mod cmd_asm;
pub mod cmd_bench;
pub mod cmd_fuzz;
pub mod cmd_regroup;
pub mod cmd_render;
pub mod cmd_report;
pub mod cmd_run;
pub mod cmd_scene;
pub mod cmd_spd;
pub mod cmd_sweep;
pub mod cost;
pub mod fuzz;
pub mod inputs;
pub mod metrics;
pub mod output;
pub mod profile;
pub mod reference;
pub mod render;
pub mod render_options;
pub mod schedule;
pub mod surfer;
pub mod testbench;
pub mod timing;
