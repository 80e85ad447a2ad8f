//! The BSP nodes of the paper's traversal: resident (Fig. 5's, or the
//! compact index lists of [`super::super::NodeLayout::Compact`]) or, for a
//! scene that does not fit FB set 0, streamed (node records, leaf lists,
//! leaf blocks and mailboxes in main memory). The fields are named in the
//! program's header (`N_*`, `NC_*`, `SN_*`) and read by
//! `traversal/paper.rs` and `traversal/streamed.rs`.
//!
//! ```text
//! Fig. 5: flags (bit 15 leaf, bits 1..0 axis), split, left, right (FB
//!     addresses), cell bounds widened by 2 LSB (6 words), one membership
//!     bit vector per type present (bit 15 of word 0 = the type's object 0)
//! compact: an inner node's flags, split, left, right or a leaf's flags and
//!     cell bounds, then per type present the number of the node's objects
//!     of that type and their slot indices, ascending
//! mailboxes (resident): one word per object, the number of the pass that
//!     last tested it (object merging)
//! ```

use super::super::NodeLayout;
use super::{
    fb_word_bytes, FbImage, Finish, Stream, TypeInfo, FB_LIMIT, NODE_BYTES, STREAM_BANK, W,
};

/// Head words of a Fig. 5 node: flags, split, left, right, cell bounds.
pub const NODE_HEAD: usize = 10;
/// Head words of a compact inner node (flags, split, left, right) and
/// leaf (flags, cell bounds); the index lists follow.
pub const COMPACT_INNER_HEAD: usize = 4;
pub const COMPACT_LEAF_HEAD: usize = 7;

/// Head words of a compact node.
pub fn compact_head(leaf: bool) -> usize {
    if leaf {
        COMPACT_LEAF_HEAD
    } else {
        COMPACT_INNER_HEAD
    }
}

/// The nodes (and, streamed, everything after the shading streams) of the
/// paper's traversal, after the records laid out by [`super::build_as`].
#[allow(clippy::too_many_arguments)]
pub(super) fn paper_nodes(
    mut w: W,
    fin: Finish,
    mut types: Vec<TypeInfo>,
    nodes: &[crate::bsp::Node],
    slot: &[(usize, usize)],
    records_start: usize,
    streamed: bool,
    node_layout: NodeLayout,
    bv_offset: usize,
    mailbox_slots: usize,
    err: &dyn Fn(usize, String) -> String,
) -> Result<FbImage, String> {
    // BSP nodes: Fig. 5 (fixed size) or compact (head, then per type a
    // count and the slot indices).
    let node_words = match node_layout {
        NodeLayout::Fig5 => bv_offset,
        NodeLayout::Compact => 0,
    };
    let mut node_at = Vec::with_capacity(nodes.len() + 1);
    node_at.push(0usize);
    for n in nodes {
        let size = match node_layout {
            NodeLayout::Fig5 => node_words,
            NodeLayout::Compact => compact_head(n.split.is_none()) + types.len() + n.objects.len(),
        };
        node_at.push(node_at.last().copied().unwrap_or(0) + size);
    }
    let node_section = node_at[nodes.len()];
    let root = w.fb.len();
    let total = root + node_section + mailbox_slots;
    if total > FB_LIMIT || streamed {
        let st = streamed_image(&mut w, fin.objects, &types, nodes, slot, records_start, err)?;
        let (root, mailbox) = (st.root as usize, st.mailbox as usize);
        return Ok(fin.layout(
            w.fb,
            types,
            root,
            NODE_BYTES / 4,
            total,
            node_section,
            mailbox,
            Some(st),
        ));
    }
    resident(&mut w, &types, nodes, slot, node_layout, &node_at);
    debug_assert_eq!(w.fb.len(), root + node_section);
    let mailbox = w.fb.len();
    w.fb.resize(mailbox + mailbox_slots, 0);
    for t in &mut types {
        t.mailbox += mailbox;
    }
    Ok(fin.layout(
        w.fb,
        types,
        root,
        node_words,
        total,
        node_section,
        mailbox,
        None,
    ))
}

/// The streamed image of the paper's traversal: only the tables, camera,
/// lights and shading stay in the FB (bank 0); objects, nodes and
/// mailboxes go to main memory.
fn streamed_image(
    w: &mut W,
    objects: usize,
    types: &[TypeInfo],
    nodes: &[crate::bsp::Node],
    slot: &[(usize, usize)],
    records_start: usize,
    err: &dyn Fn(usize, String) -> String,
) -> Result<Stream, String> {
    use fields::*;
    let word = |f: crate::tracer::emit::Name| f.at() / 4;
    // Streamed: only the tables, camera, lights and shading stay in the
    // FB (bank 0); objects, nodes and mailboxes go to main memory.
    super::streamed_types_fit(types, err)?;
    let records = w.fb.split_off(records_start);
    let split_slot = resident_split(w, err)?;
    let base = super::super::mem::STREAM;
    let nn = nodes.len();
    let lists_at = NODE_BYTES * nn;
    let list_bytes: usize = nodes
        .iter()
        .filter(|n| n.split.is_none())
        .map(|n| 4 * n.objects.len())
        .sum();
    let blocks_at = lists_at + list_bytes;
    let mut node_img = vec![0u8; lists_at];
    let mut lists: Vec<u8> = Vec::with_capacity(list_bytes);
    let mut blocks: Vec<u8> = Vec::new();
    let mut largest = 0usize;
    // Mailbox addresses are known once the blocks are laid out: lay
    // the blocks out first, patch the lists after.
    let mut list_objs: Vec<usize> = Vec::new();
    for (k, n) in nodes.iter().enumerate() {
        let mut f = [0i32; 16];
        match n.split {
            Some(sp) => {
                f[word(SN_FLAGS)] = sp.axis as i32;
                f[word(SN_SPLIT)] = w.sat(sp.position * w.s);
                f[word(SN_LEFT)] = (base as usize + NODE_BYTES * sp.children[0] as usize) as i32;
                f[word(SN_RIGHT)] = (base as usize + NODE_BYTES * sp.children[1] as usize) as i32;
            }
            None => {
                f[word(SN_FLAGS)] = -32768;
                let list_addr = base as usize + lists_at + 4 * list_objs.len();
                let words = leaf_block(
                    w,
                    n,
                    types,
                    slot,
                    (&records, records_start),
                    &mut f,
                    &mut list_objs,
                );
                if !n.objects.is_empty() {
                    if words.len() > STREAM_BANK {
                        return Err(err(
                            0,
                            format!(
                                "a BSP leaf of {} objects needs {} FB words; FB bank 1 holds {STREAM_BANK}",
                                n.objects.len(),
                                words.len()
                            ),
                        ));
                    }
                    largest = largest.max(words.len());
                    f[word(SN_BLOCK)] = (base as usize + blocks_at + blocks.len()) as i32;
                    f[word(SN_BLOCK_WORDS)] = words.len() as i32;
                    f[word(SN_OBJECTS)] = n.objects.len() as i32;
                    f[word(SN_LIST)] = list_addr as i32;
                    blocks.extend(fb_word_bytes(&words, w.x));
                }
            }
        }
        let at = NODE_BYTES * k;
        for (d, x) in node_img[at..at + NODE_BYTES].chunks_mut(4).zip(f) {
            d.copy_from_slice(&x.to_le_bytes());
        }
    }
    let mb_at = (blocks_at + blocks.len()).next_multiple_of(4);
    let mailbox = base as usize + mb_at;
    for &o in &list_objs {
        lists.extend(((mailbox + 2 * o) as u32).to_le_bytes());
    }
    let mut image = node_img;
    image.extend(lists);
    image.extend(blocks);
    image.resize(mb_at, 0);
    let end = base as usize + mb_at + 2 * objects;
    if end > super::super::mem::STREAM_END as usize {
        return Err(err(
            0,
            format!(
                "the streamed scene needs {} bytes of main memory; {} are reserved",
                end - base as usize,
                super::super::mem::STREAM_END - base
            ),
        ));
    }
    Ok(Stream {
        base,
        image,
        root: base,
        mailbox: mailbox as u32,
        split_slot,
        nodes: nn,
        largest_block: largest,
        extra_pieces: 0,
        late_leaves: 0,
        cache_slots: 0,
        slot_words: 0,
        slots_at: 0,
        fans: None,
    })
}

/// The split word after the resident part (the node being classified);
/// returns where it is.
fn resident_split(w: &mut W, err: &dyn Fn(usize, String) -> String) -> Result<usize, String> {
    let split_slot = w.fb.len();
    w.raw(0);
    super::resident_fits(w, err)?;
    Ok(split_slot)
}

/// A leaf's block: its cell's bounds widened by 2 LSB, then its objects'
/// records by type (`records` from `records_start` on; their ids pushed
/// to `list_objs`), each type's count in the node record `f`.
fn leaf_block(
    w: &W,
    n: &crate::bsp::Node,
    types: &[TypeInfo],
    slot: &[(usize, usize)],
    (records, records_start): (&[i32], usize),
    f: &mut [i32; 16],
    list_objs: &mut Vec<usize>,
) -> Vec<i32> {
    use fields::SN_COUNTS;
    let mut words: Vec<i32> = Vec::new();
    for v in n.bounds.min.to_array() {
        words.push(w.sat((v * w.s).floor() - 2.0));
    }
    for v in n.bounds.max.to_array() {
        words.push(w.sat((v * w.s).ceil() + 2.0));
    }
    for (j, ti) in types.iter().enumerate() {
        let mut cnt = 0;
        for &o in &n.objects {
            let (t, q) = slot[o as usize];
            if t == ti.ty as usize {
                let at = ti.first - records_start + q * ti.size;
                words.extend_from_slice(&records[at..at + ti.size]);
                list_objs.push(o as usize);
                cnt += 1;
            }
        }
        f[SN_COUNTS as usize / 4 + j] = cnt;
    }
    words
}

/// The resident nodes after the records (Fig. 5's or compact).
fn resident(
    w: &mut W,
    types: &[TypeInfo],
    nodes: &[crate::bsp::Node],
    slot: &[(usize, usize)],
    node_layout: NodeLayout,
    node_at: &[usize],
) {
    let root = w.fb.len();
    let addr = |k: u32| root + node_at[k as usize];
    for n in nodes {
        match n.split {
            Some(sp) => {
                w.raw(sp.axis as i64);
                w.coord(sp.position);
                w.raw(addr(sp.children[0]) as i64);
                w.raw(addr(sp.children[1]) as i64);
            }
            None => {
                w.word16(0x8000);
                if node_layout == NodeLayout::Fig5 {
                    w.raw(0);
                    w.raw(0);
                    w.raw(0);
                }
            }
        }
        // Cell bounds: every Fig. 5 node; compact, leaves only (the only
        // nodes whose bounds a kernel reads).
        if node_layout == NodeLayout::Fig5 || n.split.is_none() {
            for v in n.bounds.min.to_array() {
                w.push((v * w.s).floor() - 2.0);
            }
            for v in n.bounds.max.to_array() {
                w.push((v * w.s).ceil() + 2.0);
            }
        }
        for ti in types {
            // The node's objects of this type, ascending (the order the
            // Fig. 6 loop meets them in).
            let ks = n.objects.iter().filter_map(|&o| {
                let (t, k) = slot[o as usize];
                (t == ti.ty as usize).then_some(k)
            });
            match node_layout {
                NodeLayout::Fig5 => {
                    let words = crate::scene_image::membership_words(ti.bv_words * 16, ks);
                    for b in words {
                        w.word16(b);
                    }
                }
                NodeLayout::Compact => {
                    let at = w.fb.len();
                    w.raw(0);
                    for k in ks {
                        w.raw(k as i64);
                    }
                    w.fb[at] = (w.fb.len() - at - 1) as i32;
                }
            }
        }
    }
}

/// The node fields the paper's traversal reads (named in the program's
/// header): resident nodes in FB words, streamed ones in bytes of a
/// `NODE_BYTES` record in main memory.
pub mod fields {
    use crate::tracer::emit::Name;

    pub const N_FLAGS: Name = Name::new(
        "N_FLAGS",
        0,
        "node: bit 15 a leaf, bits 1..0 the split axis",
    );
    pub const N_SPLIT: Name = Name::new("N_SPLIT", 1, "  inner: the split's position");
    pub const N_LEFT: Name = Name::new("N_LEFT", 2, "  inner: the child below (FB address)");
    pub const N_RIGHT: Name = Name::new("N_RIGHT", 3, "  inner: the child above");
    pub const N_BOUNDS: Name = Name::new(
        "N_BOUNDS",
        4,
        "  Fig. 5: the cell, widened by 2 LSB: min.xyz, max.xyz",
    );
    pub const NC_INNER_LISTS: Name = Name::new(
        "NC_INNER_LISTS",
        super::COMPACT_INNER_HEAD as u32,
        "  compact inner: per type, a count and the slot indices",
    );
    pub const NC_LEAF_BOUNDS: Name = Name::new(
        "NC_LEAF_BOUNDS",
        1,
        "  compact leaf: the cell, widened by 2 LSB",
    );
    pub const NC_LEAF_LISTS: Name = Name::new(
        "NC_LEAF_LISTS",
        super::COMPACT_LEAF_HEAD as u32,
        "  compact leaf: per type, a count and the slot indices",
    );

    pub const SN_FLAGS: Name = Name::new("SN_FLAGS", 0, "  -32768 a leaf, else the split axis");
    pub const SN_SPLIT: Name = Name::new("SN_SPLIT", 4, "  the split's position");
    pub const SN_LEFT: Name = Name::new("SN_LEFT", 8, "  the children (byte addresses)");
    pub const SN_RIGHT: Name = Name::new("SN_RIGHT", 12, "");
    pub const SN_BLOCK: Name = Name::new("SN_BLOCK", 16, "  leaf: its block (bounds, records)");
    pub const SN_BLOCK_WORDS: Name = Name::new("SN_BLOCK_WORDS", 20, "  leaf: the block's words");
    pub const SN_LIST: Name = Name::new("SN_LIST", 24, "  leaf: its list of mailbox addresses");
    /// Per type present (in test order), the leaf's objects of that type:
    /// `SN_COUNT_type` = `SN_COUNTS + 4 j`.
    pub const SN_COUNTS: u32 = 28;
    pub const SN_OBJECTS: Name = Name::new("SN_OBJECTS", 56, "  leaf: objects in all");
    pub const U_NSTACK: Name = Name::new(
        "U_NSTACK",
        0,
        "an unordered subtree (USTK): the node stack where it ends",
    );
    pub const U_AXIS: Name = Name::new("U_AXIS", 4, "  its split axis");
    pub const U_FRAME: Name = Name::new("U_FRAME", 8, "  bytes");
}

/// The header lines of the resident nodes' fields.
pub fn header(layout: NodeLayout, types: &[TypeInfo]) -> Vec<String> {
    use crate::tracer::emit::define;
    use fields::*;
    let mut v: Vec<String> = [N_FLAGS, N_SPLIT, N_LEFT, N_RIGHT]
        .iter()
        .map(|n| n.define())
        .collect();
    match layout {
        NodeLayout::Fig5 => {
            v.push(N_BOUNDS.define());
            for t in types {
                let up = t.ty.name().to_uppercase();
                v.push(define(
                    &format!("N_BV_{up}"),
                    t.bv_offset,
                    &format!("  the {} under it, a bit each", t.ty.plural()),
                ));
                v.push(define(
                    &format!("BV_WORDS_{up}"),
                    t.bv_words,
                    "  words of that bit vector",
                ));
            }
        }
        NodeLayout::Compact => {
            v.extend(
                [NC_INNER_LISTS, NC_LEAF_BOUNDS, NC_LEAF_LISTS]
                    .iter()
                    .map(|n| n.define()),
            );
        }
    }
    v
}

/// The header lines of the streamed nodes' fields (`types`: the types
/// present, in test order).
pub fn streamed_header(types: &[&str]) -> Vec<String> {
    use crate::tracer::emit::define;
    use fields::*;
    let mut v = vec![define(
        "NODE_BYTES",
        NODE_BYTES,
        "a node record (main memory):",
    )];
    v.extend(
        [
            SN_FLAGS,
            SN_SPLIT,
            SN_LEFT,
            SN_RIGHT,
            SN_BLOCK,
            SN_BLOCK_WORDS,
            SN_LIST,
        ]
        .iter()
        .map(|n| n.define()),
    );
    for (j, t) in types.iter().enumerate() {
        v.push(define(
            &format!("SN_COUNT_{}", t.to_uppercase()),
            SN_COUNTS as usize + 4 * j,
            if j == 0 {
                "  leaf: objects of each type"
            } else {
                ""
            },
        ));
    }
    v.push(SN_OBJECTS.define());
    v.extend([U_NSTACK, U_AXIS, U_FRAME].iter().map(|n| n.define()));
    v
}
