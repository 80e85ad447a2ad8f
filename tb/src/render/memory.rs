//! A work item's main memory: where its chip puts the tiles' pixels and
//! how much memory it needs, the tile list fed to it a chunk at a time,
//! the pixels read back.

use anyhow::{anyhow, Result};
use firmware::asm::Image;
use firmware::tracer::{self, mem, Firmware};
use rtl::rc::Word;
use rtl::Chip;

/// Where an item's chip puts its tiles' pixels, and the main memory it
/// needs: as large as the program touches (its segments, the tile list of
/// `tiles` tiles, the output tiles and the streamed scene image), not the
/// 16 MiB default: a fresh instance per item must not zero-fill memory
/// nobody reads.
pub(super) fn item_memory(img: &Image, fw: &Firmware, tiles: usize) -> (u32, usize) {
    let wb = fw.fb_word_bytes();
    // What lies above `mem::OUTPUT`: the streamed scene image and its
    // mailboxes, the packet traversal's mailboxes.
    let above = fw
        .layout
        .stream
        .as_ref()
        // the image, then the mailboxes (a half-word per object)
        .map(|st| {
            (st.base as usize + st.image.len()).max(st.mailbox as usize + 2 * fw.layout.objects)
        })
        .into_iter()
        .chain(
            // the packet traversal's mailboxes (main memory, resident or
            // streamed)
            (fw.layout.traversal == tracer::Traversal::Packet)
                .then(|| fw.layout.mailbox + tracer::layout::PK_MAILBOX_BYTES * fw.layout.objects),
        )
        .max()
        .unwrap_or(0);
    // The tiles' pixels: at `mem::OUTPUT`, or past that data where an
    // item's tiles would reach it (each tile's address is in the list).
    let out_bytes = tiles * fw.out_tile_bytes() as usize;
    let output = if above > mem::OUTPUT as usize
        && mem::OUTPUT as usize + out_bytes > mem::STREAM as usize
    {
        above.next_multiple_of(1 << 12) as u32
    } else {
        mem::OUTPUT
    };
    let ends = img
        .segments
        .iter()
        .map(|s| s.addr as usize + s.data.len())
        .chain([
            mem::FB_IMAGE as usize + wb as usize * fw.fb.len(),
            mem::TILE_LIST as usize + 4 + 12 * tiles.min(LIST_CHUNK),
            output as usize + out_bytes,
            above,
        ]);
    let mem_bytes = ends.max().unwrap_or(0).next_multiple_of(1 << 16);
    (output, mem_bytes)
}

/// The pixels of the tiles `tiles` of the item's list, read back from
/// main memory at `output`.
pub(super) fn read_tiles(
    mem: &rtl::memory::MainMemory,
    fw: &Firmware,
    output: u32,
    tiles: std::ops::Range<usize>,
) -> Vec<Vec<i32>> {
    let wb = fw.fb_word_bytes();
    tiles
        .map(|k| {
            let base = output + k as u32 * fw.out_tile_bytes();
            (0..256)
                .map(|i| {
                    let v = mem.read(base + wb * i, wb);
                    if wb == 2 {
                        v as u16 as i16 as i32
                    } else {
                        v as i32
                    }
                })
                .collect()
        })
        .collect()
}

/// Tile-list entries a chip's list holds (below `mem::OUTPUT`, 12 bytes
/// each after the count).
const LIST_CHUNK: usize = ((mem::OUTPUT - mem::TILE_LIST - 4) / 12) as usize;

/// Write the tile list's chunk from `list[from]` (count, then per tile its
/// corner and its pixels' address, `output` plus the tile's place in
/// `list`); returns where the next chunk starts.
pub(super) fn feed<W: Word>(
    chip: &mut Chip<W>,
    list: &[(u32, u32)],
    from: usize,
    output: u32,
    tile_bytes: u32,
) -> Result<usize> {
    let to = list.len().min(from + LIST_CHUNK);
    let mut bytes = Vec::with_capacity(4 + 12 * (to - from));
    bytes.extend(((to - from) as u32).to_le_bytes());
    for (k, (x, y)) in list.iter().enumerate().take(to).skip(from) {
        bytes.extend(x.to_le_bytes());
        bytes.extend(y.to_le_bytes());
        bytes.extend((output + k as u32 * tile_bytes).to_le_bytes());
    }
    chip.load(mem::TILE_LIST, &bytes)
        .map_err(|f| anyhow!("{f}"))?;
    Ok(to)
}
