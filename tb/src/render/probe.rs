//! The probe: a render of 1/16 of the frame's tiles (every fourth tile row and column), by
//! which the autotuners ([`crate::autotune`]) and `--datapath auto` compare firmwares.

use anyhow::Result;
use firmware::tracer::{Firmware, Options};
use rtl::rc::Datapath;
use rtl::Timing;

use crate::reference::NO_HIT;

use super::item::{run_item, run_items, work_items, Frame};
use super::to8;

/// Every `PROBE_STRIDE`-th tile row and column (1/16 of the tiles) make
/// the probe by which [`choose_firmware`] compares BSP trees and
/// `render --datapath auto` the chips.
pub(crate) const PROBE_STRIDE: u32 = 4;

/// A render of the probe's tiles: their cycles, and their pixels (row by
/// row within each tile, tiles in order) with the colours and hit objects.
#[derive(Clone, Debug)]
pub struct ProbeRender {
    pub cycles: u64,
    pub pixels: Vec<(u32, u32)>,
    pub rgb8: Vec<u8>,
    pub hits: Vec<u32>,
    /// The f64 reference's colours and hits on the same pixels, when
    /// computed.
    pub reference: Option<(Vec<u8>, Vec<u32>)>,
    /// The cycles of a close call's second probe, once run ([`faster`]).
    pub second_cycles: Option<u64>,
}

/// Run the probe's tiles of `opt`'s frame on the chip with `fw`.
pub fn probe(fw: &Firmware, opt: &Options, timing: &Timing) -> Result<ProbeRender> {
    probe_at(fw, opt, timing, PROBE_STRIDE / 2)
}

/// Two firmwares' probes this close (a share of the smaller's cycles) are
/// a close call: [`faster`] runs both again on other tiles before it
/// decides.
pub(crate) const CLOSE_CALL: f64 = 0.02;

/// The tile rows and columns of a close call's second probe: those `k`
/// with `k % PROBE_STRIDE == SECOND_PROBE_PHASE`, half a stride from the
/// probe's.
pub(crate) const SECOND_PROBE_PHASE: u32 = 0;

/// Whether `b` (probed as `pb`) renders `opt`'s frame faster than `a`
/// (probed as `pa`) by more than `margin` of `a`'s cycles: decided on the
/// probe, and where the two probes are within [`CLOSE_CALL`] of each
/// other, on the probe and a second probe of as many other tiles together
/// (the probe's 1/16 of the tiles alone misjudged differences of 1% to 4%
/// on the frame). The second probes' cycles are kept in `pa` and `pb`, so
/// a firmware compared again is not probed again.
pub(crate) fn faster(
    (a, pa): (&Firmware, &mut ProbeRender),
    (b, pb): (&Firmware, &mut ProbeRender),
    opt: &Options,
    timing: &Timing,
    margin: f64,
) -> Result<bool> {
    let (lo, hi) = (
        pa.cycles.min(pb.cycles) as f64,
        pa.cycles.max(pb.cycles) as f64,
    );
    if hi > lo * (1.0 + CLOSE_CALL) {
        return Ok((pb.cycles as f64) < pa.cycles as f64 * (1.0 - margin));
    }
    let second = |fw: &Firmware, known: Option<u64>| {
        known.map_or_else(
            || probe_at(fw, opt, timing, SECOND_PROBE_PHASE).map(|p| p.cycles),
            Ok,
        )
    };
    let (qa, qb) = rayon::join(
        || second(a, pa.second_cycles),
        || second(b, pb.second_cycles),
    );
    let (qa, qb) = (qa?, qb?);
    pa.second_cycles = Some(qa);
    pb.second_cycles = Some(qb);
    let (ta, tb) = ((pa.cycles + qa) as f64, (pb.cycles + qb) as f64);
    Ok(tb < ta * (1.0 - margin))
}

/// [`probe`] on the tile rows and columns `k` with `k % PROBE_STRIDE ==
/// phase`.
fn probe_at(fw: &Firmware, opt: &Options, timing: &Timing, phase: u32) -> Result<ProbeRender> {
    let (tw, th) = (fw.tile_w, fw.tile_h);
    let (nx, ny) = (opt.width.div_ceil(tw), opt.height.div_ceil(th));
    let pick = |n: u32| -> Vec<u32> {
        let v: Vec<u32> = (0..n).filter(|k| k % PROBE_STRIDE == phase).collect();
        if v.is_empty() {
            vec![n / 2]
        } else {
            v
        }
    };
    let mut tiles = Vec::new();
    for ty in pick(ny) {
        for tx in pick(nx) {
            tiles.push((tx * tw, ty * th));
        }
    }
    let img = super::assemble_generated(fw, opt.depth)?;
    let items = work_items(tiles.len(), rayon::current_num_threads(), false);
    let frame = Frame {
        img: &img,
        fw,
        tiles: &tiles,
        timing,
        plain: false,
        say_files: false,
    };
    let runs = run_items(&img, &items, |gi, seed| {
        let own = items[gi].clone();
        let r = match fw.datapath {
            Datapath::W16 => run_item::<i16>(&frame, own, seed, None, false),
            Datapath::W32 => run_item::<i32>(&frame, own, seed, None, false),
        };
        (r, 0.0)
    });
    let mut p = ProbeRender {
        cycles: 0,
        pixels: Vec::new(),
        rgb8: Vec::new(),
        hits: Vec::new(),
        reference: None,
        second_cycles: None,
    };
    let mut ended = false;
    for (own, (r, _)) in items.iter().zip(runs) {
        let mut g = r?;
        if ended {
            g.out.iter_mut().for_each(|o| o.fill(0));
        } else {
            p.cycles += g.counted.cycles;
            ended = g.halted;
        }
        for (k, out) in g.out.iter().enumerate() {
            let (x0, y0) = tiles[own.start + k];
            for lane in 0..64u32 {
                let (row, col) = (lane / 8, lane % 8);
                let (x, y) = (x0 + col, y0 + row);
                if row >= th || col >= tw || x >= opt.width || y >= opt.height {
                    continue;
                }
                p.pixels.push((x, y));
                for c in 0..3 {
                    p.rgb8.push(to8(out[c * 64 + lane as usize], fw.datapath));
                }
                let id = out[192 + lane as usize];
                p.hits.push(if id < 0 { NO_HIT } else { id as u32 });
            }
        }
    }
    Ok(p)
}
