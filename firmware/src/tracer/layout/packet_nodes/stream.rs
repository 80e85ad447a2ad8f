//! The streamed packet layout: node records in main memory, each leaf's
//! records a block moved into FB bank 1 (a block larger than the bank
//! cut into pieces), what stays resident in the FB.

use super::super::super::mem;
use super::super::{
    fb_word_bytes, FansApart, Finish, Stream, TypeInfo, NODE_BYTES, STREAM_BANK, W,
};
use super::fields::{
    PS_BLOCK, PS_BLOCK_WORDS, PS_COUNTS, PS_FB, PS_FLAGS, PS_LEFT, PS_LIST, PS_NEXT, PS_OBJECTS,
    PS_RIGHT, PS_SHARED, PS_SPLIT,
};
use super::{pk_slot, word, Tree, LEAF_AWAKE, LEAF_EMPTY, LEAF_LATE, PK_MAILBOX_BYTES};
use crate::bsp::Node;

/// Leaf pieces: a leaf's records (grouped by type) cut into a first piece
/// of at most `first` words, a second of at most `second` (where `second`
/// is under `rest`), and what remains in as few pieces of at most `rest`
/// words as hold it, of about equal words (rather than full pieces and a
/// remainder: as many pieces, the longest shorter, so the longest wait
/// for a piece's DMA is shorter); a piece holds at least one record. Each piece is a
/// node record of its own, chained from the leaf (`PS_NEXT`). Per piece
/// its (type index, slot) pairs and its place in its leaf (0 for the
/// first), and per node the index of its first piece (`usize::MAX`: none).
#[allow(clippy::type_complexity)]
fn pieces(
    tree: &Tree,
    first: usize,
    second: usize,
    rest: usize,
) -> (Vec<Vec<(usize, usize)>>, Vec<usize>, Vec<usize>) {
    let types = tree.types;
    let mut pieces: Vec<Vec<(usize, usize)>> = Vec::new();
    let mut in_leaf = Vec::new();
    let mut first_piece = vec![usize::MAX; tree.nodes.len()];
    for (k, n) in tree.nodes.iter().enumerate() {
        if n.split.is_some() || n.objects.is_empty() {
            continue;
        }
        first_piece[k] = pieces.len();
        let recs: Vec<(usize, usize)> = tree
            .per_type(n)
            .into_iter()
            .enumerate()
            .flat_map(|(j, qs)| qs.into_iter().map(move |q| (j, q)))
            .collect();
        // Up to `limit` words from `recs[*i..]`; the piece closes at the
        // first record that reaches `enough` words.
        let take = |i: &mut usize, limit: usize, enough: usize| {
            let (mut piece, mut w) = (Vec::new(), 0);
            while let Some(&r) = recs.get(*i) {
                let sz = types[r.0].size;
                if w + sz > limit && !piece.is_empty() {
                    break;
                }
                piece.push(r);
                w += sz;
                *i += 1;
                if w >= enough {
                    break;
                }
            }
            piece
        };
        let mut i = 0;
        let mut leaf = vec![take(&mut i, first, usize::MAX)];
        if second < rest && i < recs.len() {
            leaf.push(take(&mut i, second, usize::MAX));
        }
        let left: usize = recs[i..].iter().map(|&(j, _)| types[j].size).sum();
        if left > 0 {
            let n = left.div_ceil(rest);
            let even = left.div_ceil(n);
            while i < recs.len() {
                leaf.push(take(&mut i, rest, even));
            }
        }
        for (place, piece) in leaf.into_iter().enumerate() {
            pieces.push(piece);
            in_leaf.push(place);
        }
    }
    (pieces, first_piece, in_leaf)
}

/// Write a node record (16 words) into the streamed image.
fn put(img: &mut [u8], rec: usize, f: &[i32; 16]) {
    for (i, x) in f.iter().enumerate() {
        img[NODE_BYTES * rec + 4 * i..NODE_BYTES * rec + 4 * i + 4]
            .copy_from_slice(&x.to_le_bytes());
    }
}

/// The streamed image: records, nodes and leaf blocks leave the FB, which
/// keeps what comes before the records and the split words.
pub(super) fn streamed_image(
    mut w: W,
    fin: &Finish,
    tree: &Tree,
    records_start: usize,
    err: &dyn Fn(usize, String) -> String,
) -> Result<(Vec<i32>, Stream), String> {
    let types = tree.types;
    super::super::streamed_types_fit(types, err)?;
    let nodes = &tree.nodes;
    let records = w.fb.split_off(records_start);
    let split_slot = resident_part(&mut w, err)?;
    let base = mem::STREAM as usize;
    let banks = banks(&w, fin, types, err)?;
    let (pieces, first_piece, in_leaf) = pieces(tree, banks.first, banks.second, banks.rest);
    let nn = nodes.len();
    let lists_at = NODE_BYTES * (nn + pieces.len());
    let list_bytes: usize = pieces.iter().map(|p| 4 * p.len()).sum();
    let blocks_at = lists_at + list_bytes;
    let mut img = vec![0u8; blocks_at];
    let at = PieceAt {
        base,
        lists_at,
        blocks_at,
    };
    let records = (&records[..], records_start);
    let PieceImage {
        rec: mut piece_rec,
        lists,
        mut blocks,
        largest,
    } = piece_image(tree, &pieces, &in_leaf, records, &w, &banks, at);
    chain_pieces(&mut piece_rec, &first_piece, nn, base);
    // The banded polygons' sub-edges (apart) follow the blocks, each
    // polygon's on a unit of its own.
    let fans = (!w.fans.is_empty()).then(|| {
        let unit = super::super::super::primitives::polygon::FAN_UNIT;
        let at = (base + blocks_at + blocks.len()).next_multiple_of(unit);
        blocks.resize(at - base - blocks_at, 0);
        blocks.extend(fb_word_bytes(&w.fans, w.x));
        FansApart {
            at: at as u32,
            buf: 2 * STREAM_BANK - banks.fan_buf,
            words: w.fan_most,
            word_shift: w.word_bytes().trailing_zeros(),
        }
    });
    // The mailboxes follow the image; the lists hold their addresses.
    let mailbox = (base + blocks_at + blocks.len()).next_multiple_of(PK_MAILBOX_BYTES);
    for (i, o) in lists.iter().enumerate() {
        let a = if tree.refs[*o as usize] > 1 {
            (mailbox + PK_MAILBOX_BYTES * *o as usize) as u32
        } else {
            0
        };
        img[lists_at + 4 * i..lists_at + 4 * i + 4].copy_from_slice(&a.to_le_bytes());
    }
    let late_leaves = node_records(
        &mut img,
        nodes,
        &piece_rec,
        &first_piece,
        &w,
        fin.pieces.rest,
    );
    for (p, f) in piece_rec.iter().enumerate() {
        put(&mut img, nn + p, f);
    }
    img.extend(blocks);
    let end = mailbox + PK_MAILBOX_BYTES * fin.objects;
    if end > mem::STREAM_END as usize {
        return Err(err(
            0,
            format!(
                "the streamed scene needs {} bytes of main memory; {} are reserved",
                end - base,
                mem::STREAM_END as usize - base
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
        late_leaves,
        cache_slots: banks.cache_slots,
        slot_words: banks.slot_words,
        slots_at: banks.slots_at,
        fans,
    };
    Ok((w.fb, st))
}

/// Where the streamed image's parts begin: the image in main memory, the
/// pieces' object lists and their blocks (bytes from `base`).
#[derive(Clone, Copy)]
struct PieceAt {
    base: usize,
    lists_at: usize,
    blocks_at: usize,
}

/// The streamed pieces' node records (block address and words, the FB
/// slot it is moved to, per-type counts; the next piece is chained
/// after), their objects' ids (the lists) and their blocks of records.
struct PieceImage {
    rec: Vec<[i32; 16]>,
    lists: Vec<u32>,
    blocks: Vec<u8>,
    /// The largest block's words.
    largest: usize,
}

/// The pieces' [`PieceImage`], their records copied from `records` (the
/// records written from `records_start` on).
fn piece_image(
    tree: &Tree,
    pieces: &[Vec<(usize, usize)>],
    in_leaf: &[usize],
    (records, records_start): (&[i32], usize),
    w: &W,
    b: &Banks,
    at: PieceAt,
) -> PieceImage {
    let types = tree.types;
    let mut out = PieceImage {
        rec: vec![[0i32; 16]; pieces.len()],
        lists: Vec::new(),
        blocks: Vec::new(),
        largest: 0,
    };
    let mut leaves = 0usize;
    for (p, pc) in pieces.iter().enumerate() {
        let mut words: Vec<i32> = Vec::new();
        let mut counts = [0i32; super::super::STREAMED_TYPES];
        for &(j, q) in pc {
            let ti = &types[j];
            let from = ti.first - records_start + q * ti.size;
            words.extend_from_slice(&records[from..from + ti.size]);
            counts[j] += 1;
        }
        out.largest = out.largest.max(words.len());
        let f = &mut out.rec[p];
        f[word(PS_FLAGS)] = -32768;
        f[word(PS_LIST)] = (at.base + at.lists_at + 4 * out.lists.len()) as i32;
        for &(j, q) in pc {
            out.lists.push(types[j].objects[q] as u32);
        }
        f[word(PS_FB)] = if in_leaf[p] == 0 {
            b.slots_at + (leaves % b.cache_slots) * b.slot_words
        } else if in_leaf[p] % 2 == 0 {
            STREAM_BANK
        } else {
            b.bank0_buf
        } as i32;
        leaves += (in_leaf[p] == 0) as usize;
        f[word(PS_BLOCK)] = (at.base + at.blocks_at + out.blocks.len()) as i32;
        f[word(PS_BLOCK_WORDS)] = words.len() as i32;
        f[PS_COUNTS as usize / 4..][..super::super::STREAMED_TYPES].copy_from_slice(&counts);
        f[word(PS_OBJECTS)] = pc.len() as i32;
        f[word(PS_SHARED)] = tree.shared(pc.iter().map(|&(j, q)| types[j].objects[q])) as i32;
        out.blocks.extend(fb_word_bytes(&words, w.x));
    }
    out
}

/// Chain the pieces of each of the `nn` nodes' leaves (a leaf's pieces are
/// consecutive, from `first_piece`; `usize::MAX` for an inner node): each
/// piece's record points at the next's.
fn chain_pieces(piece_rec: &mut [[i32; 16]], first_piece: &[usize], nn: usize, base: usize) {
    let n_pieces = piece_rec.len();
    for k in 0..nn {
        let first = first_piece[k];
        if first == usize::MAX {
            continue;
        }
        let end = first_piece[k + 1..]
            .iter()
            .copied()
            .find(|&p| p != usize::MAX)
            .unwrap_or(n_pieces);
        for (p, rec) in piece_rec.iter_mut().enumerate().take(end - 1).skip(first) {
            rec[word(PS_NEXT)] = (base + NODE_BYTES * (nn + p + 1)) as i32;
        }
    }
}

/// The resident words after the records' place: `SPLIT`, then `SLOTS`: a
/// pushed node's RAM slot by its place on the node stack, every 4th word
/// (the stack's entries are 4 bytes apart, so TinyRISC finds the slot of
/// the top at a constant offset from its stack pointer). Returns where
/// `SPLIT` is.
fn resident_part(w: &mut W, err: &dyn Fn(usize, String) -> String) -> Result<usize, String> {
    let split_slot = w.fb.len();
    w.raw(0);
    for d in 0..crate::tracer::memory_map::ram::P_SLOTS {
        w.raw(pk_slot(d));
        if d + 1 < crate::tracer::memory_map::ram::P_SLOTS {
            for _ in 0..3 {
                w.raw(0);
            }
        }
    }
    super::super::resident_fits(w, err)?;
    Ok(split_slot)
}

/// Where a streamed leaf's pieces go in the FB: the pieces' limits, the
/// buffer at the top of bank 0, the leaf cache's slots in bank 1, the
/// sub-edges' buffer at its top.
struct Banks {
    rest: usize,
    first: usize,
    second: usize,
    bank0_buf: usize,
    slot_words: usize,
    cache_slots: usize,
    slots_at: usize,
    fan_buf: usize,
}

/// The FB's banks for the streamed pieces of `types`' records, above the
/// resident words `w` holds.
fn banks(
    w: &W,
    fin: &Finish,
    types: &[TypeInfo],
    err: &dyn Fn(usize, String) -> String,
) -> Result<Banks, String> {
    // A leaf's pieces alternate between FB bank 1 and the top of bank 0,
    // above the resident words.
    let largest_record = types.iter().map(|t| t.size).max().unwrap_or(0);
    let room = STREAM_BANK - w.fb.len();
    if largest_record > room {
        return Err(err(
            0,
            format!(
                "a {}-word record does not fit the {room} words bank 0 has above the streamed layout's resident part",
                largest_record
            ),
        ));
    }
    let rest = fin.pieces.rest.max(largest_record).min(room);
    let first = fin.pieces.first.min(rest);
    let second = fin.pieces.second_or_rest().clamp(first, rest);
    let bank0_buf = STREAM_BANK - rest;
    // Bank 1: the further pieces' buffer (even places), then the cache's
    // slots for first pieces (one per leaf, direct-mapped by the leaf's
    // order, neighbouring leaves in different slots); with no room for a
    // slot beside the buffer, one slot that is the buffer.
    let slot_words = first.max(largest_record).next_multiple_of(4);
    let buffer = rest.next_multiple_of(4);
    // The top of bank 1: the buffer a packet's bands of a polygon's
    // sub-edges are moved into (sub-edges apart).
    let fan_buf = w.fan_most.next_multiple_of(4);
    if buffer + fan_buf > STREAM_BANK {
        return Err(err(
            0,
            format!(
                "a banded polygon's {} words of sub-edges and the leaf pieces' {buffer}-word buffer do not fit FB bank 1 ({STREAM_BANK} words)",
                w.fan_most
            ),
        ));
    }
    let bank1 = STREAM_BANK - fan_buf;
    let (cache_slots, slots_at) = if buffer + slot_words <= bank1 {
        ((bank1 - buffer) / slot_words, STREAM_BANK + buffer)
    } else {
        (1, STREAM_BANK)
    };
    Ok(Banks {
        rest,
        first,
        second,
        bank0_buf,
        slot_words,
        cache_slots,
        slots_at,
        fan_buf,
    })
}

/// The node records: inner nodes their split, leaves their first piece's
/// record and flags (`LEAF_AWAKE`, `LEAF_LATE` for a first piece over
/// `rest` words of shared objects). Returns the late leaves.
fn node_records(
    img: &mut [u8],
    nodes: &[Node],
    piece_rec: &[[i32; 16]],
    first_piece: &[usize],
    w: &W,
    rest: usize,
) -> usize {
    let base = mem::STREAM as usize;
    let mut late_leaves = 0usize;
    for (k, n) in nodes.iter().enumerate() {
        let mut f = [0i32; 16];
        match n.split {
            Some(sp) => {
                f[word(PS_FLAGS)] = 4 * sp.axis as i32;
                f[word(PS_SPLIT)] = w.sat(sp.position * w.s);
                f[word(PS_LEFT)] = (base + NODE_BYTES * sp.children[0] as usize) as i32;
                f[word(PS_RIGHT)] = (base + NODE_BYTES * sp.children[1] as usize) as i32;
            }
            None => {
                f[word(PS_FLAGS)] = -32768 | LEAF_EMPTY;
                if first_piece[k] != usize::MAX {
                    // The leaf's record is its first piece's (its list,
                    // block, next piece, counts).
                    let p = piece_rec[first_piece[k]];
                    f[word(PS_LIST)] = p[word(PS_LIST)];
                    f[word(PS_FB)] = p[word(PS_FB)];
                    f[word(PS_BLOCK)..].copy_from_slice(&p[word(PS_BLOCK)..]);
                    let awake = p[word(PS_SHARED)] != 0 || p[word(PS_NEXT)] != 0;
                    let late = p[word(PS_BLOCK_WORDS)] as usize > rest
                        && p[word(PS_SHARED)] == p[word(PS_OBJECTS)];
                    late_leaves += late as usize;
                    f[word(PS_FLAGS)] = -32768
                        | if awake { LEAF_AWAKE } else { 0 }
                        | if late { LEAF_LATE } else { 0 };
                }
            }
        }
        put(img, k, &f);
    }
    late_leaves
}
