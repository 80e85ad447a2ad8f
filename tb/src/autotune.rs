//! The autotuners of `render`: which BSP tree, shadow packets, second leaf piece and child
//! order the packet traversal's firmware takes, each decided by running candidates on the
//! probe ([`crate::render::probe`]) and keeping the faster where the image is the same.

use anyhow::{anyhow, Result};
use firmware::scene::Scene;
use firmware::tracer::{self, Firmware, Numerics, Options};
use rayon::prelude::*;
use rtl::Timing;

use crate::render::{faster, probe, ProbeRender};

/// The firmware for `opt`. Where the options leave the BSP to the tracer
/// and it has more than one candidate ([`tracer::resolve_bsp`]: the packet
/// traversal's median, SAH and chip-cost SAH trees), each is run on the probe (every
/// fourth row and column of tiles, at the frame's size, so each packet is
/// as coherent as in the frame) and compared with the f64 reference on the
/// same pixels: the tree with the fewest cycles is kept among those whose
/// probe is within [`TREE_PSNR_SLACK`] dB of the best one's (a faster tree
/// must not cost image quality: the trees find the same hits up to ties,
/// but a tie between surfaces of different colours is visible); ties go
/// to the first. With `ShadowPackets::Auto` where merging applies
/// ([`tracer::shadows::applies`]), the chosen tree is probed again with
/// merged shadow packets and the fewer cycles kept (the images are the
/// same); with the second leaf piece `auto` on a streamed scene, the
/// second piece's size likewise ([`choose_pieces`]); with
/// `ChildOrder::Auto`, the order the view's rays ask for likewise
/// ([`choose_child_order`]). Deterministic.
pub fn choose_firmware(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
) -> Result<Firmware> {
    Ok(choose_firmware_probed(scene, opt, nm, timing)?.0)
}

/// See [`choose_firmware`].
pub(crate) const TREE_PSNR_SLACK: f64 = 0.25;

/// [`choose_firmware`], with the chosen firmware's probe when one ran.
pub(crate) fn choose_firmware_probed(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
) -> Result<(Firmware, Option<ProbeRender>)> {
    let (fw, p) = choose_tree(scene, opt, nm, timing)?;
    let (fw, p) = choose_shadows(scene, opt, nm, timing, fw, p)?;
    let (fw, p) = choose_pieces(scene, opt, nm, timing, fw, p)?;
    choose_child_order(scene, opt, nm, timing, fw, p)
}

/// The share of the probe's cycles a second leaf piece of `2 * FIRST`
/// words must save to replace one of REST's ([`choose_pieces`]).
pub(crate) const PIECES_MARGIN: f64 = 0.003;

/// `--leaf-pieces` with the second piece `auto` (the default; streamed
/// scenes): the tree and shadow packets chosen, a second piece of at most
/// `2 * FIRST` words against one of REST's on the probe. The small second
/// piece is a shorter wait after the first piece's tests but one more
/// turn of the leaf's loop, which pays where the array waits for further
/// pieces (SPD rings, mount) and costs where the tests hide the DMA (SPD
/// gears); the same objects are tested in the same order, so the images
/// are the same.
fn choose_pieces(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
    fw: Firmware,
    p: Option<ProbeRender>,
) -> Result<(Firmware, Option<ProbeRender>)> {
    let Some(second) = opt.pieces.auto_second() else {
        return Ok((fw, p));
    };
    if fw.layout.stream.is_none() {
        return Ok((fw, p));
    }
    let small = Options {
        bsp: fw.bsp,
        shadows: fw.shadows,
        pieces: tracer::LeafPieces {
            second: Some(second),
            ..opt.pieces
        },
        ..*opt
    };
    let sfw = tracer::build_with(scene, &small, nm).map_err(|e| anyhow!("{e}"))?;
    keep_faster((fw, p), sfw, opt, timing, PIECES_MARGIN)
}

/// `fw` (with its probe, if one ran) or `alt`, which renders the same
/// image, whichever runs the probe in fewer cycles: `alt` where it saves
/// more than `margin` of `fw`'s ([`faster`]: a close call is probed
/// twice).
fn keep_faster(
    (fw, p): (Firmware, Option<ProbeRender>),
    alt: Firmware,
    opt: &Options,
    timing: &Timing,
    margin: f64,
) -> Result<(Firmware, Option<ProbeRender>)> {
    let (p, ap) = rayon::join(
        || p.map_or_else(|| probe(&fw, opt, timing), Ok),
        || probe(&alt, opt, timing),
    );
    let (mut p, mut ap) = (p?, ap?);
    if faster((&fw, &mut p), (&alt, &mut ap), opt, timing, margin)? {
        ap.reference = p.reference;
        Ok((alt, Some(ap)))
    } else {
        Ok((fw, Some(p)))
    }
}

/// `--shadow-packets auto`: the tree chosen, merged shadow packets
/// against a packet per light on the probe, the fewer cycles kept.
fn choose_shadows(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
    fw: Firmware,
    p: Option<ProbeRender>,
) -> Result<(Firmware, Option<ProbeRender>)> {
    if opt.shadows != tracer::ShadowPackets::Auto || !tracer::shadows::applies(opt, &fw.layout) {
        return Ok((fw, p));
    }
    let merged = Options {
        bsp: fw.bsp,
        shadows: tracer::ShadowPackets::Merged,
        ..*opt
    };
    let mfw = tracer::build_with(scene, &merged, nm).map_err(|e| anyhow!("{e}"))?;
    // The same images: the same rays, traced in other packets.
    keep_faster((fw, p), mfw, opt, timing, 0.0)
}

/// Eye rays the host traces to learn the ways rays end
/// ([`choose_child_order`]): about this many, every k-th pixel of the
/// frame in both directions.
pub(crate) const CHILD_ORDER_SAMPLES: u64 = 16_384;

/// The share of the probe's cycles a child order must save to replace
/// the one it is tried against ([`choose_child_order`]): the probe's
/// 1/16 of the tiles cannot tell smaller differences from the frame's.
pub(crate) const CHILD_ORDER_MARGIN: f64 = 0.003;

/// `--child-order auto` (packet traversal). First the order the view's
/// rays ask for: per axis and kind of pass, the way most of the rays that
/// end went ([`tracer::ChildOrder::from_hits`], from the f64 reference's
/// rays of every k-th pixel: the secondary rays that hit, the shadow rays
/// that are blocked); then, per axis of closest-hit passes that the
/// sample leaves to the majority though its secondary rays go both ways
/// along it, the rule of the way its rays that hit lean, however little.
/// Each is run on the probe: the view's order is kept where it takes
/// fewer cycles than the majority, each axis's rule where it saves more
/// than [`CHILD_ORDER_MARGIN`] of the cycles of the order before it (the
/// same images: the same hits, found in another order).
fn choose_child_order(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
    fw: Firmware,
    p: Option<ProbeRender>,
) -> Result<(Firmware, Option<ProbeRender>)> {
    use tracer::{AxisOrder, ChildOrder};
    if opt.child_order != ChildOrder::Auto || opt.traversal != tracer::Traversal::Packet {
        return Ok((fw, p));
    }
    let pixels = opt.width as u64 * opt.height as u64;
    let stride = ((pixels / CHILD_ORDER_SAMPLES) as f64)
        .sqrt()
        .floor()
        .max(1.0) as u32;
    let w = crate::reference::ray_ways(scene, opt.width, opt.height, opt.depth, stride);
    let prior = ChildOrder::from_hits(
        (&w.secondary_hit, &w.secondary),
        (&w.shadow_blocked, &w.shadow),
    );
    let mixed: Vec<usize> = (0..3)
        .filter(|&a| w.secondary[a][0] > 0 && w.secondary[a][1] > 0)
        .collect();
    if prior == ChildOrder::MAJORITY && mixed.is_empty() {
        return Ok((fw, p));
    }
    // Every order is generated on the same layout (the kept firmware's:
    // the orders differ only in their programs).
    let build = |base: &Firmware, order: ChildOrder| {
        tracer::with_child_order(scene, base, opt, nm, order).map_err(|e| anyhow!("{e}"))
    };
    let mut best = match p {
        Some(p) => (fw, p),
        None => {
            let p = probe(&fw, opt, timing)?;
            (fw, p)
        }
    };
    let keep = |best: &mut (Firmware, ProbeRender), fw: Firmware, mut p: ProbeRender, margin| {
        if faster((&best.0, &mut best.1), (&fw, &mut p), opt, timing, margin)? {
            p.reference = best.1.reference.take();
            *best = (fw, p);
        }
        Ok::<(), anyhow::Error>(())
    };
    if prior != ChildOrder::MAJORITY {
        let pfw = build(&best.0, prior)?;
        let pp = probe(&pfw, opt, timing)?;
        keep(&mut best, pfw, pp, 0.0)?;
    }
    for a in mixed {
        let (mut closest, any) = best.0.child_order.rules();
        if closest[a] != AxisOrder::Majority {
            continue;
        }
        // The way the sample leans, if only a little.
        let [down, up] = w.secondary_hit[a];
        closest[a] = if down >= up {
            AxisOrder::Down
        } else {
            AxisOrder::Up
        };
        let f = build(&best.0, ChildOrder::Fixed { closest, any })?;
        let p = probe(&f, opt, timing)?;
        keep(&mut best, f, p, CHILD_ORDER_MARGIN)?;
    }
    Ok((best.0, Some(best.1)))
}

/// [`choose_firmware_probed`]'s choice of the BSP tree (shadow packets
/// `Auto` built as `PerLight`).
fn choose_tree(
    scene: &Scene,
    opt: &Options,
    nm: &Numerics,
    timing: &Timing,
) -> Result<(Firmware, Option<ProbeRender>)> {
    let cands = tracer::resolve_bsp(opt, scene.objects.len());
    if cands.len() < 2 {
        let fw = tracer::build_with(scene, opt, nm).map_err(|e| anyhow!("{e}"))?;
        return Ok((fw, None));
    }
    let mut tried: Vec<(ProbeRender, f64, Firmware)> = Vec::new();
    let mut reference: Option<(Vec<u8>, Vec<u32>)> = None;
    let mut first_err = None;
    // The candidates built and probed side by side (each probe's chip
    // instances and each tree's build share the thread pool), taken in
    // their order.
    let built: Vec<std::result::Result<Result<(Firmware, ProbeRender)>, String>> = cands
        .par_iter()
        .map(|&bsp| {
            let o = Options { bsp, ..*opt };
            tracer::build_with(scene, &o, nm).map(|fw| probe(&fw, opt, timing).map(|p| (fw, p)))
        })
        .collect();
    for b in built {
        let (fw, mut p) = match b {
            Ok(probed) => probed?,
            Err(e) => {
                first_err.get_or_insert(e);
                continue;
            }
        };
        let (r8, rh) = reference.get_or_insert_with(|| {
            crate::reference::render_pixels(scene, opt.width, opt.height, opt.depth, &p.pixels)
        });
        let psnr = crate::metrics::psnr(&p.rgb8, r8);
        p.reference = Some((r8.clone(), rh.clone()));
        tried.push((p, if psnr.is_finite() { psnr } else { 99.0 }, fw));
    }
    let best_psnr = tried.iter().map(|t| t.1).fold(f64::NEG_INFINITY, f64::max);
    let mut pick: Option<(ProbeRender, f64, Firmware)> = None;
    for t in tried {
        if t.1 >= best_psnr - TREE_PSNR_SLACK
            && pick.as_ref().is_none_or(|(b, _, _)| t.0.cycles < b.cycles)
        {
            pick = Some(t);
        }
    }
    match pick {
        Some((p, _, fw)) => Ok((fw, Some(p))),
        None => Err(anyhow!(
            "{}",
            first_err.unwrap_or_else(|| "internal: no BSP to build".into())
        )),
    }
}
