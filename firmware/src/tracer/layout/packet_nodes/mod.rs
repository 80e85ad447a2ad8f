//! The BSP nodes of the packet traversal ([`super::super::Traversal::Packet`]):
//! inner nodes carry their interval stack slots instead of the objects under
//! them, leaves per type present a count and the FB addresses of their
//! objects' records; mailboxes (objects in more than one leaf) in main
//! memory. Resident when it fits FB set 0, else streamed (node records in
//! main memory, each leaf's records a block moved into FB bank 1, a block
//! larger than the bank cut into pieces). The fields are named in the
//! program's header (`PN_*`, `PL_*`, `LE_*`, `PS_*`, `MB_*`) and read by
//! `traversal/packet/`; the subtrees it walks as one leaf are chosen
//! here ([`super::super::Collapse`]).

use super::super::{mem, Collapse};
pub use super::costs::{chip_costs, PK_LEAF_COST, PK_NODE_COST, PK_OBJECT_RISC};
use super::{FbImage, Finish, TypeInfo, FB_LIMIT, NODE_BYTES, W};
use crate::bsp::Node;

mod stream;
use stream::streamed_image;

/// Widening of every split plane and of the root box in the packet
/// traversal, in LSB of the scene format.
pub const P_TOL: i32 = 4;

/// A leaf's flags (bit 15 set): TinyRISC reads the awake rays for the
/// mailbox checks (some object of the leaf has a mailbox, or, streamed,
/// the leaf has more pieces).
pub const LEAF_AWAKE: i32 = 1;
/// A leaf's flags: it has no object.
pub const LEAF_EMPTY: i32 = 2;
/// A streamed leaf's flags: its first piece is larger than further pieces
/// may be (`--leaf-pieces`' REST: one large record) and every object in it
/// has a mailbox, so the piece is moved only once the mailbox scan finds
/// an object in it some awake ray has not tested (on a miss of the leaf
/// cache): a large record the packet's rays have all tested in another
/// leaf is not moved again. The scan costs about ten TinyRISC cycles, the
/// move at least a cycle per two words.
pub const LEAF_LATE: i32 = 4;

/// Words of a packet-traversal inner node: axis, parent's slot, split,
/// own slot, left, right (FB addresses, or byte addresses when streamed).
pub const PK_INNER: usize = 6;
/// Words before a resident packet leaf's lists: flags, parent's slot,
/// object count, objects with a mailbox (in more than one leaf).
pub const PK_LEAF_HEAD: usize = 4;
/// Bytes of a packet-traversal mailbox in main memory: the pass that last
/// tested the object, and which rays did (64-bit mask), padded.
pub const PK_MAILBOX_BYTES: usize = 16;

/// RC RAM address of the interval slot of BSP depth `d`.
fn pk_slot(d: u32) -> i64 {
    (super::super::memory_map::ram::P_SLOT.value
        + 2 * d.min(super::super::memory_map::ram::P_SLOTS - 1)) as i64
}

/// The tree the packet traversal walks ([`collapsed`]), and what its
/// node writers share.
struct Tree<'a> {
    nodes: Vec<Node>,
    /// Per scene object, the number of leaves it is in: an object in one
    /// leaf only is met once per pass (each node is visited at most once)
    /// and needs no mailbox.
    refs: Vec<u32>,
    types: &'a [TypeInfo],
    slot: &'a [(usize, usize)],
}

impl Tree<'_> {
    /// A leaf's objects of each type, in slot order.
    fn per_type(&self, n: &Node) -> Vec<Vec<usize>> {
        self.types
            .iter()
            .map(|ti| {
                n.objects
                    .iter()
                    .filter_map(|&o| {
                        let (t, q) = self.slot[o as usize];
                        (t == ti.ty as usize).then_some(q)
                    })
                    .collect()
            })
            .collect()
    }

    /// The RAM slot a node's parent pushed it with (0 for the root).
    fn parent_slot(n: &Node) -> i64 {
        if n.depth == 0 {
            0
        } else {
            pk_slot(n.depth - 1)
        }
    }

    /// Objects of `objects` in more than one leaf (with a mailbox).
    fn shared(&self, objects: impl Iterator<Item = usize>) -> usize {
        objects.filter(|&o| self.refs[o] > 1).count()
    }
}

/// The tree the traversal walks: where the cost model says so (or, with
/// `Collapse::Objects(c)`, under `c` objects) a subtree is one leaf of the
/// objects under it (testing them all with the rays that reach it costs
/// less than walking it). Also the expected cost of the model's tree.
fn collapsed(nodes: &[Node], fin: &Finish) -> (Vec<Node>, f64) {
    // Expected cost (array cycles) of a packet that reaches node k:
    // walking (a node visit, then each child with the probability that a
    // ray through the cell meets the child's, its surface area over the
    // cell's) or testing everything under it.
    let test_all = |n: &Node| -> f64 {
        let leaf = if n.objects.is_empty() {
            0.0
        } else {
            PK_LEAF_COST
        };
        leaf + n.objects.iter().map(|&o| fin.cost[o as usize]).sum::<f64>()
    };
    fn expect(nodes: &[Node], k: usize, test_all: &dyn Fn(&Node) -> f64, keep: &mut [bool]) -> f64 {
        let n = &nodes[k];
        let all = test_all(n);
        let Some(sp) = n.split else { return all };
        let area = n.bounds.surface_area().max(1e-300);
        let mut walk = PK_NODE_COST;
        for c in sp.children {
            let ch = &nodes[c as usize];
            walk += (ch.bounds.surface_area() / area).min(1.0)
                * expect(nodes, c as usize, test_all, keep);
        }
        if all <= walk {
            keep[k] = false;
            all
        } else {
            walk
        }
    }
    let mut keep = vec![true; nodes.len()];
    let mut model_keep = vec![true; nodes.len()];
    let expected_cost = expect(nodes, 0, &test_all, &mut model_keep);
    let collapse = match fin.collapse {
        Collapse::Auto => {
            keep = model_keep;
            // The root is walked whenever the BSP has one split: the pass's
            // start clips the rays to the root cell, which culls the rays
            // that miss the scene (the surface-area weights assume every
            // ray meets the cell).
            keep[0] = true;
            usize::MAX
        }
        Collapse::Objects(c) => c,
    };
    fn walk(nodes: &[Node], k: usize, collapse: usize, keep: &[bool], out: &mut Vec<Node>) -> u32 {
        let n = &nodes[k];
        let at = out.len();
        out.push(Node {
            split: None,
            ..n.clone()
        });
        if let Some(sp) = n.split {
            if keep[k] && (collapse == usize::MAX || n.objects.len() > collapse) {
                let l = walk(nodes, sp.children[0] as usize, collapse, keep, out);
                let r = walk(nodes, sp.children[1] as usize, collapse, keep, out);
                out[at].split = Some(crate::bsp::Split {
                    children: [l, r],
                    ..sp
                });
            }
        }
        at as u32
    }
    let mut tree = Vec::with_capacity(nodes.len());
    walk(nodes, 0, collapse, &keep, &mut tree);
    (tree, expected_cost)
}

/// The BSP nodes for the packet traversal: inner nodes carry their stack
/// slots instead of the objects under them, leaves per type present a
/// count and the FB addresses of their objects' records; the mailboxes in
/// main memory. Resident when it fits FB set 0, else streamed.
#[allow(clippy::too_many_arguments)]
pub(super) fn packet_nodes(
    w: W,
    fin: Finish,
    types: Vec<TypeInfo>,
    nodes: &[Node],
    slot: &[(usize, usize)],
    records_start: usize,
    streamed: bool,
    err: &dyn Fn(usize, String) -> String,
) -> Result<FbImage, String> {
    let (nodes, expected_cost) = collapsed(nodes, &fin);
    let mut refs = vec![0u32; fin.objects];
    for n in nodes.iter().filter(|n| n.split.is_none()) {
        for &o in &n.objects {
            refs[o as usize] += 1;
        }
    }
    let tree = Tree {
        nodes,
        refs,
        types: &types,
        slot,
    };
    let size = |n: &Node| match n.split {
        Some(_) => PK_INNER,
        None => PK_LEAF_HEAD + types.len() + 2 * n.objects.len(),
    };
    let mut node_at = Vec::with_capacity(tree.nodes.len() + 1);
    node_at.push(0usize);
    for n in &tree.nodes {
        node_at.push(node_at.last().copied().unwrap_or(0) + size(n));
    }
    let node_section = node_at[tree.nodes.len()];
    let total = w.fb.len() + node_section;
    let root_leaf = tree.nodes[0].split.is_none();
    let mut lay = if total <= FB_LIMIT && !streamed {
        let (fb, root) = resident(w, &tree, &node_at);
        debug_assert_eq!(fb.len(), total);
        // The mailboxes (main memory, TinyRISC's), where the streamed
        // image would start.
        let mailbox = mem::STREAM as usize;
        drop(tree);
        fin.layout(fb, types, root, 0, total, node_section, mailbox, None)
    } else {
        let (fb, st) = streamed_image(w, &fin, &tree, records_start, err)?;
        let mailbox = st.mailbox as usize;
        drop(tree);
        fin.layout(
            fb,
            types,
            st.base as usize,
            NODE_BYTES / 4,
            total,
            node_section,
            mailbox,
            Some(st),
        )
    };
    lay.root_leaf = root_leaf;
    lay.expected_cost = expected_cost;
    Ok(lay)
}

/// The resident nodes after the records: the FB image and the root's
/// address.
fn resident(mut w: W, tree: &Tree, node_at: &[usize]) -> (Vec<i32>, usize) {
    let root = w.fb.len();
    for n in &tree.nodes {
        match n.split {
            Some(sp) => {
                w.raw(4 * sp.axis as i64);
                w.raw(Tree::parent_slot(n));
                w.coord(sp.position);
                w.raw(pk_slot(n.depth));
                w.raw((root + node_at[sp.children[0] as usize]) as i64);
                w.raw((root + node_at[sp.children[1] as usize]) as i64);
            }
            None => {
                let shared = tree.shared(n.objects.iter().map(|&o| o as usize));
                let flags = if n.objects.is_empty() {
                    LEAF_EMPTY
                } else if shared > 0 {
                    LEAF_AWAKE
                } else {
                    0
                };
                w.word16(0x8000 | flags as u16);
                w.raw(Tree::parent_slot(n));
                w.raw(n.objects.len() as i64);
                w.raw(shared as i64);
                for (ti, qs) in tree.types.iter().zip(tree.per_type(n)) {
                    w.raw(qs.len() as i64);
                    for q in qs {
                        let o = ti.objects[q];
                        w.raw((ti.first + q * ti.size) as i64);
                        w.raw(if tree.refs[o] > 1 { o as i64 } else { -1 });
                    }
                }
            }
        }
    }
    (w.fb, root)
}

/// The node fields the packet traversal reads (named in the program's
/// header): resident nodes in FB words, streamed ones in bytes of a
/// `NODE_BYTES` record in main memory, and the mailboxes.
pub mod fields {
    use crate::tracer::emit::Name;

    pub const PN_FLAGS: Name = Name::new(
        "PN_FLAGS",
        0,
        "packet node: the split axis times 4, or bit 15 a leaf (+1: some object with a mailbox, +2: empty)",
    );
    pub const PN_PARENT_SLOT: Name = Name::new(
        "PN_PARENT_SLOT",
        1,
        "  the RAM slot its parent pushed it with",
    );
    pub const PN_SPLIT: Name = Name::new("PN_SPLIT", 2, "  inner: the split's position");
    pub const PN_SLOT: Name = Name::new("PN_SLOT", 3, "  inner: the RAM slot of its depth");
    pub const PN_LEFT: Name = Name::new("PN_LEFT", 4, "  inner: the children (FB addresses)");
    pub const PN_RIGHT: Name = Name::new("PN_RIGHT", 5, "");
    pub const PL_OBJECTS: Name = Name::new("PL_OBJECTS", 2, "  leaf: its objects");
    pub const PL_SHARED: Name = Name::new(
        "PL_SHARED",
        3,
        "  leaf: of those, in other leaves too (a mailbox)",
    );
    pub const PL_LISTS: Name = Name::new(
        "PL_LISTS",
        4,
        "  leaf: per type a count, then an entry per object:",
    );
    pub const LE_RECORD: Name = Name::new("LE_RECORD", 0, "    its record (FB address)");
    pub const LE_MAILBOX: Name = Name::new("LE_MAILBOX", 1, "    its mailbox index (-1: none)");
    pub const LE_WORDS: Name = Name::new("LE_WORDS", 2, "");
    /// The resident fields, in header order.
    pub const RESIDENT: &[Name] = &[
        PN_FLAGS,
        PN_PARENT_SLOT,
        PN_SPLIT,
        PN_SLOT,
        PN_LEFT,
        PN_RIGHT,
        PL_OBJECTS,
        PL_SHARED,
        PL_LISTS,
        LE_RECORD,
        LE_MAILBOX,
        LE_WORDS,
    ];

    pub const PS_FLAGS: Name = Name::new(
        "PS_FLAGS",
        0,
        "  the split axis times 4; -32768 a piece or a leaf (+1: the awake rays read, +2: empty)",
    );
    pub const PS_SPLIT: Name = Name::new("PS_SPLIT", 8, "  inner: the split's position");
    pub const PS_LEFT: Name = Name::new("PS_LEFT", 16, "  inner: the children (byte addresses)");
    pub const PS_RIGHT: Name = Name::new("PS_RIGHT", 20, "");
    pub const PS_LIST: Name = Name::new(
        "PS_LIST",
        8,
        "  leaf: per object its mailbox's address (0: none)",
    );
    pub const PS_FB: Name = Name::new(
        "PS_FB",
        12,
        "  leaf: the FB address its block is moved to (bank 1, or the top of bank 0)",
    );
    pub const PS_BLOCK: Name = Name::new("PS_BLOCK", 16, "  leaf: its block of records");
    pub const PS_BLOCK_WORDS: Name = Name::new("PS_BLOCK_WORDS", 20, "  leaf: the block's words");
    pub const PS_NEXT: Name = Name::new("PS_NEXT", 24, "  leaf: its next piece (0: none)");
    /// Per type present (in test order), the leaf's objects of that type:
    /// `PS_COUNT_type` = `PS_COUNTS + 4 j`.
    pub const PS_COUNTS: u32 = 28;
    pub const PS_OBJECTS: Name = Name::new("PS_OBJECTS", 56, "  leaf: objects in all");
    pub const PS_SHARED: Name = Name::new("PS_SHARED", 60, "  leaf: of those, with a mailbox");

    pub const MB_SHIFT: Name = Name::new(
        "MB_SHIFT",
        4,
        "a mailbox (main memory, 16 bytes, MAILBOX + index << MB_SHIFT):",
    );
    pub const MB_PASS: Name = Name::new("MB_PASS", 0, "  the pass that last tested the object");
    pub const MB_RAYS: Name = Name::new(
        "MB_RAYS",
        4,
        "  the rays that have not in that pass (64-bit mask, 1: asleep at every test)",
    );
}

/// A streamed node record's word of field `f`.
fn word(f: crate::tracer::emit::Name) -> usize {
    f.at() / 4
}

/// The header lines of the packet traversal's node fields.
pub fn header(streamed: bool, types: &[&str]) -> Vec<String> {
    use crate::tracer::emit::define;
    use fields::*;
    let mut v: Vec<String> = if streamed {
        let mut v = vec![define(
            "NODE_BYTES",
            NODE_BYTES,
            "a packet node record (main memory):",
        )];
        v.extend(
            [
                PS_FLAGS,
                PS_SPLIT,
                PS_LEFT,
                PS_RIGHT,
                PS_LIST,
                PS_FB,
                PS_BLOCK,
                PS_BLOCK_WORDS,
                PS_NEXT,
            ]
            .iter()
            .map(|n| n.define()),
        );
        for (j, t) in types.iter().enumerate() {
            v.push(define(
                &format!("PS_COUNT_{}", t.to_uppercase()),
                PS_COUNTS as usize + 4 * j,
                if j == 0 {
                    "  leaf: objects of each type"
                } else {
                    ""
                },
            ));
        }
        v.push(PS_OBJECTS.define());
        v.push(PS_SHARED.define());
        v
    } else {
        RESIDENT.iter().map(|n| n.define()).collect()
    };
    v.extend([MB_SHIFT, MB_PASS, MB_RAYS].iter().map(|n| n.define()));
    v
}
