//! The TinyRISC program: tile loop, recursion levels, BSP traversal steered
//! by the RCs' status, the Fig. 6 object loop with mailboxes, and output.
//!
//! TinyRISC registers: r0 = 0, r15 = link, r14 = node stack pointer; the
//! tile loop keeps its state in memory so that the subroutines may use
//! r1..r13.

use std::fmt::Write;

use super::kernels::{self as k, Inside, K};
use super::layout::{ChipType, Layout};
use super::{mem, NodeLayout, Numerics, Options, Traversal};
use crate::scene::Scene;

pub struct Program {
    pub source: String,
    pub context_words: usize,
    pub kernels: Vec<(String, usize)>,
}

/// Output banks of FB set 1 (alternating, so DMA drains one while the next
/// tile is written to the other).
const OUT_BANK: [u32; 2] = [0x8000, 0xC000];

/// A kernel's context-memory address, as an assembler expression.
fn kaddr(n: &str) -> String {
    format!("({n} - CTXBASE) / 4")
}

/// A kernel's length in contexts, as an assembler expression.
fn klen(n: &str) -> String {
    format!("({n}_end - {n}) / 4")
}

/// Broadcast kernel `n` (no FB stream).
fn cb(w: &mut String, n: &str) {
    let _ = writeln!(
        w,
        "        li r1, {}\n        cbcast r1, {}",
        kaddr(n),
        klen(n)
    );
}

pub fn program(
    scene: &Scene,
    lay: &Layout,
    opt: &Options,
    nm: &Numerics,
    tw: u32,
    th: u32,
) -> Result<Program, String> {
    // ---- kernels ----
    let packet = lay.traversal == Traversal::Packet;
    let mut ks: Vec<(&str, K)> = if packet {
        let mut init = k::init();
        k::pk_init_ram(&mut init);
        vec![
            ("k_init", init),
            ("k_rows", k::rows()),
            ("k_lanes", k::lanes(tw, th)),
            ("k_wake", k::pk_wake_restore()),
            ("k_sign0", k::sign(0)),
            ("k_sign1", k::sign(1)),
            ("k_sign2", k::sign(2)),
            ("k_pinit", k::pk_init(nm.approx())),
            ("k_pn0b", k::pk_node(0, false)),
            ("k_pn0a", k::pk_node(0, true)),
            ("k_pn1b", k::pk_node(1, false)),
            ("k_pn1a", k::pk_node(1, true)),
            ("k_pn2b", k::pk_node(2, false)),
            ("k_pn2a", k::pk_node(2, true)),
            ("k_p2nd", k::pk_second()),
            ("k_psl", k::pk_sleep_first()),
            ("k_ptake", k::pk_take()),
            ("k_ppush", k::pk_push()),
            ("k_ppop", k::pk_pop()),
            ("k_pleafa", k::pk_leaf_any()),
        ]
    } else {
        vec![
            ("k_init", k::init()),
            ("k_rows", k::rows()),
            ("k_lanes", k::lanes(tw, th)),
            ("k_wake", k::wake_restore()),
            ("k_sign0", k::sign(0)),
            ("k_sign1", k::sign(1)),
            ("k_sign2", k::sign(2)),
            ("k_cls0", k::classify(0)),
            ("k_cls1", k::classify(1)),
            ("k_cls2", k::classify(2)),
            ("k_clsr", k::classify_above()),
            ("k_leafc", k::leaf_closest()),
            ("k_leafa", k::leaf_any()),
        ]
    };
    // Smooth triangles: the shading normal and the reflection's fallback.
    let smooth = lay.types.iter().any(|x| {
        matches!(
            x.ty,
            ChipType::SmoothTriangle | ChipType::GlassSmoothTriangle
        )
    });
    let refract = lay.refract;
    let post = |level0: bool, m: usize, eps: i32| {
        if smooth || refract {
            k::post_ext(level0, m, eps, smooth, refract)
        } else {
            k::post(level0, m, eps)
        }
    };
    let reflect_setup = if smooth {
        k::reflect_setup_smooth
    } else {
        k::reflect_setup
    };
    ks.extend([
        ("k_eye", k::eye_ext(lay.kd, nm.approx(), refract)),
        ("k_post0", post(true, lay.materials, nm.eps_lsb)),
        ("k_post1", post(false, lay.materials, nm.eps_lsb)),
        ("k_light", k::light_setup(nm.approx(), lay.light_shifted)),
        ("k_shade", k::shade(&lay.shines)),
        ("k_out0", k::out_word(0)),
        ("k_out1", k::out_word(1)),
        ("k_out2", k::out_word(2)),
        ("k_out3", k::out_word(3)),
    ]);
    let mut st_row = K::default();
    st_row.c(format!("st r8, [#{}]", k::ram::LANE_ROW));
    let mut st_col = K::default();
    st_col.c(format!("st r8, [#{}]", k::ram::LANE_COL));
    ks.push(("k_strow", st_row));
    ks.push(("k_stcol", st_col));
    let levels = opt.depth;
    let mut refl: Vec<(String, K)> = Vec::new();
    for l in 0..levels.saturating_sub(1) {
        refl.push((format!("k_refl{l}"), reflect_setup(l)));
        refl.push((format!("k_pop{l}"), k::reflect_pop(l)));
        if refract {
            refl.push((
                format!("k_tset{l}"),
                k::refract_prepare(l, lay.transmit_materials, nm.approx()),
            ));
            refl.push((format!("k_refr{l}"), k::refract_setup(l)));
            refl.push((format!("k_rpop{l}"), k::refract_pop(l)));
        }
    }
    if lay.stream.is_some() && !packet {
        refl.push(("k_leafcu".into(), k::leaf_closest_ordered()));
        refl.push(("k_uzero".into(), k::unord_zero()));
        for a in 0..3u8 {
            refl.push((format!("k_uin{a}"), k::unord_count(a, 1)));
            refl.push((format!("k_uout{a}"), k::unord_count(a, -1)));
        }
    }
    // Object kernels: only the types present.
    let mut objk: Vec<(&str, K)> = Vec::new();
    let has = |t: ChipType| lay.types.iter().any(|x| x.ty == t);
    if has(ChipType::Sphere) {
        objk.push((
            "k_sphere",
            k::sphere_with(
                lay.ks_sphere,
                lay.ep_sphere,
                nm.approx(),
                lay.sphere_fine,
                lay.fine_normals,
            ),
        ));
    }
    if has(ChipType::GlassSphere) {
        objk.push((
            "k_gsphere",
            k::sphere_two_sided(
                lay.ks_sphere,
                lay.ep_sphere,
                nm.approx(),
                lay.sphere_fine,
                lay.fine_normals,
            ),
        ));
    }
    if has(ChipType::Cylinder) {
        objk.push((
            "k_cyl",
            k::cylinder(lay.ks_cyl, lay.ep_cyl, nm.approx(), lay.fine_normals),
        ));
        objk.push(("k_disc", k::planar(Inside::Disc, lay.kt_disc, nm.approx())));
    }
    if has(ChipType::Cone) {
        objk.push(("k_cone", k::cone(lay.ks_cone, lay.ep_cone, nm.approx())));
        if !has(ChipType::Cylinder) {
            objk.push((
                "k_disc",
                k::planar(Inside::Disc, lay.kt_disc, nm.approx()),
            ));
        }
    }
    if has(ChipType::Box) {
        objk.push(("k_box", k::aabox(nm.approx())));
    }
    if has(ChipType::Rectangle) {
        objk.push((
            "k_rect",
            k::planar(Inside::Rectangle, lay.kt_rect, nm.approx()),
        ));
    }
    if has(ChipType::Triangle) {
        objk.push((
            "k_tri",
            k::planar(Inside::Triangle, lay.kt_tri, nm.approx()),
        ));
    }
    if has(ChipType::SmoothTriangle) {
        objk.push(("k_tris", k::smooth_triangle(lay.kt_tri, nm.approx())));
    }
    if has(ChipType::Polygon) {
        objk.push(("k_polyh", k::polygon_head(nm.approx())));
        objk.push(("k_polye", k::polygon_edge()));
        objk.push(("k_polyt", k::polygon_tail()));
    }
    // Transmitting (two-sided) planar types.
    if has(ChipType::GlassRectangle) {
        objk.push((
            "k_grect",
            k::planar_two_sided(Inside::Rectangle, lay.kt_rect, nm.approx()),
        ));
    }
    if has(ChipType::GlassTriangle) {
        objk.push((
            "k_gtri",
            k::planar_two_sided(Inside::Triangle, lay.kt_tri, nm.approx()),
        ));
    }
    if has(ChipType::GlassCylinder) {
        objk.push((
            "k_gcylf",
            k::cylinder_side(lay.ks_cyl, lay.ep_cyl, nm.approx(), false, lay.fine_normals),
        ));
        objk.push((
            "k_gcylb",
            k::cylinder_side(lay.ks_cyl, lay.ep_cyl, nm.approx(), true, lay.fine_normals),
        ));
    }
    if has(ChipType::GlassCone) {
        objk.push((
            "k_gconef",
            k::cone_side(lay.ks_cone, lay.ep_cone, nm.approx(), false),
        ));
        objk.push((
            "k_gconeb",
            k::cone_side(lay.ks_cone, lay.ep_cone, nm.approx(), true),
        ));
    }
    if has(ChipType::GlassCylinder) || has(ChipType::GlassCone) {
        objk.push((
            "k_gdisc",
            k::planar_two_sided(Inside::Disc, lay.kt_disc, nm.approx()),
        ));
    }
    if has(ChipType::GlassSmoothTriangle) {
        objk.push((
            "k_gtris",
            k::smooth_triangle_two_sided(lay.kt_tri, nm.approx()),
        ));
    }
    if has(ChipType::GlassBox) {
        objk.push(("k_gbox", k::aabox_two_sided(nm.approx())));
    }
    if has(ChipType::GlassPolygon) {
        objk.push(("k_gpolyh", k::polygon_head_two_sided(nm.approx())));
        if !has(ChipType::Polygon) {
            objk.push(("k_polye", k::polygon_edge()));
        }
        objk.push(("k_gpolyt", k::polygon_tail_two_sided()));
    }

    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(
        w,
        "; MorphoSys BSP ray tracer, generated by firmware::tracer for {}",
        scene.source
    );
    let _ = writeln!(
        w,
        "; {}x{}, {} ways ({}x{} tiles), depth {}, {} datapath, scene format Q{}.{}, {} normals",
        opt.width,
        opt.height,
        opt.ways,
        tw,
        th,
        opt.depth,
        opt.datapath,
        opt.datapath.bits() - 1 - lay.frac,
        lay.frac,
        if lay.fine_normals { "fine" } else { "coarse" }
    );
    let _ = writeln!(
        w,
        "; {} traversal, BSP {} split to depth {}, at most {} objects per leaf{}",
        opt.traversal,
        format!("{:?}", opt.bsp.rule).to_lowercase(),
        opt.bsp.max_depth,
        opt.bsp.max_leaf,
        if opt.traversal == Traversal::Packet {
            format!(", collapse {}", opt.collapse)
        } else {
            format!(", {} nodes", opt.layout)
        }
    );
    let _ = writeln!(w, "        .datapath {}", opt.datapath.bits());
    let _ = writeln!(
        w,
        "; FB image ({} words) at 0x{:x}, tile list at 0x{:x}: loaded by the host.",
        lay.fb.len(),
        mem::FB_IMAGE,
        mem::TILE_LIST
    );
    let _ = writeln!(w, "CTXBASE = 0x{:x}", mem::CTX_BASE);
    let _ = writeln!(w, "FBIMG = 0x{:x}", mem::FB_IMAGE);
    let _ = writeln!(w, "FBWORDS = {}", lay.fb.len());
    let _ = writeln!(w, "TILELIST = 0x{:x}", mem::TILE_LIST);
    let _ = writeln!(w, "FB_EYE = {}", lay.eye);
    let _ = writeln!(w, "FB_POST = {}", lay.post);
    let _ = writeln!(w, "ROOT = {}", lay.root);
    let _ = writeln!(w, "MAILBOX = {}", lay.mailbox);
    let _ = writeln!(w, "NOBJ = {}", lay.objects);
    let _ = writeln!(w);
    // ---- data ----
    let _ = writeln!(
        w,
        "        .data\nPASS:   .word 0\nMODE:   .word 0\nSAVE_LR: .word 0\nAWAKE:  .word 0, 0\nNEG:    .word 0, 0, 0, 0, 0, 0\n\
T_START: .word 0\nT_END:  .word 0\nTESTS:  .word 0\nPASSES: .word 0\nTL_PTR: .word 0\nTL_CNT: .word 0\nTL_BANK: .word 0\nCUR_OUT: .word 0\n\
NSTACK: .space 256\n"
    );
    if packet {
        let _ = writeln!(
            w,
            "NK:     .word 0, 0, 0\nNF:     .word 0, 0, 0\nNS:     .word 0, 0, 0\nCUR_BLK: .word 0\nROOTBOX = {}",
            lay.root_box
        );
        if let Some(st) = &lay.stream {
            let _ = writeln!(
                w,
                "SPLIT = {}\nSBANK = 0x{:x}",
                st.split_slot,
                super::layout::STREAM_BANK
            );
        }
    } else if let Some(st) = &lay.stream {
        let _ = writeln!(
            w,
            "UPTR:   .word 0\nUSTK:   .space 160\nCUR_BLK: .word 0\nSPLIT = {}\nSBANK = 0x{:x}",
            st.split_slot,
            super::layout::STREAM_BANK
        );
    }

    // ---- text ----
    let _ = writeln!(w, "        .text");
    let sb = |w: &mut String, n: &str, fb: String| {
        let _ = writeln!(
            w,
            "        li r1, {}\n        li r2, {fb}\n        sbcb r1, r2, {}",
            kaddr(n),
            klen(n)
        );
    };
    let _ = writeln!(
        w,
        "_start: li r1, FBIMG\n        li r2, 0\n        li r3, FBWORDS\n        ldfb r1, r2, r3\n        dwait\n\
        li r1, CTXBASE\n        li r2, 0\n        li r3, (ctx_end - CTXBASE) / 4\n        ldctxt r1, r2, r3\n        dwait"
    );
    sb(w, "k_init", "0".into());
    let _ = writeln!(
        w,
        "        li r1, {}\n        cbcr r1, r0, 1",
        kaddr("k_rows")
    );
    cb(w, "k_strow");
    let _ = writeln!(
        w,
        "        li r1, {}\n        cbcc r1, r0, 1",
        kaddr("k_rows")
    );
    cb(w, "k_stcol");
    cb(w, "k_lanes");
    let _ = writeln!(
        w,
        "        rcany r1\n        rdcyc r1\n        sw r1, T_START(r0)\n        li r1, TILELIST\n        lw r2, 0(r1)\n        addi r1, r1, 4\n\
        sw r1, TL_PTR(r0)\n        sw r2, TL_CNT(r0)"
    );
    let _ = writeln!(
        w,
        "tile:   lw r2, TL_CNT(r0)\n        beqz r2, finish\n        lw r1, TL_PTR(r0)\n        lw r3, 0(r1)\n        lw r4, 4(r1)\n        lw r5, 8(r1)\n\
        sw r5, CUR_OUT(r0)\n        li r6, FB_EYE\n        sfb r3, 0(r6)\n        sfb r4, 1(r6)"
    );
    // Level 0.
    sb(w, "k_eye", "FB_EYE".into());
    let shade_level = |w: &mut String, level: u32| {
        let _ = writeln!(w, "        sw r0, MODE(r0)\n        jal trace");
        cb(w, "k_wake");
        sb(
            w,
            if level == 0 { "k_post0" } else { "k_post1" },
            "FB_POST".into(),
        );
        for (i, _) in lay.lights.iter().enumerate() {
            sb(w, "k_light", format!("{}", lay.lights[i]));
            let _ = writeln!(
                w,
                "        li r1, 1\n        sw r1, MODE(r0)\n        jal trace"
            );
            cb(w, "k_wake");
            sb(w, "k_shade", format!("{}", lay.shades[i]));
        }
    };
    // The ray tree, depth first: a level's shading, then its reflected
    // ray's subtree and, where the scene refracts, its refracted ray's
    // (skipped when no ray of the tile refracts there).
    fn tree(
        w: &mut String,
        level: u32,
        levels: u32,
        refract: bool,
        transmit: usize,
        skips: &mut u32,
        shade_level: &dyn Fn(&mut String, u32),
    ) {
        shade_level(w, level);
        if level + 1 >= levels {
            return;
        }
        if refract {
            let _ = writeln!(
                w,
                "        li r1, {}\n        li r2, {transmit}\n        sbcb r1, r2, {}",
                kaddr(&format!("k_tset{level}")),
                klen(&format!("k_tset{level}"))
            );
        }
        cb(w, &format!("k_refl{level}"));
        tree(w, level + 1, levels, refract, transmit, skips, shade_level);
        cb(w, &format!("k_pop{level}"));
        if refract {
            *skips += 1;
            let skip = format!("norefr{}", *skips);
            cb(w, &format!("k_refr{level}"));
            let _ = writeln!(w, "        rcany r1\n        beqz r1, {skip}");
            tree(w, level + 1, levels, refract, transmit, skips, shade_level);
            let _ = writeln!(w, "{skip}:");
            cb(w, "k_wake");
            cb(w, &format!("k_rpop{level}"));
        }
    }
    let mut skips = 0;
    tree(
        w,
        0,
        levels.max(1),
        lay.refract,
        lay.transmit,
        &mut skips,
        &shade_level,
    );
    // Output: four words per lane through the FB, then DMA to memory.
    let _ = writeln!(
        w,
        "        lw r5, TL_BANK(r0)\n        li r4, {}\n        beqz r5, outb0\n        li r4, {}\noutb0:  dwait",
        OUT_BANK[0], OUT_BANK[1]
    );
    for i in 0..4 {
        let n = format!("k_out{i}");
        let _ = writeln!(
            w,
            "        li r1, {}\n        cbcast r1, 1\n        wfb r4, {}",
            kaddr(&n),
            64 * i
        );
    }
    let _ = writeln!(
        w,
        "        lw r3, CUR_OUT(r0)\n        stfb r3, r4, 256\n        lw r5, TL_BANK(r0)\n        xori r5, r5, 1\n        sw r5, TL_BANK(r0)\n\
        lw r1, TL_PTR(r0)\n        addi r1, r1, 12\n        sw r1, TL_PTR(r0)\n        lw r2, TL_CNT(r0)\n        addi r2, r2, -1\n        sw r2, TL_CNT(r0)\n        j tile"
    );
    let _ = writeln!(
        w,
        "finish: dwait\n        rdcyc r1\n        sw r1, T_END(r0)\n        halt\n"
    );

    if packet {
        packet_trace(w, lay);
    } else {
        paper_trace(w, lay);
    }

    // ---- contexts ----
    let _ = writeln!(w, "        .ctx\n        .org CTXBASE");
    let mut kernels = Vec::new();
    let mut words = 0usize;
    // Row-mode group must be 8-aligned: put it first.
    let mut all: Vec<(String, K)> = Vec::new();
    let mut rows = None;
    for (n, kk) in ks {
        if n == "k_rows" {
            rows = Some(kk);
        } else {
            all.push((n.to_string(), kk));
        }
    }
    if let Some(r) = rows {
        all.insert(0, ("k_rows".into(), r));
    }
    all.extend(refl);
    for (n, kk) in objk {
        all.push((n.to_string(), kk));
    }
    for (n, kk) in &all {
        let _ = write!(w, "{}", kk.text(n));
        kernels.push((n.clone(), kk.len()));
        words += kk.len();
    }
    let _ = writeln!(w, "ctx_end:");
    if words > 8192 {
        return Err(format!(
            "the kernels need {words} context words; the context memory holds 8192"
        ));
    }
    Ok(Program {
        source: s,
        context_words: words,
        kernels,
    })
}

/// The paper's traversal (resident or streamed) and its object loops.
fn paper_trace(w: &mut String, lay: &Layout) {
    // ---- trace: one ray pass over the BSP ----
    let _ = writeln!(
        w,
        "; trace: the RCs hold o, d, tbest; MODE 0 closest hit, 1 any hit (shadow).\n\
trace:  sw r15, SAVE_LR(r0)\n        lw r1, PASSES(r0)\n        addi r1, r1, 1\n        sw r1, PASSES(r0)\n\
        lw r1, PASS(r0)\n        addi r1, r1, 1\n        li r2, 0x7fff\n        blt r1, r2, pass_ok\n        jal clear_mailbox\n        li r1, 1\npass_ok: sw r1, PASS(r0)"
    );
    for a in 0..3 {
        cb(w, &format!("k_sign{a}"));
        let _ = writeln!(w, "        rcfl r2\n        rcfh r3\n        sw r2, NEG+{}(r0)\n        sw r3, NEG+{}(r0)", 8 * a, 8 * a + 4);
    }
    let compact = lay.node_layout == NodeLayout::Compact;
    if lay.stream.is_none() {
        let _ = writeln!(
        w,
        "        jal awake\n        li r14, NSTACK\n        li r5, ROOT\n\
visit:  lw r11, AWAKE(r0)\n        lw r12, AWAKE+4(r0)\n        or r1, r11, r12\n        beqz r1, done\n\
        lfb r6, 0(r5)\n        blt r6, r0, leaf\n        andi r7, r6, 3\n        li r1, {cls0}\n        li r2, {cls1}\n\
        beqz r7, cls_go\n        li r1, {cls1}\n        li r2, {cls2}\n        slti r3, r7, 2\n        bnez r3, cls_go\n        li r1, {cls2}\n\
cls_go: addi r2, r5, 1\n        sbcb r1, r2, {len}\n        rcfl r1\n        rcfh r2\n        li r8, {clsr}\n        cbcast r8, 1\n        rcfl r3\n        rcfh r4\n\
        and r1, r1, r11\n        and r2, r2, r12\n        and r3, r3, r11\n        and r4, r4, r12\n\
        or r9, r3, r4\n        bnez r9, hasr\n        or r9, r1, r2\n        beqz r9, pop\n        lfb r5, 2(r5)\n        j visit\n\
hasr:   or r9, r1, r2\n        bnez r9, both\n        lfb r5, 3(r5)\n        j visit\n\
both:   bne r1, r3, incoh\n        bne r2, r4, incoh\n        slli r9, r7, 3\n        lw r10, NEG(r9)\n        lw r13, NEG+4(r9)\n\
        and r10, r10, r11\n        and r13, r13, r12\n        or r9, r10, r13\n        beqz r9, posdir\n        bne r10, r11, incoh\n        bne r13, r12, incoh\n\
        lfb r9, 2(r5)\n        sw r9, 0(r14)\n        addi r14, r14, 4\n        lfb r5, 3(r5)\n        j visit\n\
posdir: lfb r9, 3(r5)\n        sw r9, 0(r14)\n        addi r14, r14, 4\n        lfb r5, 2(r5)\n        j visit\n\
incoh:  {incoh_lists}jal test_objects\n        j pop\n\
leaf:   {leaf_lists}jal test_objects\n        lw r1, MODE(r0)\n        bnez r1, leaf_any\n        li r1, {leafc}\n        addi r2, r5, {bounds}\n        sbcb r1, r2, {leafclen}\n        j leaf_aw\n\
leaf_any: li r1, {leafa}\n        cbcast r1, {leafalen}\nleaf_aw: jal awake\n\
pop:    li r9, NSTACK\n        beq r14, r9, done\n        addi r14, r14, -4\n        lw r5, 0(r14)\n        j visit\n\
done:   lw r15, SAVE_LR(r0)\n        ret\n",
        cls0 = kaddr("k_cls0"),
        cls1 = kaddr("k_cls1"),
        cls2 = kaddr("k_cls2"),
        len = klen("k_cls0"),
        clsr = kaddr("k_clsr"),
        leafc = kaddr("k_leafc"),
        leafclen = klen("k_leafc"),
        leafa = kaddr("k_leafa"),
        leafalen = klen("k_leafa"),
        // Compact nodes: r6 = the node's index lists, after a head whose
        // size depends on the kind of node; the leaf's bounds follow its
        // flags.
        incoh_lists = if compact {
            format!("addi r6, r5, {}\n        ", super::layout::COMPACT_INNER_HEAD)
        } else {
            String::new()
        },
        leaf_lists = if compact {
            format!("addi r6, r5, {}\n        ", super::layout::COMPACT_LEAF_HEAD)
        } else {
            String::new()
        },
        bounds = if compact { 1 } else { 4 },
    );
    } else {
        stream_trace(w, lay);
    }
    // awake: AWAKE = ~sleep (the lanes of the tile are the only ones awake
    // at a pass's start).
    let _ = writeln!(
        w,
        "awake:  rcsl r1\n        rcsh r2\n        nor r1, r1, r0\n        nor r2, r2, r0\n        sw r1, AWAKE(r0)\n        sw r2, AWAKE+4(r0)\n        ret\n"
    );
    if lay.stream.is_none() {
        let _ = writeln!(
        w,
        "clear_mailbox:\n        li r2, MAILBOX\n        li r3, NOBJ\n        beqz r3, cm_done\ncm_loop: sfb r0, 0(r2)\n        addi r2, r2, 1\n        addi r3, r3, -1\n        bnez r3, cm_loop\ncm_done: ret\n"
    );

        // ---- test_objects: Fig. 6 for every type present ----
        let _ = writeln!(
            w,
            "; test_objects: r5 = node (compact: r6 = its lists); every object of the node's {} not yet\n\
; tested in this pass (mailbox) is broadcast with its type's kernel.\n\
test_objects:\n        lw r13, PASS(r0)",
            match lay.node_layout {
                NodeLayout::Fig5 => "bit vectors",
                NodeLayout::Compact => "index lists",
            }
        );
        for t in &lay.types {
            let n = t.ty.name();
            if compact {
                // Per type: the count, then that many slot indices k;
                // mailbox = MB + k, record = first + k size.
                let _ = writeln!(
                    w,
                    "        lfb r9, 0(r6)\n        addi r6, r6, 1\n        beqz r9, {n}_wend\n        li r8, {mb}\n        li r10, {size}\n        li r12, {first}\n\
{n}_bit:\n        lfb r1, 0(r6)\n        addi r6, r6, 1\n        add r2, r8, r1\n        lfb r3, 0(r2)\n        beq r3, r13, {n}_next\n        sfb r13, 0(r2)\n\
        mul r7, r1, r10\n        add r7, r7, r12\n        lw r1, TESTS(r0)\n        addi r1, r1, 1\n        sw r1, TESTS(r0)",
                    mb = t.mailbox,
                    size = t.size,
                    first = t.first
                );
            } else {
                let _ = writeln!(
            w,
            "        addi r6, r5, {bv}\n        li r7, {first}\n        li r8, {mb}\n        li r9, {nw}\n\
{n}_word:\n        lfb r10, 0(r6)\n        addi r6, r6, 1\n        slli r10, r10, 16\n        li r4, 16\n\
{n}_bit:\n        beqz r10, {n}_skip\n        bge r10, r0, {n}_next\n        lfb r1, 0(r8)\n        beq r1, r13, {n}_next\n        sfb r13, 0(r8)\n\
        lw r1, TESTS(r0)\n        addi r1, r1, 1\n        sw r1, TESTS(r0)",
            bv = t.bv_offset,
            first = t.first,
            mb = t.mailbox,
            nw = t.bv_words
        );
            }
            broadcast_object(w, t.ty, n, lay.fine_normals);
            if compact {
                let _ = writeln!(
                    w,
                    "{n}_next:\n        addi r9, r9, -1\n        bnez r9, {n}_bit\n{n}_wend:"
                );
                continue;
            }
            let _ = writeln!(
            w,
            "{n}_next:\n        addi r7, r7, {size}\n        addi r8, r8, 1\n        slli r10, r10, 1\n        addi r4, r4, -1\n        bnez r4, {n}_bit\n        j {n}_wend\n\
{n}_skip:\n        li r1, {size}\n        mul r1, r1, r4\n        add r7, r7, r1\n        add r8, r8, r4\n\
{n}_wend:\n        addi r9, r9, -1\n        bnez r9, {n}_word",
            size = t.size
        );
        }
        let _ = writeln!(w, "        ret\n");
    }
}

/// Popcount of `x` into `x` (SWAR), clobbering `t1`, `t2`.
fn popcount(w: &mut String, x: &str, t1: &str, t2: &str) {
    let _ = writeln!(
        w,
        "        srli {t1}, {x}, 1\n        li {t2}, 0x55555555\n        and {t1}, {t1}, {t2}\n        sub {x}, {x}, {t1}\n\
        li {t2}, 0x33333333\n        and {t1}, {x}, {t2}\n        srli {x}, {x}, 2\n        and {x}, {x}, {t2}\n        add {x}, {x}, {t1}\n\
        srli {t1}, {x}, 4\n        add {x}, {x}, {t1}\n        li {t2}, 0x0f0f0f0f\n        and {x}, {x}, {t2}\n\
        li {t2}, 0x01010101\n        mul {x}, {x}, {t2}\n        srli {x}, {x}, 24"
    );
}

/// The masked packet traversal ([`Traversal::Packet`]), resident or
/// streamed. Per pass: `k_pinit` (every awake ray takes part; its interval
/// starts as `[0, tbest]` clipped to the root cell), then per axis the
/// order of the children, the one the majority of the awake rays meets
/// first (`NK`: that axis's node kernel, `NF`/`NS`: offsets of the first
/// and second child in a node record). At an inner node the node kernel
/// splits every awake ray's interval and `rcst` says which children some
/// awake ray reaches: none (pop), the second only (its intervals become
/// current), some the first (the others sleep; the second is pushed) or
/// all the first (one more `rcany` asks whether to push the second). A
/// popped node wakes every RC; the rays not alive, or whose interval for
/// it is empty or lies beyond their hit, sleep again, and a node no ray
/// needs is skipped. TinyRISC registers: r5 node, r13 object tests of the
/// pass, r14 node stack.
fn packet_trace(w: &mut String, lay: &Layout) {
    let streamed = lay.stream.is_some();
    // Child offsets in a node record: FB words (resident) or bytes.
    let (left, right) = if streamed { (16, 20) } else { (4, 5) };
    let _ = writeln!(
        w,
        "; trace (packet traversal): the RCs hold o, d, tbest; MODE 0 closest hit, 1 any hit (shadow).\n\
trace:  sw r15, SAVE_LR(r0)\n        lw r1, PASSES(r0)\n        addi r1, r1, 1\n        sw r1, PASSES(r0)\n\
        lw r1, PASS(r0)\n        addi r1, r1, 1\n        sw r1, PASS(r0)\n        li r13, 0"
    );
    if lay.root_leaf {
        // The whole tree is one leaf: its objects are tested by the awake
        // rays, nothing to walk.
        // (`k_sign0` runs only to mark the pass's start for the
        // simulator's count of the rays traced: its RCs are the pass's.)
        let _ = writeln!(
            w,
            "        li r1, {sign}\n        cbcast r1, 1\n        li r14, NSTACK\n        li r5, ROOT\n        rcsl r4\n        rcsh r10\n        nor r4, r4, r0\n        nor r10, r10, r0\n\
        or r1, r4, r10\n        beqz r1, pdone\n        lw r11, PASS(r0)\n        j leaf_go",
            sign = kaddr("k_sign0")
        );
    }
    let _ = writeln!(
        w,
        "        li r1, {pinit}\n        li r2, ROOTBOX\n        sbcb r1, r2, {pinitlen}",
        pinit = kaddr("k_pinit"),
        pinitlen = klen("k_pinit"),
    );
    for a in 0..3 {
        let _ = writeln!(
            w,
            "        li r1, {sign}\n        cbcast r1, 1\n        rcst r3",
            sign = kaddr(&format!("k_sign{a}"))
        );
        if a == 0 {
            let _ = writeln!(w, "        li r4, 2\n        beq r3, r4, pdone");
        }
        let _ = writeln!(
            w,
            "        li r8, 0\n        beqz r3, ord{a}\n        li r8, 1\n        li r4, 3\n        beq r3, r4, ord{a}\n        jal majority\n\
ord{a}:   li r1, {nb}\n        li r2, {left}\n        li r3, {right}\n        beqz r8, ordb{a}\n        li r1, {na}\n        li r2, {right}\n        li r3, {left}\n\
ordb{a}:  sw r1, NK+{o}(r0)\n        sw r2, NF+{o}(r0)\n        sw r3, NS+{o}(r0)",
            nb = kaddr(&format!("k_pn{a}b")),
            na = kaddr(&format!("k_pn{a}a")),
            o = 4 * a,
        );
    }
    // The node loop. `dispatch_full`: r5 = a node, r6 = its flags; an inner
    // node's kernel is issued (its split streamed), then `vnode` fetches the
    // children, the first child's flags, kernel (and split) while it runs,
    // so that `dispatch_pre` issues the first child's kernel at once.
    let ldn = if streamed { "lw" } else { "lfb" };
    let nlen = klen("k_pn0b");
    let dispatch_full = |w: &mut String| {
        let split = if streamed {
            "        lw r2, 8(r5)\n        sfb r2, SPLIT(r0)\n        li r2, SPLIT"
        } else {
            "        addi r2, r5, 2"
        };
        let _ = writeln!(
            w,
            "        blt r6, r0, leaf\n        slli r7, r6, 2\n        lw r1, NK(r7)\n{split}\n        sbcb r1, r2, {nlen}\n        j vnode"
        );
    };
    let dispatch_pre = |w: &mut String| {
        let split = if streamed {
            "        sfb r15, SPLIT(r0)\n        li r2, SPLIT"
        } else {
            "        addi r2, r5, 2"
        };
        let _ = writeln!(
            w,
            "        mv r5, r9\n        blt r6, r0, leaf\n        mv r7, r3\n{split}\n        sbcb r11, r2, {nlen}\n        j vnode"
        );
    };
    // Push the second child (r10) with every awake ray's interval for it
    // (the push kernel streams the node's slot address, r12).
    let push = |w: &mut String| {
        if streamed {
            let _ = writeln!(
                w,
                "        sfb r12, SPLIT+1(r0)\n        li r2, SPLIT+1\n        li r1, {push}\n        sbcb r1, r2, {pushlen}",
                push = kaddr("k_ppush"),
                pushlen = klen("k_ppush")
            );
        } else {
            let _ = writeln!(
                w,
                "        li r1, {push}\n        sbcb r1, r12, {pushlen}",
                push = kaddr("k_ppush"),
                pushlen = klen("k_ppush")
            );
        }
        let _ = writeln!(w, "        sw r10, 0(r14)\n        addi r14, r14, 4");
    };
    let _ = writeln!(
        w,
        "        li r14, NSTACK\n        li r5, ROOT\n        {ldn} r6, 0(r5)"
    );
    dispatch_full(w);
    let _ = writeln!(
        w,
        "vnode:  lw r8, NF(r7)\n        add r8, r8, r5\n        {ldn} r9, 0(r8)\n        lw r10, NS(r7)\n        add r10, r10, r5\n        {ldn} r10, 0(r10)\n\
        {ldn} r6, 0(r9)\n        andi r3, r6, 3\n        slli r3, r3, 2\n        lw r11, NK(r3)\n{pre}        {slot}\n\
        rcst r4\n        addi r1, r4, -3\n        beqz r1, vall\n        addi r1, r4, -1\n        beqz r1, vboth\n        bnez r4, pop\n\
        li r1, {take}\n        cbcast r1, {takelen}\n        mv r5, r10\n        {ldn} r6, 0(r5)",
        pre = if streamed { "        lw r15, 8(r9)\n" } else { "" },
        slot = if streamed { "lw r12, 12(r5)" } else { "addi r12, r5, 3" },
        take = kaddr("k_ptake"),
        takelen = klen("k_ptake"),
    );
    dispatch_full(w);
    let _ = writeln!(w, "vboth:");
    push(w);
    let _ = writeln!(
        w,
        "        li r1, {sl}\n        cbcast r1, 1",
        sl = kaddr("k_psl")
    );
    dispatch_pre(w);
    let _ = writeln!(
        w,
        "vall:   li r1, {second}\n        cbcast r1, 1\n        rcany r4\n        beqz r4, vfirst",
        second = kaddr("k_p2nd")
    );
    push(w);
    let _ = writeln!(w, "vfirst:");
    dispatch_pre(w);
    // The leaf: every object not yet tested by every awake ray in this
    // pass, by type. Mailboxes (main memory, 16 bytes per object in more
    // than one leaf): the pass that last tested the object and which rays
    // did; r4, r10 = the awake mask (read only for leaves with such
    // objects), r11 = PASS.
    let awake = "        rcsl r4\n        rcsh r10\n        nor r4, r4, r0\n        nor r10, r10, r0\n        lw r11, PASS(r0)";
    // The mailbox check of the object whose mailbox address is in r8: on
    // to `{n}_next` when every awake ray has tested it in this pass, else
    // the mailbox is updated and the object goes to `{n}_go`.
    let check = |w: &mut String, n: &str| {
        let _ = writeln!(
            w,
            "        lw r1, 0(r8)\n        bne r1, r11, {n}_fresh\n        lw r2, 4(r8)\n        lw r3, 8(r8)\n        \
or r1, r2, r4\n        bne r1, r2, {n}_upd\n        or r1, r3, r10\n        beq r1, r3, {n}_next\n\
{n}_upd: or r2, r2, r4\n        or r3, r3, r10\n        sw r2, 4(r8)\n        sw r3, 8(r8)\n        j {n}_go\n\
{n}_fresh: sw r11, 0(r8)\n        sw r4, 4(r8)\n        sw r10, 8(r8)\n{n}_go:  addi r13, r13, 1"
        );
    };
    let _ = writeln!(
        w,
        "; The leaf (r5). An object in more than one leaf has a mailbox: the pass that last tested it and\n\
; which rays did; it is broadcast unless every awake ray has tested it in this pass."
    );
    if streamed {
        // The block's DMA starts at once: the array reads bank 1 only in a
        // leaf's object tests, and a pop or a node decision (which waits
        // for the array) lies between two leaves; the mailbox scan runs
        // while it moves, and `dwait` only comes before the first object.
        // A leaf's further pieces wait for the array to finish the last.
        let _ = writeln!(
            w,
            "leaf:   lw r1, 56(r5)\n        beqz r1, lf_done\n        lw r1, 60(r5)\n        lw r2, 24(r5)\n        or r1, r1, r2\n        beqz r1, pt_piece\n{awake}\n\
leaf_go:\n\
pt_piece: lw r1, 16(r5)\n        lw r3, 20(r5)\n        lw r2, CUR_BLK(r0)\n        beq r1, r2, pt_scan0\n\
        li r2, SBANK\n        ldfb r1, r2, r3\n        sw r1, CUR_BLK(r0)\n\
pt_scan0: lw r6, 8(r5)\n        lw r9, 56(r5)\n\
pt_scan: lw r8, 0(r6)\n        addi r6, r6, 4\n        beqz r8, pt_load\n        lw r1, 0(r8)\n        bne r1, r11, pt_load\n\
        lw r2, 4(r8)\n        nor r2, r2, r0\n        and r2, r2, r4\n        bnez r2, pt_load\n\
        lw r3, 8(r8)\n        nor r3, r3, r0\n        and r3, r3, r10\n        bnez r3, pt_load\n\
        addi r9, r9, -1\n        bnez r9, pt_scan\n        j pt_nextp\n\
pt_load: dwait\n        li r7, SBANK\n        lw r6, 8(r5)"
        );
        for (j, t) in lay.types.iter().enumerate() {
            let n = format!("p{}", t.ty.name());
            let _ = writeln!(
                w,
                "        lw r9, {cnt}(r5)\n        beqz r9, {n}_end\n{n}_loop:\n        lw r8, 0(r6)\n        addi r6, r6, 4\n        beqz r8, {n}_go",
                cnt = 28 + 4 * j
            );
            check(w, &n);
            broadcast_object(w, t.ty, &n, lay.fine_normals);
            let _ = writeln!(
                w,
                "{n}_next:\n        addi r7, r7, {size}\n        addi r9, r9, -1\n        bnez r9, {n}_loop\n{n}_end:",
                size = t.size
            );
        }
        let _ = writeln!(
            w,
            "pt_nextp: lw r5, 24(r5)\n        beqz r5, lf_done\n        rcany r2\n        j pt_piece"
        );
    } else {
        let _ = writeln!(
            w,
            "leaf:   lfb r1, 2(r5)\n        beqz r1, lf_done\n        lfb r1, 3(r5)\n        beqz r1, leaf_go\n{awake}\n\
leaf_go: li r12, MAILBOX\n        addi r6, r5, {head}",
            head = super::layout::PK_LEAF_HEAD
        );
        for t in &lay.types {
            let n = format!("p{}", t.ty.name());
            let _ = writeln!(
                w,
                "        lfb r9, 0(r6)\n        addi r6, r6, 1\n        beqz r9, {n}_end\n\
{n}_loop:\n        lfb r7, 0(r6)\n        lfb r8, 1(r6)\n        addi r6, r6, 2\n        blt r8, r0, {n}_go\n        slli r8, r8, 4\n        add r8, r8, r12"
            );
            check(w, &n);
            broadcast_object(w, t.ty, &n, lay.fine_normals);
            let _ = writeln!(
                w,
                "{n}_next:\n        addi r9, r9, -1\n        bnez r9, {n}_loop\n{n}_end:"
            );
        }
    }
    let _ = writeln!(
        w,
        "lf_done: lw r1, MODE(r0)\n        beqz r1, pop\n        li r1, {leafa}\n        cbcast r1, {leafalen}\n\
pop:    li r9, NSTACK\n        beq r14, r9, pdone\n        addi r14, r14, -4\n        lw r5, 0(r14)\n        li r1, {pop}\n{pop_at}        sbcb r1, r2, {poplen}\n\
        {ldn} r6, 0(r5)\n        rcany r4\n        beqz r4, pop",
        leafa = kaddr("k_pleafa"),
        leafalen = klen("k_pleafa"),
        pop = kaddr("k_ppop"),
        poplen = klen("k_ppop"),
        pop_at = if streamed {
            "        lw r2, 4(r5)\n        sfb r2, SPLIT+2(r0)\n        li r2, SPLIT+2\n"
        } else {
            "        addi r2, r5, 1\n"
        },
    );
    dispatch_full(w);
    let _ = writeln!(
        w,
        "pdone:  lw r1, TESTS(r0)\n        add r1, r1, r13\n        sw r1, TESTS(r0)\n        lw r15, SAVE_LR(r0)\n        ret\n"
    );
    // majority: r8 = 1 when more awake rays have F (a negative direction
    // component) than not.
    let _ = writeln!(
        w,
        "majority:\n        rcfl r1\n        rcfh r2\n        rcsl r3\n        rcsh r4\n        nor r3, r3, r0\n        nor r4, r4, r0\n\
        and r5, r1, r3\n        and r6, r2, r4\n        nor r1, r1, r0\n        nor r2, r2, r0\n        and r1, r1, r3\n        and r2, r2, r4"
    );
    for x in ["r5", "r6", "r1", "r2"] {
        popcount(w, x, "r9", "r10");
    }
    let _ = writeln!(
        w,
        "        add r5, r5, r6\n        add r1, r1, r2\n        slt r8, r1, r5\n        ret\n"
    );
}

/// The streamed traversal (scenes that do not fit FB set 0): nodes, leaf
/// lists and mailboxes in main memory (read by TinyRISC), each leaf's block
/// (bounds and records) moved into FB bank 1 by DMA before its objects are
/// broadcast; the split value of a node is written into bank 0 for the
/// classification kernel. Incoherent nodes are not resolved by testing the
/// whole subtree (thousands of objects) but by visiting both children in a
/// fixed order; inside such an unordered subtree the closest-hit pass does
/// not put rays to sleep at a leaf (a nearer hit may lie in a cell not
/// visited yet); the shadow pass does (any hit will do).
fn stream_trace(w: &mut String, lay: &Layout) {
    let _ = writeln!(
        w,
        "        jal awake\n        li r9, USTK\n        sw r9, UPTR(r0)\n        li r1, {uzero}\n        cbcast r1, {uzlen}\n        li r14, NSTACK\n        li r5, ROOT\n\
visit:  lw r11, AWAKE(r0)\n        lw r12, AWAKE+4(r0)\n        or r1, r11, r12\n        beqz r1, done\n\
        lw r6, 0(r5)\n        blt r6, r0, leaf\n        lw r1, 4(r5)\n        sfb r1, SPLIT(r0)\n        andi r7, r6, 3\n        li r1, {cls0}\n\
        beqz r7, cls_go\n        li r1, {cls1}\n        slti r3, r7, 2\n        bnez r3, cls_go\n        li r1, {cls2}\n\
cls_go: li r2, SPLIT\n        sbcb r1, r2, {len}\n        rcfl r1\n        rcfh r2\n        li r8, {clsr}\n        cbcast r8, 1\n        rcfl r3\n        rcfh r4\n\
        and r1, r1, r11\n        and r2, r2, r12\n        and r3, r3, r11\n        and r4, r4, r12\n\
        or r9, r3, r4\n        bnez r9, hasr\n        or r9, r1, r2\n        beqz r9, pop\n        lw r5, 8(r5)\n        j visit\n\
hasr:   or r9, r1, r2\n        bnez r9, both\n        lw r5, 12(r5)\n        j visit\n\
both:   slli r9, r7, 3\n        lw r10, NEG(r9)\n        lw r13, NEG+4(r9)\n\
        and r10, r10, r11\n        and r13, r13, r12\n        or r9, r10, r13\n        beqz r9, posdir\n        bne r10, r11, mixed\n        bne r13, r12, mixed\n\
        lw r9, 8(r5)\n        sw r9, 0(r14)\n        addi r14, r14, 4\n        lw r5, 12(r5)\n        j visit\n\
mixed:  lw r9, UPTR(r0)\n        sw r14, 0(r9)\n        sw r7, 4(r9)\n        addi r9, r9, 8\n        sw r9, UPTR(r0)\n\
        li r1, {uin0}\n        beqz r7, mx_go\n        li r1, {uin1}\n        slti r3, r7, 2\n        bnez r3, mx_go\n        li r1, {uin2}\n\
mx_go:  cbcast r1, {ulen}\n\
posdir: lw r9, 12(r5)\n        sw r9, 0(r14)\n        addi r14, r14, 4\n        lw r5, 8(r5)\n        j visit\n\
leaf:   lw r1, 20(r5)\n        beqz r1, pop\n        jal test_objects\n        beqz r4, pop\n        lw r1, MODE(r0)\n        bnez r1, leaf_any\n\
        li r1, {leafc}\n        sbcb r1, r4, {leafclen}\n        j leaf_aw\n\
leaf_any: li r1, {leafa}\n        cbcast r1, {leafalen}\nleaf_aw: jal awake\n\
pop:    lw r9, UPTR(r0)\n        li r8, USTK\n        beq r9, r8, pop2\n        lw r10, -8(r9)\n        bne r10, r14, pop2\n\
        lw r7, -4(r9)\n        addi r9, r9, -8\n        sw r9, UPTR(r0)\n\
        li r1, {uout0}\n        beqz r7, px_go\n        li r1, {uout1}\n        slti r3, r7, 2\n        bnez r3, px_go\n        li r1, {uout2}\n\
px_go:  cbcast r1, {ulen}\n\
pop2:   li r9, NSTACK\n        beq r14, r9, done\n        addi r14, r14, -4\n        lw r5, 0(r14)\n        j visit\n\
done:   lw r15, SAVE_LR(r0)\n        ret\n",
        uzero = kaddr("k_uzero"),
        uzlen = klen("k_uzero"),
        uin0 = kaddr("k_uin0"),
        uin1 = kaddr("k_uin1"),
        uin2 = kaddr("k_uin2"),
        uout0 = kaddr("k_uout0"),
        uout1 = kaddr("k_uout1"),
        uout2 = kaddr("k_uout2"),
        ulen = klen("k_uin0"),
        cls0 = kaddr("k_cls0"),
        cls1 = kaddr("k_cls1"),
        cls2 = kaddr("k_cls2"),
        len = klen("k_cls0"),
        clsr = kaddr("k_clsr"),
        leafc = kaddr("k_leafcu"),
        leafclen = klen("k_leafcu"),
        leafa = kaddr("k_leafa"),
        leafalen = klen("k_leafa"),
    );
    let _ = writeln!(
        w,
        "clear_mailbox:\n        li r2, MAILBOX\n        li r3, NOBJ\n        beqz r3, cm_done\ncm_loop: sh r0, 0(r2)\n        addi r2, r2, 2\n        addi r3, r3, -1\n        bnez r3, cm_loop\ncm_done: ret\n"
    );
    // test_objects: r5 = leaf; its block is moved into bank 1 unless it is
    // there already (the last block loaded), once the array is idle.
    let _ = writeln!(
        w,
        "; test_objects (streamed): r5 = leaf node in main memory.\n\
test_objects:\n        lw r9, 56(r5)\n        lw r6, 24(r5)\n        lw r13, PASS(r0)\n\
to_scan: lw r2, 0(r6)\n        addi r6, r6, 4\n        lhu r1, 0(r2)\n        bne r1, r13, to_need\n        addi r9, r9, -1\n        bnez r9, to_scan\n        li r4, 0\n        ret\n\
to_need: li r4, SBANK\n        lw r1, 16(r5)\n        lw r3, 20(r5)\n        lw r2, CUR_BLK(r0)\n        beq r1, r2, to_have\n\
        rcany r2\n        li r2, SBANK\n        ldfb r1, r2, r3\n        dwait\n        sw r1, CUR_BLK(r0)\n\
to_have: lw r6, 24(r5)\n        lw r13, PASS(r0)\n        li r7, SBANK + {head}",
        head = super::layout::BLOCK_HEAD
    );
    for (j, t) in lay.types.iter().enumerate() {
        let n = format!("s{}", t.ty.name());
        let _ = writeln!(
            w,
            "        lw r9, {cnt}(r5)\n        beqz r9, {n}_end\n\
{n}_loop:\n        lw r2, 0(r6)\n        addi r6, r6, 4\n        lhu r1, 0(r2)\n        beq r1, r13, {n}_next\n        sh r13, 0(r2)\n\
        lw r1, TESTS(r0)\n        addi r1, r1, 1\n        sw r1, TESTS(r0)",
            cnt = 28 + 4 * j
        );
        broadcast_object(w, t.ty, n.as_str(), lay.fine_normals);
        let _ = writeln!(
            w,
            "{n}_next:\n        addi r7, r7, {size}\n        addi r9, r9, -1\n        bnez r9, {n}_loop\n{n}_end:",
            size = t.size
        );
    }
    let _ = writeln!(w, "        ret\n");
}

/// TinyRISC code that broadcasts the test of one object of type `ty`,
/// whose FB record starts at the address in `r7`, by the kernels of its
/// type (labels prefixed `n`; clobbers r1..r3). Shared by the resident
/// Fig. 6 / compact loops and the streamed leaf loop.
fn broadcast_object(w: &mut String, ty: ChipType, n: &str, fine_normals: bool) {
    use super::layout::{
        cyl_body_words, CONE_BODY_WORDS, PLANAR_WORDS, POLY_EDGE_WORDS, POLY_HEAD_WORDS,
    };
    let one = |w: &mut String, k: &str| {
        let _ = writeln!(
            w,
            "        li r1, {}\n        sbcb r1, r7, {}",
            kaddr(k),
            klen(k)
        );
    };
    // Body, then the two end caps as disc records where the caps word is set.
    let capped = |w: &mut String, k: &str, body: usize| {
        let _ = writeln!(
            w,
            "        li r1, {}\n        addi r2, r7, 1\n        sbcb r1, r2, {}\n        lfb r3, 0(r7)\n        beqz r3, {n}_nocap",
            kaddr(k),
            klen(k)
        );
        for c in 0..2 {
            let _ = writeln!(
                w,
                "        li r1, {}\n        addi r2, r7, {}\n        sbcb r1, r2, {}",
                kaddr("k_disc"),
                1 + body + c * PLANAR_WORDS,
                klen("k_disc")
            );
        }
        let _ = writeln!(w, "{n}_nocap:");
    };
    match ty {
        ChipType::Sphere => one(w, "k_sphere"),
        ChipType::GlassSphere => one(w, "k_gsphere"),
        ChipType::Rectangle => one(w, "k_rect"),
        ChipType::Triangle => one(w, "k_tri"),
        ChipType::SmoothTriangle => one(w, "k_tris"),
        ChipType::Box => one(w, "k_box"),
        ChipType::Cylinder => capped(w, "k_cyl", cyl_body_words(fine_normals)),
        ChipType::Cone => capped(w, "k_cone", CONE_BODY_WORDS),
        ChipType::GlassRectangle => one(w, "k_grect"),
        ChipType::GlassTriangle => one(w, "k_gtri"),
        ChipType::GlassBox => one(w, "k_gbox"),
        ChipType::GlassSmoothTriangle => one(w, "k_gtris"),
        ChipType::GlassCylinder | ChipType::GlassCone => {
            // Both bodies, then the caps as two-sided discs where set.
            let (front, back, body) = if ty == ChipType::GlassCylinder {
                ("k_gcylf", "k_gcylb", cyl_body_words(fine_normals))
            } else {
                ("k_gconef", "k_gconeb", CONE_BODY_WORDS)
            };
            let _ = writeln!(
                w,
                "        li r1, {}\n        addi r2, r7, 1\n        sbcb r1, r2, {}\n        li r1, {}\n        addi r2, r7, {}\n        sbcb r1, r2, {}\n        lfb r3, 0(r7)\n        beqz r3, {n}_nocap",
                kaddr(front),
                klen(front),
                kaddr(back),
                1 + body,
                klen(back)
            );
            for c in 0..2 {
                let _ = writeln!(
                    w,
                    "        li r1, {}\n        addi r2, r7, {}\n        sbcb r1, r2, {}",
                    kaddr("k_gdisc"),
                    1 + 2 * body + c * PLANAR_WORDS,
                    klen("k_gdisc")
                );
            }
            let _ = writeln!(w, "{n}_nocap:");
        }
        ChipType::Polygon | ChipType::GlassPolygon => {
            let (head, tail) = if ty == ChipType::Polygon {
                ("k_polyh", "k_polyt")
            } else {
                ("k_gpolyh", "k_gpolyt")
            };
            let _ = writeln!(
                w,
                "        li r1, {}\n        addi r2, r7, 1\n        sbcb r1, r2, {}\n        lfb r3, 0(r7)\n        addi r2, r7, {}\n        li r1, {}\n\
{n}_fan:\n        beqz r3, {n}_tail\n        sbcb r1, r2, {}\n        addi r2, r2, {}\n        addi r3, r3, -1\n        j {n}_fan\n\
{n}_tail:\n        li r1, {}\n        sbcb r1, r2, {}",
                kaddr(head),
                klen(head),
                1 + POLY_HEAD_WORDS,
                kaddr("k_polye"),
                klen("k_polye"),
                POLY_EDGE_WORDS,
                kaddr(tail),
                klen(tail)
            );
        }
    }
}
