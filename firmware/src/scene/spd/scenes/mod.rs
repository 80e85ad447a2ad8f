//! The SPD scenes, each ported from its C program: balls ("sphereflake"),
//! tetra, jacks, rings, gears, lattice, shells, mount, tree.

/// The light scale the SPD programs compute: 1 for NFF output.
pub(super) const LSCALE_NFF: f64 = 1.0;

mod balls;
mod gears;
mod jacks;
mod lattice;
mod mount;
mod rings;
mod shells;
mod tetra;
mod tree;

pub(super) use balls::balls;
pub(super) use gears::gears;
pub(super) use jacks::jacks;
pub(super) use lattice::lattice;
pub(super) use mount::mount;
pub(super) use rings::rings;
pub(super) use shells::shells;
pub(super) use tetra::tetra;
pub(super) use tree::tree;
