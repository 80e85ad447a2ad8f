//! Where the tracer keeps its data: the RC RAM map ([`ram`]), the FB's
//! extent ([`FB_LIMIT`], [`STREAM_BANK`]), the number formats of the
//! kernels ([`formats`]). The generator writes kernels
//! with these names and the program's header defines them, one line and
//! a comment each, so the emitted firmware reads `ld r8, [r0 + #C_ONE]`,
//! not `ld r8, [r0 + #256]`.

use super::emit::{define, Name};

/// Words of FB set 0.
pub const FB_LIMIT: usize = 0x8000;

/// FB bank 1 (set 0): the streaming buffer of the streamed layout.
pub const STREAM_BANK: usize = 0x4000;

/// The RC RAM map: word addresses in every RC's 512-word RAM. The ray
/// registers r1..r7 (origin, direction, `tbest`) live across kernels; what
/// must outlive a kernel and does not fit the registers is here.
pub mod ram {
    use super::Name;

    /// Reciprocal square root table (RSQ_ENTRIES words; index `X >> RSQ_SHIFT`, X in Q.11).
    pub const RSQ: Name = Name::new("RSQ", 0, "reciprocal square root table, Q1.14");
    /// Reciprocal table (RCP_ENTRIES words; index bits of a normalised divisor).
    pub const RCP: Name = Name::new("RCP", 128, "reciprocal table, 2^29 / d");
    pub const C_ONE: Name = Name::new("C_ONE", 256, "1.0 in Q1.14");
    pub const C_INF: Name = Name::new("C_INF", 257, "the largest word: no hit");
    pub const LANE_ROW: Name = Name::new("LANE_ROW", 258, "the RC's row in the array, 0..7");
    pub const LANE_COL: Name = Name::new("LANE_COL", 259, "the RC's column, 0..7");
    pub const LANE_ACT: Name = Name::new(
        "LANE_ACT",
        260,
        "1 if the RC traces a ray of the tile (the ways), else 0",
    );
    /// The "vector" of the paper's Fig. 7: closest hit of the current pass.
    pub const HIT_OBJ: Name = Name::new("HIT_OBJ", 261, "closest hit of the pass: object id");
    pub const HIT_MAT: Name = Name::new("HIT_MAT", 262, "closest hit: material id");
    pub const HIT_N: Name = Name::new("HIT_N", 263, "closest hit: normal, 3 words Q1.14");
    /// `tbest` at the start of the pass (a hit is `tbest < PASS_T0`).
    pub const PASS_T0: Name = Name::new(
        "PASS_T0",
        266,
        "tbest at the pass's start (a hit: tbest < PASS_T0)",
    );
    /// Shading state of the current recursion level.
    pub const SH_P: Name = Name::new("SH_P", 267, "hit point being shaded, 3 words");
    pub const SH_N: Name = Name::new("SH_N", 270, "its shading normal, 3 words");
    pub const SH_MAT: Name = Name::new("SH_MAT", 273, "its material id");
    pub const SH_D: Name = Name::new("SH_D", 274, "direction of the ray that hit, 3 words");
    pub const ACT: Name = Name::new("ACT", 277, "1 if the ray being shaded hit something");
    pub const COL: Name = Name::new("COL", 278, "colour of this level, 3 words Q3.12");
    pub const OUT_OBJ: Name =
        Name::new("OUT_OBJ", 281, "object id of the eye ray's hit (-1: none)");
    pub const SH_KS: Name = Name::new("SH_KS", 282, "reflectance Ks of the hit's material");
    pub const SH_NL: Name = Name::new("SH_NL", 283, "N.L towards the current light");
    pub const SH_RV: Name = Name::new("SH_RV", 284, "R.V of the current light");
    pub const LIT: Name = Name::new("LIT", 285, "1 if the light is in front of the surface");
    pub const TMP0: Name = Name::new("TMP0", 286, "temporaries of one kernel");
    pub const TMP1: Name = Name::new("TMP1", 287, "");
    pub const TMP2: Name = Name::new("TMP2", 288, "");
    pub const TMP3: Name = Name::new("TMP3", 289, "");
    pub const TMP4: Name = Name::new("TMP4", 290, "");
    /// The cone kernel's frame values and zoom (8 words, temporaries of
    /// that kernel).
    pub const CONE_TMP: Name = Name::new("CONE_TMP", 291, "the cone kernel's temporaries, 8 words");
    /// Four more temporaries of one kernel (the cylinder's: `TMP7`, `TMP8`
    /// keep its `1/r` and `r` from its bound on), sharing the cone
    /// kernel's words.
    pub const TMP5: Name = Name::new("TMP5", 291, "the cylinder kernel's (CONE_TMP's words)");
    pub const TMP6: Name = Name::new("TMP6", 292, "");
    pub const TMP7: Name = Name::new("TMP7", 293, "");
    pub const TMP8: Name = Name::new("TMP8", 294, "");
    /// Two-sided planar objects: the object the current rays leave (-1:
    /// none, eye rays), which they do not hit again.
    pub const ORIG_OBJ: Name = Name::new(
        "ORIG_OBJ",
        299,
        "the object the rays leave (-1: none): not hit again",
    );
    /// The local stack: a frame per recursion level.
    pub const STACK: Name = Name::new(
        "STACK",
        300,
        "per recursion level: colour so far and reflection weight",
    );
    /// Words of a stack frame: colour r, g, b and the reflection weight.
    pub const STACK_FRAME: u32 = 4;
    /// Fields of a stack frame.
    pub const FR_COL: Name = Name::new("FR_COL", 0, "frame: colour so far, 3 words");
    pub const FR_KS: Name = Name::new("FR_KS", 3, "frame: reflection weight");
    /// Local positions ([`crate::tracer::Positions::Local`]), past the
    /// deepest recursion's stack frames (`STACK + 7 * STACK_FRAME`): the
    /// remainder of the current rays' origins, of the hit point being
    /// shaded, and the closest local hit's point (its `t` tags it: the
    /// pass's hit is local where `tbest` equals `HIT_TL`).
    pub const RAY_OL: Name = Name::new(
        "RAY_OL",
        328,
        "local positions: the ray origin's remainder, 3 words, 2^-14 LSB",
    );
    pub const SH_PL: Name = Name::new("SH_PL", 331, "the remainder of SH_P, 3 words");
    pub const HIT_PH: Name = Name::new(
        "HIT_PH",
        334,
        "closest local hit: its point, 3 words (remainder in HIT_PL)",
    );
    pub const HIT_PL: Name = Name::new("HIT_PL", 337, "its point's remainder, 3 words");
    /// Streamed layout: number of unordered BSP subtrees the ray is in
    /// whose visiting order goes against its direction (it may only sleep
    /// at a leaf when this is 0).
    pub const UNORD: Name = Name::new(
        "UNORD",
        340,
        "unordered subtrees entered against the ray's direction",
    );
    /// Smooth triangles: the interpolated shading normal of the closest
    /// smooth triangle hit so far and its object id (it is the hit's
    /// shading normal when the id is the hit's), and the geometric normal
    /// of the hit being shaded.
    pub const HIT_NS: Name = Name::new(
        "HIT_NS",
        341,
        "closest smooth triangle: shading normal, 3 words",
    );
    pub const HIT_NS_OBJ: Name = Name::new("HIT_NS_OBJ", 344, "its object id");
    pub const SH_NG: Name = Name::new(
        "SH_NG",
        345,
        "geometric normal of the hit being shaded, 3 words",
    );
    /// Two-sided (transmitting) objects: the id of the closest one hit
    /// from its back so far (-1: none), and whether the hit being shaded
    /// is such a back hit (the ray leaves the object).
    pub const HIT_BACK_OBJ: Name = Name::new(
        "HIT_BACK_OBJ",
        348,
        "closest object hit from its back (-1: none)",
    );
    pub const SH_BACK: Name = Name::new("SH_BACK", 349, "1 if the hit being shaded is a back hit");
    /// The refraction stack: per recursion level, the refracted ray's
    /// origin (3), direction (3) and weight T (0: none), set up before the
    /// level's reflection and traced after it.
    pub const REFR: Name = Name::new(
        "REFR",
        350,
        "per recursion level: the refracted ray to trace",
    );
    /// Words of a refraction frame.
    pub const REFR_FRAME: u32 = 7;
    pub const RF_O: Name = Name::new("RF_O", 0, "refraction frame: origin, 3 words");
    pub const RF_D: Name = Name::new("RF_D", 3, "refraction frame: direction, 3 words");
    pub const RF_T: Name = Name::new("RF_T", 6, "refraction frame: weight T (0: no ray)");
    /// Local positions: the closest local hit's `t` (past the deepest
    /// recursion's refraction frames, `REFR + 7 * REFR_FRAME`).
    pub const HIT_TL: Name = Name::new(
        "HIT_TL",
        399,
        "the closest local hit's t (-1: none this pass)",
    );
    /// Local positions: the closest local hit's `t` below the LSB.
    pub const HIT_TLL: Name = Name::new(
        "HIT_TLL",
        401,
        "the closest local hit's t's remainder, 2^-14 LSB",
    );
    /// Packet traversal: 1 while the ray takes part in the current pass (it
    /// may be woken at a pop).
    pub const P_ALIVE: Name = Name::new("P_ALIVE", 400, "1 while the ray takes part in the pass");
    /// Per axis, the direction's reciprocal as a shift `z - 1` and a signed
    /// mantissa `R`, and the widening `dt` of a plane in `t`.
    pub const P_Z: Name = Name::new("P_Z", 403, "per axis: shift z - 1 of 1/d");
    pub const P_R: Name = Name::new("P_R", 406, "per axis: signed mantissa of 1/d");
    pub const P_DT: Name = Name::new("P_DT", 409, "per axis: a plane's widening in t");
    /// Merged shadow packets ([`crate::tracer::shadows`]): the RC's
    /// number, whether it holds a ray of the packet, its own `ORIG_OBJ`
    /// meanwhile, and per light (up to 12) the N.L and R.V of its hit.
    pub const LANE_ID: Name = Name::new("LANE_ID", 412, "the RC's number, row * 8 + column");
    pub const SHADOW_LOADED: Name = Name::new(
        "SHADOW_LOADED",
        413,
        "1 if the RC holds a ray of the merged shadow packet",
    );
    pub const SHADOW_ORIG: Name = Name::new(
        "SHADOW_ORIG",
        414,
        "the RC's own ORIG_OBJ while merged packets load others'",
    );
    /// The interval stack: one slot per BSP depth (the far child of the
    /// node at depth d is pushed into slot d), words `tmax, tmin`.
    pub const P_SLOT: Name = Name::new(
        "P_SLOT",
        416,
        "per BSP depth: the pushed child's interval (tmax, tmin)",
    );
    /// Slots of the interval stack.
    pub const P_SLOTS: u32 = crate::scene_image::MAX_BSP_DEPTH;
    /// Fields of an interval slot.
    pub const SLOT_TMAX: Name = Name::new("SLOT_TMAX", 0, "slot: far end of the interval");
    pub const SLOT_TMIN: Name = Name::new("SLOT_TMIN", 1, "slot: near end");
    /// Per recursion level, the object the refracted ray leaves.
    pub const ORIG_STACK: Name = Name::new(
        "ORIG_STACK",
        480,
        "per recursion level: the object its refracted ray leaves",
    );
    /// Local positions: the ray direction's remainder, in the words of
    /// the merged shadow packets' slots (local positions run without
    /// them, [`crate::tracer::shadows::applies`]).
    pub const RAY_DL: Name = Name::new(
        "RAY_DL",
        488,
        "local positions: the ray direction's remainder, 3 words, 2^-27 (SHADOW_SLOTS' words)",
    );
    pub const SHADOW_SLOTS: Name = Name::new(
        "SHADOW_SLOTS",
        488,
        "merged shadows: per light, N.L and R.V of the hit",
    );

    /// Every name of the map, in address order (fields of frames after).
    pub const ALL: &[Name] = &[
        RSQ,
        RCP,
        C_ONE,
        C_INF,
        LANE_ROW,
        LANE_COL,
        LANE_ACT,
        HIT_OBJ,
        HIT_MAT,
        HIT_N,
        PASS_T0,
        SH_P,
        SH_N,
        SH_MAT,
        SH_D,
        ACT,
        COL,
        OUT_OBJ,
        SH_KS,
        SH_NL,
        SH_RV,
        LIT,
        TMP0,
        TMP1,
        TMP2,
        TMP3,
        TMP4,
        CONE_TMP,
        TMP5,
        TMP6,
        TMP7,
        TMP8,
        ORIG_OBJ,
        STACK,
        RAY_OL,
        SH_PL,
        HIT_PH,
        HIT_PL,
        UNORD,
        HIT_NS,
        HIT_NS_OBJ,
        SH_NG,
        HIT_BACK_OBJ,
        SH_BACK,
        REFR,
        HIT_TL,
        P_ALIVE,
        HIT_TLL,
        P_Z,
        P_R,
        P_DT,
        LANE_ID,
        SHADOW_LOADED,
        SHADOW_ORIG,
        P_SLOT,
        ORIG_STACK,
        RAY_DL,
        SHADOW_SLOTS,
    ];
    /// Fields of the frames and slots above.
    pub const FIELDS: &[Name] = &[FR_COL, FR_KS, RF_O, RF_D, RF_T, SLOT_TMAX, SLOT_TMIN];
}

/// The number formats: the kernels write every fraction count of the
/// 16-bit chip's formats as `Qn` (`n` + the datapath's extra bits `X`), so
/// one kernel text serves both datapaths.
pub mod formats {
    /// The `Qn` constants the kernels use.
    pub const Q: [u32; 9] = [7, 8, 10, 11, 12, 13, 14, 15, 16];

    /// What `Qn` is, for the header.
    pub fn doc(n: u32) -> &'static str {
        match n {
            14 => "unit vectors, cosines (Q1.14)",
            12 => "colours and weights (Q3.12)",
            13 => "Q.13: halves of Q1.14 quantities",
            15 => "Q.15: products of two Q1.14 with one more bit",
            11 => "Q.11: the square of a vector in normalize",
            _ => "",
        }
    }
}

/// The header lines of the formats: `X` and `Q7`..`Q16`.
pub fn format_lines(extra_bits: u32) -> Vec<String> {
    let mut v = vec![define(
        "X",
        extra_bits,
        "extra fraction bits of the datapath (16 on the 32-bit chip)",
    )];
    for n in formats::Q {
        v.push(define(
            &format!("Q{n}"),
            format!("{n} + X"),
            formats::doc(n),
        ));
    }
    v
}

/// The header lines of the RC RAM map.
pub fn ram_lines(depth: u32) -> Vec<String> {
    let mut v: Vec<String> = ram::ALL.iter().map(Name::define).collect();
    v.push(define(
        "STACK_FRAME",
        ram::STACK_FRAME,
        "words of a STACK frame",
    ));
    v.push(define(
        "REFR_FRAME",
        ram::REFR_FRAME,
        "words of a REFR frame",
    ));
    for l in 0..depth.saturating_sub(1) {
        v.push(define(
            &format!("STACK_L{l}"),
            format!("STACK + {l}*STACK_FRAME"),
            if l == 0 {
                "the frame of recursion level 0, 1, ..."
            } else {
                ""
            },
        ));
    }
    for l in 0..depth.saturating_sub(1) {
        v.push(define(
            &format!("REFR_L{l}"),
            format!("REFR + {l}*REFR_FRAME"),
            if l == 0 {
                "the refraction frame of level 0, 1, ..."
            } else {
                ""
            },
        ));
    }
    v.extend(ram::FIELDS.iter().map(Name::define));
    v
}

#[cfg(test)]
mod tests {
    use super::ram;
    use crate::tracer::MAX_RAY_DEPTH;

    // The deepest recursion's stack and refraction frames end before the
    // words placed after them.
    const FRAMES: u32 = MAX_RAY_DEPTH - 1;
    const _: () = assert!(ram::STACK.value + FRAMES * ram::STACK_FRAME <= ram::RAY_OL.value);
    const _: () = assert!(ram::REFR.value + FRAMES * ram::REFR_FRAME <= ram::HIT_TL.value);
    const _: () = assert!(ram::HIT_PL.value + 3 <= ram::UNORD.value);

    /// The map runs in address order.
    #[test]
    fn the_map_runs_in_address_order() {
        for w in ram::ALL.windows(2) {
            assert!(
                w[0].value <= w[1].value,
                "{} after {}",
                w[1].name,
                w[0].name
            );
        }
    }
}
