//! The BSP nodes of the packet traversal ([`super::super::Traversal::Packet`]):
//! inner nodes carry their interval stack slots instead of the objects under
//! them, leaves per type present a count and the FB addresses of their
//! objects' records; mailboxes (objects in more than one leaf) in main
//! memory. Resident when it fits FB set 0, else streamed (node records in
//! main memory, each leaf's records a block moved into FB bank 1, a block
//! larger than the bank cut into pieces). The fields are named in the
//! program's header (`PN_*`, `PL_*`, `LE_*`, `PS_*`, `MB_*`) and read by
//! `traversal/packet.rs`; the subtrees it walks as one leaf are chosen
//! here ([`super::super::Collapse`]).

use super::super::primitives::{
    aabox, cone, cylinder, planar, polygon, sphere, Body, Fit, Gen, Sides,
};
use super::{
    fb_word_bytes, Finish, Layout, Stream, TypeInfo, FB_LIMIT, NODE_BYTES, STREAM_BANK, W,
};
use crate::scene::{PrimType, Scene, Shape};

/// Array cycles a packet spends on an inner node (its kernel and
/// TinyRISC's decision), for [`super::super::Collapse::Auto`].
const PK_NODE_COST: f64 = 60.0;

/// Per scene object, the array cycles of one test: its kernels' contexts
/// (caps and polygon edges included) and about 12 cycles of TinyRISC's
/// loop (mailbox and issue) that the array does not always hide. The
/// kernels as with the default numerics (the lengths the cost model was
/// fitted with).
pub(super) fn object_costs(scene: &Scene, s: f64, fit: &Fit) -> Vec<f64> {
    let g = Gen {
        datapath: rtl::rc::Datapath::W16,
        approx: super::super::math::Approx::default(),
        fine_normals: fit.fine_normals,
    };
    let sphere = sphere::kernel(&g, fit, Sides::Front).len();
    let disc = planar::kernel(&g, planar::Inside::Disc, Sides::Front).len();
    let cyl = cylinder::kernel(&g, Body::Opaque).len();
    let cone = cone::kernel(&g, Body::Opaque).len();
    let boxk = aabox::kernel(&g, Sides::Front).len();
    let planar = planar::kernel(&g, planar::Inside::Triangle, Sides::Front).len();
    let poly: Vec<usize> = polygon::kernels(&g, Sides::Front)
        .iter()
        .map(|(_, k)| k.len())
        .collect();
    let (ph, pe, pt) = (poly[0], poly[1], poly[2]);
    scene
        .objects
        .iter()
        .map(|o| {
            let c = match &o.shape {
                Shape::Sphere { .. } => sphere,
                Shape::Cone { caps, .. } => {
                    let body = if o.shape.prim_type() == PrimType::Cone {
                        cone
                    } else {
                        cyl
                    };
                    body + if *caps { 2 * disc } else { 0 }
                }
                Shape::Box { .. } => boxk,
                Shape::Rectangle { .. } | Shape::Triangle { .. } => planar,
                Shape::Polygon { v, .. } => ph + pt + pe * polygon::edges(v, s).1.len(),
            };
            c as f64 + 12.0
        })
        .collect()
}

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

/// The BSP nodes for the packet traversal ([`Traversal::Packet`]): inner
/// nodes carry their stack slots instead of the objects under them, leaves
/// per type present a count and the FB addresses of their objects' records;
/// no mailboxes. Resident when it fits FB set 0, else streamed (node
/// records in main memory, each leaf's records a block moved into FB bank 1,
/// a block larger than the bank cut into pieces).
#[allow(clippy::too_many_arguments)]
pub(super) fn packet_nodes(
    mut w: W,
    fin: Finish,
    types: Vec<TypeInfo>,
    nodes: &[crate::bsp::Node],
    slot: &[(usize, usize)],
    records_start: usize,
    streamed: bool,
    err: &dyn Fn(usize, String) -> String,
) -> Result<Layout, String> {
    // The tree the traversal walks: a subtree with at most `collapse`
    // objects under it is one leaf of those objects (testing them all with
    // the rays that reach it costs less than walking it).
    let mut tree: Vec<crate::bsp::Node> = Vec::with_capacity(nodes.len());
    // Expected cost (array cycles) of a packet that reaches node k:
    // walking (a node visit, then each child with the probability that a
    // ray through the cell meets the child's, its surface area over the
    // cell's) or testing everything under it.
    let test_all =
        |n: &crate::bsp::Node| -> f64 { n.objects.iter().map(|&o| fin.cost[o as usize]).sum() };
    let mut keep = vec![true; nodes.len()];
    fn expect(
        nodes: &[crate::bsp::Node],
        k: usize,
        test_all: &dyn Fn(&crate::bsp::Node) -> f64,
        keep: &mut [bool],
    ) -> f64 {
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
    let mut model_keep = vec![true; nodes.len()];
    let expected_cost = expect(nodes, 0, &test_all, &mut model_keep);
    let collapse = match fin.collapse {
        super::super::Collapse::Auto => {
            keep = model_keep;
            // The root is walked whenever the BSP has one split: the pass's
            // start clips the rays to the root cell, which culls the rays
            // that miss the scene (the surface-area weights assume every
            // ray meets the cell).
            keep[0] = true;
            usize::MAX
        }
        super::super::Collapse::Objects(c) => c,
    };
    fn walk(
        nodes: &[crate::bsp::Node],
        k: usize,
        collapse: usize,
        keep: &[bool],
        out: &mut Vec<crate::bsp::Node>,
    ) -> u32 {
        let n = &nodes[k];
        let at = out.len();
        out.push(crate::bsp::Node {
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
    walk(nodes, 0, collapse, &keep, &mut tree);
    let nodes = &tree[..];
    // An object in one leaf only is met once per pass (each node is
    // visited at most once): it needs no mailbox.
    let mut refs = vec![0u32; fin.objects];
    for n in nodes.iter().filter(|n| n.split.is_none()) {
        for &o in &n.objects {
            refs[o as usize] += 1;
        }
    }
    let size = |n: &crate::bsp::Node| match n.split {
        Some(_) => PK_INNER,
        None => PK_LEAF_HEAD + types.len() + 2 * n.objects.len(),
    };
    let mut node_at = Vec::with_capacity(nodes.len() + 1);
    node_at.push(0usize);
    for n in nodes {
        node_at.push(node_at.last().copied().unwrap_or(0) + size(n));
    }
    let node_section = node_at[nodes.len()];
    let root = w.fb.len();
    let total = root + node_section;
    let parent_slot = |n: &crate::bsp::Node| {
        if n.depth == 0 {
            0
        } else {
            pk_slot(n.depth - 1)
        }
    };
    // A leaf's objects of each type, in slot order.
    let per_type = |n: &crate::bsp::Node| -> Vec<Vec<usize>> {
        types
            .iter()
            .map(|ti| {
                n.objects
                    .iter()
                    .filter_map(|&o| {
                        let (t, q) = slot[o as usize];
                        (t == ti.ty as usize).then_some(q)
                    })
                    .collect()
            })
            .collect()
    };
    if total <= FB_LIMIT && !streamed {
        for n in nodes {
            match n.split {
                Some(sp) => {
                    w.raw(sp.axis as i64);
                    w.raw(parent_slot(n));
                    w.coord(sp.position);
                    w.raw(pk_slot(n.depth));
                    w.raw((root + node_at[sp.children[0] as usize]) as i64);
                    w.raw((root + node_at[sp.children[1] as usize]) as i64);
                }
                None => {
                    w.word16(0x8000);
                    w.raw(parent_slot(n));
                    w.raw(n.objects.len() as i64);
                    w.raw(n.objects.iter().filter(|&&o| refs[o as usize] > 1).count() as i64);
                    for (ti, qs) in types.iter().zip(per_type(n)) {
                        w.raw(qs.len() as i64);
                        for q in qs {
                            let o = ti.objects[q];
                            w.raw((ti.first + q * ti.size) as i64);
                            w.raw(if refs[o] > 1 { o as i64 } else { -1 });
                        }
                    }
                }
            }
        }
        debug_assert_eq!(w.fb.len(), total);
        // The mailboxes (main memory, TinyRISC's), where the streamed
        // image would start.
        let mailbox = super::super::mem::STREAM as usize;
        let mut lay = fin.layout(w.fb, types, root, 0, total, node_section, mailbox, None);
        lay.root_leaf = nodes[0].split.is_none();
        lay.expected_cost = expected_cost;
        return Ok(lay);
    }
    // Streamed: records, nodes and leaf blocks leave the FB.
    let records = w.fb.split_off(records_start);
    let split_slot = w.fb.len();
    w.raw(0); // split
    w.raw(0); // its slot
    w.raw(0); // a popped node's parent slot
    if w.fb.len() > STREAM_BANK {
        return Err(err(
            0,
            format!(
                "the resident part of the streamed layout needs {} FB words; bank 0 holds {STREAM_BANK}",
                w.fb.len()
            ),
        ));
    }
    let base = super::super::mem::STREAM as usize;
    // Leaf pieces: a leaf's records (grouped by type) cut where a block
    // would exceed FB bank 1; each piece is a node record of its own,
    // chained from the leaf (word 6).
    let mut pieces: Vec<Vec<(usize, usize)>> = Vec::new(); // (type index, slot) per piece
    let mut first_piece = vec![usize::MAX; nodes.len()];
    for (k, n) in nodes.iter().enumerate() {
        if n.split.is_some() || n.objects.is_empty() {
            continue;
        }
        first_piece[k] = pieces.len();
        let mut cur: Vec<(usize, usize)> = Vec::new();
        let mut words = 0usize;
        for (j, qs) in per_type(n).into_iter().enumerate() {
            for q in qs {
                let sz = types[j].size;
                if sz > STREAM_BANK {
                    return Err(err(
                        0,
                        format!(
                            "a {} record of {sz} words exceeds FB bank 1",
                            types[j].ty.name()
                        ),
                    ));
                }
                if words + sz > STREAM_BANK {
                    pieces.push(std::mem::take(&mut cur));
                    words = 0;
                }
                cur.push((j, q));
                words += sz;
            }
        }
        pieces.push(cur);
    }
    let nn = nodes.len();
    let lists_at = NODE_BYTES * (nn + pieces.len());
    let list_bytes: usize = pieces.iter().map(|p| 4 * p.len()).sum();
    let blocks_at = lists_at + list_bytes;
    let mut img = vec![0u8; blocks_at];
    let mut lists: Vec<u32> = Vec::new();
    let mut blocks: Vec<u8> = Vec::new();
    let mut largest = 0usize;
    let put = |img: &mut Vec<u8>, rec: usize, f: &[i32; 16]| {
        for (i, x) in f.iter().enumerate() {
            img[NODE_BYTES * rec + 4 * i..NODE_BYTES * rec + 4 * i + 4]
                .copy_from_slice(&x.to_le_bytes());
        }
    };
    // Piece records: block address and words, next piece, per-type counts.
    let mut piece_rec = vec![[0i32; 16]; pieces.len()];
    for (p, pc) in pieces.iter().enumerate() {
        let mut words: Vec<i32> = Vec::new();
        let mut counts = [0i32; 7];
        for &(j, q) in pc {
            let ti = &types[j];
            let at = ti.first - records_start + q * ti.size;
            words.extend_from_slice(&records[at..at + ti.size]);
            counts[j] += 1;
        }
        largest = largest.max(words.len());
        let f = &mut piece_rec[p];
        f[0] = -32768;
        f[2] = (base + lists_at + 4 * lists.len()) as i32;
        for &(j, q) in pc {
            lists.push(types[j].objects[q] as u32);
        }
        f[4] = (base + blocks_at + blocks.len()) as i32;
        f[5] = words.len() as i32;
        f[7..14].copy_from_slice(&counts);
        f[14] = pc.len() as i32;
        f[15] = pc
            .iter()
            .filter(|&&(j, q)| refs[types[j].objects[q]] > 1)
            .count() as i32;
        blocks.extend(fb_word_bytes(&words, w.x));
    }
    // Chain the pieces of each leaf (a leaf's pieces are consecutive).
    for k in 0..nn {
        let first = first_piece[k];
        if first == usize::MAX {
            continue;
        }
        let end = first_piece[k + 1..]
            .iter()
            .copied()
            .find(|&p| p != usize::MAX)
            .unwrap_or(pieces.len());
        for (p, rec) in piece_rec.iter_mut().enumerate().take(end - 1).skip(first) {
            rec[6] = (base + NODE_BYTES * (nn + p + 1)) as i32;
        }
    }
    // The mailboxes follow the image; the lists hold their addresses.
    let mailbox = (base + blocks_at + blocks.len()).next_multiple_of(PK_MAILBOX_BYTES);
    for (i, o) in lists.iter().enumerate() {
        let a = if refs[*o as usize] > 1 {
            (mailbox + PK_MAILBOX_BYTES * *o as usize) as u32
        } else {
            0
        };
        img[lists_at + 4 * i..lists_at + 4 * i + 4].copy_from_slice(&a.to_le_bytes());
    }
    for (k, n) in nodes.iter().enumerate() {
        let mut f = [0i32; 16];
        f[1] = parent_slot(n) as i32;
        match n.split {
            Some(sp) => {
                f[0] = sp.axis as i32;
                f[2] = w.sat(sp.position * w.s);
                f[3] = pk_slot(n.depth) as i32;
                f[4] = (base + NODE_BYTES * sp.children[0] as usize) as i32;
                f[5] = (base + NODE_BYTES * sp.children[1] as usize) as i32;
            }
            None => {
                f[0] = -32768;
                if first_piece[k] != usize::MAX {
                    // The leaf's record is its first piece's.
                    let p = piece_rec[first_piece[k]];
                    f[2] = p[2];
                    f[4..16].copy_from_slice(&p[4..16]);
                }
            }
        }
        put(&mut img, k, &f);
    }
    for (p, f) in piece_rec.iter().enumerate() {
        put(&mut img, nn + p, f);
    }
    img.extend(blocks);
    let end = mailbox + PK_MAILBOX_BYTES * fin.objects;
    if end > super::super::mem::STREAM_END as usize {
        return Err(err(
            0,
            format!(
                "the streamed scene needs {} bytes of main memory; {} are reserved",
                end - base,
                super::super::mem::STREAM_END as usize - base
            ),
        ));
    }
    let st = Stream {
        base: base as u32,
        image: img,
        root: base as u32,
        mailbox: mailbox as u32,
        split_slot,
        nodes: nn,
        largest_block: largest,
        extra_pieces: pieces.len() - first_piece.iter().filter(|&&p| p != usize::MAX).count(),
    };
    let root_leaf = nodes[0].split.is_none();
    let mut lay = fin.layout(
        w.fb,
        types,
        base,
        NODE_BYTES / 4,
        total,
        node_section,
        mailbox,
        Some(st),
    );
    lay.root_leaf = root_leaf;
    lay.expected_cost = expected_cost;
    Ok(lay)
}
