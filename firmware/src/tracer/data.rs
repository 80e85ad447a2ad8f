//! TinyRISC's data words and the other names of the program that both the
//! generator and the host read: typed constants, so that a misspelt name
//! is a compile error, not a program that fails to assemble or a host that
//! finds no symbol. Each [`Var`] is one line of the program's `.data`
//! section (`PASS: .word 0 ; the ray pass's number`); [`Label`]s are code
//! labels and header constants the host looks up in the assembled image.

use std::fmt::{self, Display};

use super::emit::Name;

/// A data word (or block) of TinyRISC's: its name, its directive and
/// what it holds. Displayed as its name (`at(PASS, R0)` emits
/// `PASS(r0)`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Var {
    pub name: &'static str,
    /// The directive that reserves it: `.word 0`, `.space 256`.
    pub init: &'static str,
    pub doc: &'static str,
}

impl Var {
    const fn new(name: &'static str, init: &'static str, doc: &'static str) -> Var {
        Var { name, init, doc }
    }

    /// Its line of the `.data` section.
    pub fn line(&self) -> String {
        self.line_with(self.init)
    }

    /// Its line with a directive computed for the program (`.space 8 *
    /// lights`).
    pub fn line_with(&self, init: &str) -> String {
        data_line(self.name, init, self.doc)
    }
}

impl Display for Var {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name)
    }
}

/// A line of the `.data` section: `NAME:`, the directive, the comment.
pub fn data_line(name: &str, init: &str, doc: &str) -> String {
    let head = format!("{:<16}{init}", format!("{name}:"));
    if doc.is_empty() {
        head
    } else {
        format!("{head:<40}; {doc}")
    }
}

/// A name of the program the host looks up by value: a code label or a
/// header constant.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Label(pub &'static str);

impl Display for Label {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.0)
    }
}

pub const PASS: Var = Var::new("PASS", ".word 0", "the ray pass's number (mailboxes)");
pub const MODE: Var = Var::new(
    "MODE",
    ".word 0",
    "0: closest hit, 1: any hit (shadow rays)",
);
pub const SAVE_LR: Var = Var::new("SAVE_LR", ".word 0", "trace's return address");
pub const BAND_SAVE: Var = Var::new(
    "BAND_SAVE",
    ".word 0, 0, 0",
    "r8, r12, r13 while a banded polygon's bands are found",
);
pub const AWAKE: Var = Var::new("AWAKE", ".word 0, 0", "the RCs awake (RCs 0..31, 32..63)");
/// The three per-axis masks below (a label of its own, no word).
pub const NEG: Label = Label("NEG");
pub const NEG_X: Var = Var::new(
    "NEG_X",
    ".word 0, 0",
    "per axis, the rays going down along it",
);
pub const NEG_Y: Var = Var::new("NEG_Y", ".word 0, 0", "");
pub const NEG_Z: Var = Var::new("NEG_Z", ".word 0, 0", "");
pub const T_START: Var = Var::new(
    "T_START",
    ".word 0",
    "the cycle counter at the tile loop's start",
);
pub const T_END: Var = Var::new("T_END", ".word 0", "... and at its end");
pub const TESTS: Var = Var::new("TESTS", ".word 0", "object tests broadcast");
pub const PASSES: Var = Var::new("PASSES", ".word 0", "ray passes");
pub const TL_PTR: Var = Var::new("TL_PTR", ".word 0", "the tile list's current entry");
pub const TL_CNT: Var = Var::new("TL_CNT", ".word 0", "tiles left");
pub const TL_BANK: Var = Var::new("TL_BANK", ".word 0", "the output bank of this tile (0, 1)");
pub const CUR_OUT: Var = Var::new("CUR_OUT", ".word 0", "where this tile's output goes");
pub const NSTACK: Var = Var::new("NSTACK", ".space 256", "the node stack");
pub const NK: Var = Var::new(
    "NK",
    ".word 0, 0, 0",
    "per axis: the node kernel of the pass's child order",
);
pub const NF: Var = Var::new(
    "NF",
    ".word 0, 0, 0",
    "per axis: the first child's field in a node",
);
pub const NS: Var = Var::new("NS", ".word 0, 0, 0", "per axis: the second child's field");
pub const TILE_GEN: Var = Var::new(
    "TILE_GEN",
    ".word 0",
    "the tile's number for the leaf cache: its corner, y << 12 | x",
);
pub const PREV_GEN: Var = Var::new(
    "PREV_GEN",
    ".word 0",
    "the tile before's number: its leaves in the cache are hits too",
);
pub const LEAF_TAGS: Var = Var::new(
    "LEAF_TAGS",
    ".space 0x8000",
    "leaf cache tags, at LEAF_TAGS + 2 (a - SBANK) for the slot at FB address a: its block and tile",
);
pub const UPTR: Var = Var::new("UPTR", ".word 0", "the unordered-subtree stack's top");
pub const USTK: Var = Var::new("USTK", ".space 160", "the unordered-subtree stack");
pub const CUR_BLK: Var = Var::new("CUR_BLK", ".word 0", "the leaf block in SBANK");

/// Merged shadow packets' words ([`super::shadows`]).
pub const SC_RET: Var = Var::new("SC_RET", ".word 0", "shadows' return address");
pub const SC_FB: Var = Var::new("SC_FB", ".word 0", "the tile's output bank (FB address)");
pub const SC_L: Var = Var::new("SC_L", ".word 0", "the light being packed");
pub const SC_BITS: Var = Var::new(
    "SC_BITS",
    ".word 0, 0",
    "its lit RCs not packed yet (RCs 0..31, 32..63)",
);
pub const SC_N: Var = Var::new("SC_N", ".word 0", "rays in the packet");
/// `.space 8 * lights`.
pub const SC_LIT: Var = Var::new("SC_LIT", "", "per light: the RCs lit by it (two words)");
/// `.space 8 * lights`.
pub const SC_VIS: Var = Var::new(
    "SC_VIS",
    "",
    "per light: the RCs whose shadow ray is unblocked",
);
pub const SC_SRC: Var = Var::new(
    "SC_SRC",
    ".space 256",
    "per packet entry: light * 64 + the RC that spawned the ray",
);
/// `.byte` the tile's RCs.
pub const SC_LANES: Var = Var::new(
    "SC_LANES",
    "",
    "the tile's RCs: packet entry n goes to RC SC_LANES[n]",
);
pub const DEBRUIJN: Var = Var::new(
    "DEBRUIJN",
    ".byte 0, 1, 28, 2, 29, 14, 24, 3, 30, 22, 20, 15, 25, 17, 4, 8",
    "bit index of 2^i: DEBRUIJN[(2^i * 0x077CB531) >> 27]",
);

/// The tile loop's head: a work item's chip counts its cycles from here.
pub const TILE: Label = Label("tile");
/// Pass numbers wrap here (the paper's traversal: 16-bit mailboxes); a
/// header constant.
pub const PASS_WRAP: Label = Label("PASS_WRAP");
/// The streamed packet traversal's leaf cache: its lookup and its miss,
/// whose issues the simulator counts.
pub const LEAF_FIRST: Label = Label("leaf_first");
pub const LEAF_MISS: Label = Label("leaf_miss");
/// Where a leaf's further pieces wait for their DMA (the simulator counts
/// the wait).
pub const LEAF_LOAD: Label = Label("leaf_load");

/// The tile list (main memory, written by the host): its count, then an
/// entry per tile.
pub const TL_COUNT: Name = Name::new("TL_COUNT", 0, "  the number of tiles");
pub const TL_FIRST: Name = Name::new("TL_FIRST", 4, "  the first tile's entry:");
pub const TILE_PX: Name = Name::new("TILE_PX", 0, "    its corner's pixel column");
pub const TILE_PY: Name = Name::new("TILE_PY", 4, "    its corner's pixel row");
pub const TILE_OUT: Name = Name::new("TILE_OUT", 8, "    where its output goes in main memory");
pub const TILE_BYTES: Name = Name::new("TILE_BYTES", 12, "  bytes of an entry");
pub const MASK_HI: Name = Name::new("MASK_HI", 4, "the high word of a 64-bit mask (RCs 32..63)");
pub const AXIS_X: Name = Name::new("AXIS_X", 0, "a per-axis table's words");
pub const AXIS_Y: Name = Name::new("AXIS_Y", 4, "");
pub const AXIS_Z: Name = Name::new("AXIS_Z", 8, "");
/// The eye stream's first words: the tile's corner, written per tile.
pub const EYE_PX: Name = Name::new("EYE_PX", 0, "  the tile's corner, written per tile");
pub const EYE_PY: Name = Name::new("EYE_PY", 1, "");
/// FB word (bank 0) the split of the node being classified is written to
/// (streamed layouts); a header constant.
pub const SPLIT: Label = Label("SPLIT");

/// Header constants that say where the data image puts things; a program
/// emitted for another scene or other options differs in one (`render
/// --firmware` checks them).
pub const FBIMG: Label = Label("FBIMG");
pub const FBWORDS: Label = Label("FBWORDS");
pub const TILELIST: Label = Label("TILELIST");
pub const FB_EYE: Label = Label("FB_EYE");
pub const FB_POST: Label = Label("FB_POST");
pub const ROOT: Label = Label("ROOT");
pub const MAILBOX: Label = Label("MAILBOX");
pub const NOBJ: Label = Label("NOBJ");
pub const ROOTBOX: Label = Label("ROOTBOX");
pub const SBANK: Label = Label("SBANK");
pub const IMAGE_SYMBOLS: [Label; 11] = [
    FBIMG, FBWORDS, TILELIST, FB_EYE, FB_POST, ROOT, MAILBOX, NOBJ, ROOTBOX, SPLIT, SBANK,
];
