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
    fb_word_bytes, Finish, Layout, Stream, TypeInfo, FB_LIMIT, NODE_BYTES, STREAM_BANK, W,
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
) -> Result<Layout, String> {
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
    let addr = |k: u32| root + node_at[k as usize];
    let total = root + node_section + mailbox_slots;
    let mut stream = None;
    if total > FB_LIMIT || streamed {
        // Streamed: only the tables, camera, lights and shading stay in the
        // FB (bank 0); objects, nodes and mailboxes go to main memory.
        let records = w.fb.split_off(records_start);
        let split_slot = w.fb.len();
        w.raw(0);
        if w.fb.len() > STREAM_BANK {
            return Err(err(
                0,
                format!(
                    "the resident part of the streamed layout needs {} FB words; bank 0 holds {STREAM_BANK}",
                    w.fb.len()
                ),
            ));
        }
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
                    f[0] = sp.axis as i32;
                    f[1] = w.sat(sp.position * w.s);
                    f[2] = (base as usize + NODE_BYTES * sp.children[0] as usize) as i32;
                    f[3] = (base as usize + NODE_BYTES * sp.children[1] as usize) as i32;
                }
                None => {
                    f[0] = -32768;
                    let list_addr = base as usize + lists_at + 4 * list_objs.len();
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
                        f[7 + j] = cnt;
                    }
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
                        f[4] = (base as usize + blocks_at + blocks.len()) as i32;
                        f[5] = words.len() as i32;
                        f[14] = n.objects.len() as i32;
                        f[6] = list_addr as i32;
                        blocks.extend(fb_word_bytes(&words, w.x));
                    }
                }
            }
            for (i, x) in f.iter().enumerate() {
                node_img[NODE_BYTES * k + 4 * i..NODE_BYTES * k + 4 * i + 4]
                    .copy_from_slice(&x.to_le_bytes());
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
        let end = base as usize + mb_at + 2 * fin.objects;
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
        stream = Some(Stream {
            base,
            image,
            root: base,
            mailbox: mailbox as u32,
            split_slot,
            nodes: nn,
            largest_block: largest,
            extra_pieces: 0,
        });
    }
    if let Some(st) = stream {
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
        for ti in &types {
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
