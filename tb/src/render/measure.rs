//! A render measured: the chip's image and figures against the float
//! reference, as the JSON `morphosys render --json` writes; and the check
//! that a JSON on disk is such a render (`--skip-done`, `sweep --merge`).

use crate::render_options as ro;
use std::path::Path;
use std::time::Instant;

use anyhow::Result;
use firmware::tracer::Options;
use serde_json::json;

use crate::{metrics, reference};

/// Everything `render` reports.
pub struct RenderReport {
    pub json: serde_json::Value,
    pub rgb8: Vec<u8>,
    pub reference_rgb8: Vec<u8>,
}

/// Render on the chip and measure against the reference; no files
/// written.
pub fn render(
    scene: &firmware::scene::Scene,
    opt: &Options,
    settings: &crate::render::RenderSettings,
) -> Result<(crate::render::ChipRender, RenderReport)> {
    render_and_measure(scene, opt, settings, None)
}

/// [`render`] with the firmware already built (`None`: built here).
pub(crate) fn render_and_measure(
    scene: &firmware::scene::Scene,
    opt: &Options,
    host: &crate::render::RenderSettings,
    built: Option<firmware::tracer::Firmware>,
) -> Result<(crate::render::ChipRender, RenderReport)> {
    let progress = host.progress;
    let nm = host.numerics;
    let opt = &Options {
        test_cuts: opt.test_cuts.for_issue(host.timing.risc.issue),
        ..*opt
    };
    let t0 = Instant::now();
    let chip = match built {
        Some(fw) => super::render_built(fw, opt, host)?,
        None => super::render_chip(scene, opt, host)?,
    };
    let seconds = t0.elapsed().as_secs_f64();
    let refimg = reference::render(
        scene,
        &reference::Options {
            width: opt.width,
            height: opt.height,
            max_depth: opt.depth,
            corners: false,
            progress,
        },
    );
    let ref8 = refimg.to_rgb8();
    let psnr = metrics::psnr(&chip.rgb8, &ref8);
    let agree = metrics::hit_agreement(&chip.hits, &refimg.hits);
    let r = &chip.firmware.report;
    let warnings: Vec<firmware::scene::Warning> = scene
        .warnings
        .iter()
        .cloned()
        .chain(firmware::tracer::chip_warnings(scene, &r.notes))
        .collect();
    let mut json = json!({
        "scene": scene.source,
        "objects": scene.objects.len(),
        "warnings": warnings,
        "width": opt.width,
        "height": opt.height,
        ro::WAYS.key(): opt.ways,
        ro::DEPTH.key(): opt.depth,
        ro::NEWTON_STEPS.key(): nm.newton_steps,
        ro::TABLE_ENTRIES.key(): nm.table_entries,
        "psnr_db": if psnr.is_finite() { psnr } else { 99.0 },
        "hit_agreement": agree,
        "eye_misclassified": 1.0 - agree,
        "reference_rays": refimg.stats,
        "host_seconds": seconds,
        // The work items' host seconds summed over the threads: about
        // the chip render's time on one thread, whatever else runs beside
        // it (the sweep's --size-seconds).
        "host_chip_seconds": chip.item_seconds.iter().sum::<f64>(),
        "array_cycles_per_host_second": if seconds > 0.0 { chip.stats.cycles as f64 / seconds } else { 0.0 },
        "compiler_format": r.format,
        "format_note": "format: the tracer's, the finest in which every object and the eye fit with the guard bits (lights are scaled apart, never coarser than compiler_format); compiler_format: the scene image's (morphosys compile), which also spans the lights and the camera's target",
        "bsp_nodes": r.bsp.nodes,
        "bsp_max_depth": r.bsp.max_depth,
        ro::CHILD_ORDER.key(): chip.firmware.child_order.to_string(),
    });
    if let (Some(j), serde_json::Value::Object(figures)) =
        (json.as_object_mut(), chip_json(&chip, opt, host))
    {
        j.extend(figures);
    }
    let rep = RenderReport {
        json,
        rgb8: chip.rgb8.clone(),
        reference_rgb8: ref8,
    };
    Ok((chip, rep))
}

/// The chip's figures of a render: its cycles and frame rate, its rays,
/// the array's and the DMA's use, the firmware and the options it ran.
fn chip_json(
    chip: &crate::render::ChipRender,
    opt: &Options,
    host: &crate::render::RenderSettings,
) -> serde_json::Value {
    let file_hz = host.clock_given.then_some(host.timing.clock_hz);
    let clock = crate::cost::chip_clock(chip.firmware.datapath, file_hz);
    let idle_on_control = if chip.stats.cycles > 0 {
        chip.stats.array_idle_control_cycles as f64 / chip.stats.cycles as f64
    } else {
        0.0
    };
    let census = chip.ray_census();
    json!({
        "cycles": chip.cycles,
        "firmware_cycles": chip.firmware_cycles,
        "fps": chip.fps_at((clock.mhz * 1e6).round() as u64),
        "clock_mhz": clock.mhz,
        "clock": clock.from,
        "fps_at_300mhz": chip.fps_at(300_000_000),
        ro::NORMALS.key(): if chip.firmware.layout.fine_normals { "fine" } else { "coarse" },
        ro::POSITIONS.key(): if chip.firmware.layout.fit.local { "local" } else { "global" },
        "eye_rays": census[crate::render::RAY_EYE],
        "shadow_rays": census[crate::render::RAY_SHADOW],
        "reflect_rays": census[crate::render::RAY_REFLECT],
        "refract_rays": census[crate::render::RAY_REFRACT],
        "active_rc_fraction": chip.stats.active_rc_fraction(),
        "dma_stall_cycles": chip.stats.dma_stall_cycles,
        "dma_stall_share": chip.dma_stall_share(),
        "array_idle_on_control": idle_on_control,
        "array_idle_on_dma": if chip.stats.cycles > 0 {
            chip.array_idle_on_dma() as f64 / chip.stats.cycles as f64
        } else {
            0.0
        },
        "objects_tested_per_ray": chip.objects_tested_per_ray(),
        "ray_tests_per_ray": chip.tests_per_ray(),
        "simd_efficiency": chip.simd_efficiency(),
        "object_tests_offered": chip.stats.watched_offered,
        "rays_traced": chip.stats.watched_rcs[1],
        "ray_object_tests": chip.stats.watched_rcs[0],
        "startup_cycles": chip.startup_cycles,
        "tiles": chip.tiles,
        "passes": chip.passes,
        "object_tests": chip.object_tests(),
        "array_busy_cycles": chip.stats.array_busy_cycles,
        "dma_busy_cycles": chip.stats.dma_busy_cycles,
        ro::DATAPATH.key(): opt.datapath.bits(),
        "format": chip.firmware.format(),
        ro::SPLIT.key(): chip.firmware.bsp.rule,
        ro::MAX_DEPTH.key(): chip.firmware.bsp.max_depth,
        "context_words": chip.firmware.context_words,
        "kernels": chip.firmware.kernels.iter().map(|(n, l)| json!({"name": n, "contexts": l})).collect::<Vec<_>>(),
        "fb_words": chip.firmware.fb.len(),
        "node_layout": if opt.traversal == firmware::tracer::Traversal::Packet { "packet" } else { opt.layout.name() },
        ro::TRAVERSAL.key(): opt.traversal.name(),
        ro::COLLAPSE.key(): opt.collapse.to_string(),
        ro::LEAF_PIECES.key(): chip.firmware.pieces.to_string(),
        ro::SHADOW_PACKETS.key(): chip.firmware.shadows.to_string(),
        ro::SUB_EDGES.key(): opt.sub_edges.to_string(),
        ro::TEST_CUTS.key(): opt.test_cuts.to_string(),
        "resident_fb_words": chip.firmware.layout.resident_words,
        "resident_node_words": chip.firmware.layout.resident_node_words,
        "fb_layout": if chip.firmware.layout.stream.is_some() { "streamed" } else { "resident" },
        "stream_bytes": chip.firmware.layout.stream.as_ref().map_or(0, |s| s.image.len()),
        "leaf_fetches": chip.leaf_cache.map(|c| json!({
            "slots": chip.firmware.layout.stream.as_ref().map_or(0, |s| s.cache_slots),
            "slot_words": chip.firmware.layout.stream.as_ref().map_or(0, |s| s.slot_words),
            "hits": c.hits,
            "misses": c.misses,
            "stalls": chip.stats.dma_waits_watched,
        })),

    })
}

/// A render's JSON at `path` when it is complete, made with `argv` from
/// the same `inputs` ([`crate::inputs`]: scene, timing, firmware, build)
/// and holds only values a render can give; else why not, in a few words
/// ("made before the scene changed" when only the inputs differ).
pub(crate) fn render_json(
    path: &Path,
    argv: &[String],
    inputs: &serde_json::Value,
) -> Result<serde_json::Value, String> {
    // Only a regular file can hold a finished render: a FIFO or device
    // would block the read (or never end).
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {}
        Ok(_) => return Err("not a regular file".into()),
        Err(_) => return Err("missing".into()),
    }
    if std::fs::metadata(path).is_ok_and(|m| m.len() > 64 << 20) {
        return Err("larger than any render's JSON".into());
    }
    let text = firmware::input::read_to_string(path).map_err(|_| "missing".to_string())?;
    let j = serde_json::from_str::<serde_json::Value>(&text)
        .map_err(|_| "not complete JSON (a render that failed or was stopped)".to_string())?;
    let same = j["argv"].as_array().is_some_and(|v| {
        v.iter()
            .map(|x| x.as_str())
            .eq(argv.iter().map(|a| Some(a.as_str())))
    });
    if !same {
        return Err("made with other arguments".into());
    }
    if let Some(what) = crate::inputs::changed(&j["inputs"], inputs) {
        return Err(format!("made before {what} changed"));
    }
    if let Some(why) = impossible_value(&j) {
        return Err(why);
    }
    Ok(j)
}

/// The first value in a render's JSON that no render gives (a file edited
/// or corrupted by hand), named with its value.
fn impossible_value(j: &serde_json::Value) -> Option<String> {
    let Some(cycles) = j["cycles"].as_u64().filter(|&c| c > 0) else {
        return Some(format!("cycles {} is not a positive integer", j["cycles"]));
    };
    let tiles = j["tiles"].as_u64().unwrap_or(1).max(1);
    if cycles > (tiles + 1).saturating_mul(super::MAX_CYCLES_PER_TILE) {
        return Some(format!(
            "cycles {cycles} exceed the budget of {tiles} tile(s) and the start-up"
        ));
    }
    let fps = j["fps_at_300mhz"].as_f64();
    let want = 300e6 / cycles as f64;
    if fps.is_none_or(|f| (f - want).abs() > 1e-9 * want) {
        return Some(format!(
            "fps_at_300mhz {} is not 300 MHz / {cycles} cycles",
            j["fps_at_300mhz"]
        ));
    }
    for k in [
        "hit_agreement",
        "active_rc_fraction",
        "array_idle_on_control",
        "array_idle_on_dma",
        "eye_misclassified",
    ] {
        if let Some(v) = j.get(k).filter(|v| !v.is_null()) {
            if !v.as_f64().is_some_and(|x| (0.0..=1.0).contains(&x)) {
                return Some(format!("{k} {v} is not a fraction (0 to 1)"));
            }
        }
    }
    // PSNR of 8-bit images: 0 dB at the worst; identical images are
    // written as null (infinite).
    if let Some(v) = j.get("psnr_db").filter(|v| !v.is_null()) {
        if !v.as_f64().is_some_and(|x| (0.0..=200.0).contains(&x)) {
            return Some(format!("psnr_db {v} is not a PSNR of 8-bit images"));
        }
    }
    for k in ["objects_tested_per_ray", "ray_tests_per_ray"] {
        if let Some(v) = j.get(k).filter(|v| !v.is_null()) {
            if !v.as_f64().is_some_and(|x| x.is_finite() && x >= 0.0) {
                return Some(format!("{k} {v} is not a count per ray"));
            }
        }
    }
    None
}
