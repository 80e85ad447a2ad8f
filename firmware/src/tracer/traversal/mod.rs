//! The BSP traversals: TinyRISC's `trace` routine, which takes the 64
//! rays of a tile through the BSP tree once (a ray pass), and the RC
//! kernels it broadcasts at the nodes. One file each:
//!
//! - [`paper`]: the paper's (section VI, Fig. 6): the packet's segments
//!   classified against each split plane; all rays agree: follow; they
//!   disagree: test every object under the node (resident scenes).
//! - [`streamed`]: the paper's traversal for scenes whose image does not
//!   fit FB set 0: nodes and leaf lists in main memory, each leaf's block
//!   of records moved into FB bank 1 by DMA; a node where the rays
//!   disagree is resolved by visiting both children.
//! - [`packet`]: masked packet traversal with per-ray intervals
//!   (resident or streamed), the default; [`child_order`]: which child
//!   of a node its packets visit first.
//!
//! Every traversal's `trace` is called by the tile loop ([`super::tiles`])
//! with the rays in r1..r7 of every RC and `MODE` 0 (closest hit) or 1
//! (any hit: shadow rays), and returns when every ray is done.

pub mod child_order;
pub mod packet;
pub mod packet_kernels;
pub mod paper;
pub mod streamed;

use super::data::{AWAKE, MASK_HI};
use super::emit::{Code, K, R0, R1, R2};
use super::kernel_names as names;

/// The sign of the ray direction along `axis` (0, 1, 2) into F.
pub fn sign(axis: u8) -> K {
    let mut k = K::new();
    k.doc(&format!(
        "{}: F = the ray goes down along {} (d{} < 0).",
        names::sign(axis),
        ["x", "y", "z"][axis as usize],
        ["x", "y", "z"][axis as usize]
    ));
    k.c(format!("cmp.lt r{}, #0", 4 + axis));
    k
}

/// `read_awake`: `AWAKE` = the RCs not asleep (the lanes of the tile are
/// the only ones awake at a pass's start).
pub fn read_awake(t: &mut Code) {
    t.doc("read_awake: AWAKE = the mask of the RCs awake (rcsl/rcsh: the sleeping ones).\nClobbers r1, r2.");
    t.label("read_awake")
        .rcsl(R1)
        .rcsh(R2)
        .nor(R1, R1, R0)
        .nor(R2, R2, R0)
        .sw(R1, super::emit::at(AWAKE, R0))
        .sw(R2, super::emit::at(format!("{AWAKE}+{MASK_HI}"), R0))
        .ret();
}
