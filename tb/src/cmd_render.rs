//! `morphosys render`: the paper's ray tracer on the simulated chip, its
//! frame rate at 300 MHz and its error against the float reference.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use firmware::bsp::BspParams;
use firmware::tracer::{Numerics, Options, Positions};
use serde_json::json;

use crate::cmd_scene::{load_scene, png_bytes};

mod profile_report;
use crate::metrics;
use crate::reference;
use crate::render_options as ro;

#[derive(clap::Args, Debug)]
pub struct RenderArgs {
    /// Scene file (.nff or .toml); default scenes/default.toml.
    pub scene: Option<PathBuf>,
    /// Image size WIDTHxHEIGHT, each side 1..=4096 (default 256x256).
    #[arg(long = ro::SIZE.long, value_name = "WxH", value_parser = crate::cli::parse_size)]
    pub size: Option<(u32, u32)>,
    /// Rays traced in parallel: 4, 8, 16, 32 or 64.
    #[arg(long = ro::WAYS.long, value_name = "N", default_value_t = 64, value_parser = crate::cli::parse_ways)]
    pub ways: u32,
    /// Maximum ray depth 1..=8; the eye ray is depth 1 (default: the
    /// paper's recursion level 2; the SPD's is 5).
    #[arg(long = ro::DEPTH.long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u32).range(1..=firmware::tracer::MAX_RAY_DEPTH as i64))]
    pub depth: u32,
    /// Write the image here (default: <scene>-chip.png).
    #[arg(long, value_name = "PNG")]
    pub out: Option<PathBuf>,
    /// Write the figures as JSON here.
    #[arg(long, value_name = "PATH")]
    pub json: Option<PathBuf>,
    /// Write the chip's hit map here (the object each pixel's eye ray
    /// hit), for `compare --hits` against `reference --hits`.
    #[arg(long, value_name = "PATH")]
    pub hits: Option<PathBuf>,
    /// Write the waveform of the chip on the frame's first 32 tiles here: VCD, or FST
    /// where the path ends in `.fst` (GTKWave save file and filters
    /// beside it).
    #[arg(long, value_name = "PATH")]
    pub vcd: Option<PathBuf>,
    #[command(flatten)]
    pub window: crate::cli::TraceWindow,
    /// Write the generated firmware (assembly source) here.
    #[arg(long, value_name = "FILE.s")]
    pub emit_asm: Option<PathBuf>,
    /// Maximum BSP depth: a number (1..=32) or auto (the paper's 15 for
    /// the paper's traversal; for the packet traversal 15 for a median
    /// tree and 8 + 1.3 log2(objects) for the SAH trees).
    #[arg(long = ro::MAX_DEPTH.long, value_name = "auto|N", default_value = "auto", value_parser = crate::cli::parse_depth)]
    pub max_depth: u32,
    /// Maximum objects per BSP leaf.
    #[arg(long = ro::MAX_LEAF.long, value_name = "N", default_value_t = 5, value_parser = crate::cli::parse_count::<usize>)]
    pub max_leaf: usize,
    /// BSP split rule: median (the paper's spatial median, axes in turn),
    /// sah (surface area heuristic, pbrt's costs), chip (surface area
    /// heuristic with the chip's cycle costs, from its kernels, leaves that fit an
    /// FB bank) or auto (median for the paper's traversal; for the packet
    /// traversal the fastest of the three trees on a probe of the frame).
    #[arg(long = ro::SPLIT.long, value_name = "auto|median|sah|chip", default_value = "auto", value_parser = ["auto", "median", "sah", "chip"])]
    pub split: String,
    /// How BSP nodes name their objects: fig5 (the paper's bit vectors)
    /// or compact (index lists); the same image either way.
    #[arg(long = ro::LAYOUT.long, value_name = "fig5|compact", default_value = "fig5")]
    pub layout: firmware::tracer::NodeLayout,
    /// BSP traversal: paper (the paper's: where the rays disagree, test
    /// every object under the node) or packet (per-ray intervals; a
    /// child is visited only by the rays that reach it).
    #[arg(long = ro::TRAVERSAL.long, value_name = "packet|paper", default_value = "packet")]
    pub traversal: firmware::tracer::Traversal,
    /// Packet traversal: which BSP subtrees to walk as one leaf of all
    /// their objects: auto (where that costs less than walking them, by
    /// the cells' surface areas and the kernels' lengths) or N (those
    /// with at most N objects; 0: none).
    #[arg(long = ro::COLLAPSE.long, value_name = "auto|N", default_value = "auto")]
    pub collapse: firmware::tracer::Collapse,
    /// Streamed packet traversal: the words of the pieces a leaf's records
    /// are moved in by DMA, FIRST,SECOND,REST (or FIRST,REST: the second
    /// as the rest): the first piece of at most FIRST words (the wait at
    /// every leaf), the second of at most SECOND, and what remains in as
    /// few pieces of at most REST as hold it, of about equal words (each
    /// moves while the piece before it is tested); each 1..=16384, FIRST
    /// <= SECOND <= REST, a piece holds at least one record. SECOND auto
    /// (`auto` = 64,auto,256): 2 x FIRST or REST, whichever runs the probe
    /// faster.
    #[arg(long = ro::LEAF_PIECES.long, value_name = "auto|FIRST,[SECOND,]REST", default_value = "auto")]
    pub leaf_pieces: firmware::tracer::LeafPieces,
    /// Packet traversal: the shadow rays of the reflection levels (depth 2
    /// and more): light (a packet per light, the rays in the RCs that
    /// spawned them), merged (the rays of every light moved into as few
    /// packets as hold them, the answers moved back; scenes of 2 to 12
    /// lights) or auto (both run on a probe of the frame, the faster
    /// kept). The eye rays' level keeps a packet per light.
    #[arg(long = ro::SHADOW_PACKETS.long, value_name = "auto|light|merged", default_value = "auto")]
    pub shadow_packets: firmware::tracer::ShadowPackets,
    /// Streamed packet traversal: where a banded polygon's sub-edges are
    /// (polygons of 16 edges or more): apart (where a record would be
    /// over 256 words: in main memory, once per polygon, only the bands a
    /// packet's points lie in moved by DMA once they are known) or records
    /// (in the record, moved with every leaf piece that holds it, as the
    /// resident layout keeps them). The same image.
    #[arg(long = ro::SUB_EDGES.long, value_name = "apart|records", default_value = "apart")]
    pub sub_edges: firmware::tracer::SubEdges,
    /// Packet traversal: run each object test in parts, at the cuts of its
    /// kernels, the rest skipped where no awake ray can still hit the
    /// object: on (a `cut` context in the kernel's run, where the
    /// broadcast unit ends the run), tinyrisc (TinyRISC broadcasts each
    /// part after a status read), off (whole), or auto (on; tinyrisc
    /// under the timing's instruction issue model, where TinyRISC issues
    /// every context itself). The same image every way.
    #[arg(long = ro::TEST_CUTS.long, value_name = "auto|on|tinyrisc|off", default_value = "auto")]
    pub test_cuts: firmware::tracer::TestCuts,
    /// Packet traversal: which child of a node a packet visits first where
    /// its awake rays go both ways along the node's axis: majority (the
    /// near child of most of them), XYZ[,XYZ] (per axis x, y, z of
    /// closest-hit passes, then of any-hit passes, majority if omitted:
    /// m the majority, d the rays going down first, u the rays going up
    /// first; e.g. uud) or auto (per axis the way most of the view's
    /// sampled secondary rays that hit, and shadow rays that are blocked,
    /// go, kept where faster than majority on a probe of the frame; then
    /// each closest-hit axis left to the majority tried on the probe with
    /// the way its sampled rays that hit lean). The same image either way.
    #[arg(long = ro::CHILD_ORDER.long, value_name = "auto|majority|XYZ[,XYZ]", default_value = "auto")]
    pub child_order: firmware::tracer::ChildOrder,
    /// RC datapath width in bits: 16 (the paper's chip), 32 (the
    /// variant the paper announces; every format gets 16 more fraction
    /// bits), or auto: 16 unless the 16-bit chip cannot hold the scene or
    /// renders a probe of the frame (1/16 of the tiles) under 30 dB or
    /// 99% hit agreement against the reference where 32 bits do better.
    #[arg(long = ro::DATAPATH.long, value_name = "auto|16|32", value_parser = crate::cli::parse_datapath_choice, default_value = "auto")]
    pub datapath: crate::cli::DatapathChoice,
    /// Newton-Raphson steps after each reciprocal / square-root table
    /// lookup (0..=3).
    #[arg(long = ro::NEWTON_STEPS.long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u32).range(0..=3))]
    pub newton_steps: u32,
    /// Entries of the reciprocal and reciprocal square-root tables in
    /// every RC's RAM: 16, 32, 64 or 128.
    #[arg(long = ro::TABLE_ENTRIES.long, value_name = "N", default_value_t = 128, value_parser = crate::cli::parse_table_entries)]
    pub table_entries: u32,
    /// Guard bits of the coordinate format above the scene's largest
    /// object or eye coordinate (2..=4; more: a coarser format).
    #[arg(long = ro::GUARD_BITS.long, value_name = "N", default_value_t = 2, value_parser = clap::value_parser!(u32).range(2..=4))]
    pub guard_bits: u32,
    /// Offset of spawned (shadow, reflected, refracted) rays along the
    /// normal, in LSBs of the coordinate format (0..=64).
    #[arg(long = ro::RAY_OFFSET_LSB.long, value_name = "N", default_value_t = firmware::tracer::options::EPS_LSB, value_parser = clap::value_parser!(i32).range(0..=64))]
    pub ray_offset_lsb: i32,
    /// Normals of spheres and cylinders: fine (the eye moved onto the
    /// coordinate format's grid with the whole scene, and the
    /// perpendicular vector formed from unrounded centres and axes and
    /// kept perpendicular to the ray: 9 more cycles per sphere test, 19
    /// per cylinder test), coarse (the kernels as first written, with
    /// which the comparison with the paper was made) or auto (fine on
    /// the 16-bit chip, coarse on the 32-bit one)
    #[arg(long = ro::NORMALS.long, value_name = "auto|fine|coarse", default_value = "auto")]
    pub normals: firmware::tracer::Normals,
    /// Where the 16-bit chip holds positions: global (one fixed-point
    /// format for the whole scene) or local (ray origins with a remainder
    /// of 2^-14 LSB; each sphere, flat triangle, open cylinder and cone
    /// tested in a frame of its own, its LSB fitted to its size, its hit
    /// point brought back with the remainder). Local: the packet traversal on the 16-bit chip,
    /// shadow rays a packet per light. Auto: local on
    /// the 16-bit chip where global ones cannot hold the scene or render
    /// a probe of the frame (1/16 of the tiles) under --datapath auto's
    /// bar and local ones do better; else global
    #[arg(long = ro::POSITIONS.long, value_name = "auto|global|local", default_value = "auto")]
    pub positions: firmware::tracer::Positions,
    /// With --json: when that file already holds a complete render made
    /// with these same arguments from the same scene, timing file,
    /// firmware and build (their SHA-256 digests, `inputs` in the
    /// JSON), say so and stop without rendering (a rerun of a sweep
    /// plan's jobs runs only what is missing).
    #[arg(long, requires = "json")]
    pub skip_done: bool,
    /// Print (and put in the JSON) where the frame's cycles go: per RC kernel while the array works, per TinyRISC
    /// label while it waits (steps every cycle: several times slower).
    #[arg(long)]
    pub profile: bool,
    /// The chip's timing from a TOML file (any subset of the fields
    /// `morphosys timing` prints; the rest keep their defaults).
    #[arg(long, value_name = "FILE.toml")]
    pub timing: Option<PathBuf>,
    /// Render with the program assembled from this file (what
    /// `--emit-asm` writes, edited or not) instead of the generated
    /// one; the scene's data image is built as usual, with the same
    /// options the file was emitted with.
    #[arg(long, value_name = "FILE.s")]
    pub firmware: Option<PathBuf>,
    /// Step every cycle through the plain register-transfer model (one
    /// eval and commit per cycle) instead of the fast paths: slower, and
    /// the same cycles, states and waveform.
    #[arg(long)]
    pub plain: bool,
    /// The command line's arguments (after the program's name), recorded in
    /// the JSON for `--skip-done` and `sweep --merge`.
    #[arg(skip)]
    pub argv: Vec<String>,
}

/// Cycles a render traces when `--trace-cycles` is not given.
pub(crate) const DEFAULT_TRACE_CYCLES: u64 = 100_000;

fn default_out(scene: &Path) -> PathBuf {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_else(|| "render".into());
    PathBuf::from(format!("{stem}-chip.png"))
}

pub fn command(a: RenderArgs) -> Result<()> {
    for knob in a.paper_ignores() {
        eprintln!(
            "morphosys: warning: {knob}: a knob of the packet traversal, which --traversal paper ignores"
        );
    }
    let scene = load_scene(a.scene.as_deref())?;
    let (timing, clock_given) = crate::timing::load_or_default_file(a.timing.as_deref())?;
    let firmware_text = match &a.firmware {
        Some(p) => Some(
            firmware::input::read_to_string(p)
                .with_context(|| format!("{}: cannot read the firmware", p.display()))?,
        ),
        None => None,
    };
    let inputs = crate::inputs::inputs(&scene, &timing, firmware_text.as_deref());
    if let (true, Some(j)) = (a.skip_done, &a.json) {
        match crate::render::render_json(j, &a.argv, &inputs) {
            Ok(_) => {
                crate::report!(
                    "{}: already rendered with these arguments and inputs (--skip-done)",
                    j.display()
                );
                return Ok(());
            }
            Err(why) if why.starts_with("made before") => {
                eprintln!("{}: {why}: rendering again", j.display())
            }
            Err(_) => {}
        }
    }
    let out = a.check_files(&scene)?;
    let (mut opt, nm) = a.options(&timing);
    // --firmware: the file's program on the chip its `.datapath` names.
    let program = match (&a.firmware, firmware_text) {
        (Some(p), Some(text)) => Some((p.display().to_string(), text)),
        _ => None,
    };
    let (built, datapath_reason) = build(&a, &scene, &mut opt, &nm, &timing, program.as_ref())?;
    let (chip, mut rep) = crate::render::render_and_measure(
        &scene,
        &opt,
        &crate::render::RenderSettings {
            numerics: nm,
            streamed: false,
            progress: true,
            trace: a.trace_config(),
            profile: a.profile,
            timing,
            clock_given,
            item_tiles: None,
            plain: a.plain,
        },
        Some(built),
    )?;
    rep.json["timing"] = crate::timing::to_json(&timing);
    rep.json["fps_at_clock"] = chip.fps_at(timing.clock_hz).into();
    rep.json["firmware"] = match &a.firmware {
        Some(p) => p.display().to_string().into(),
        None => "generated".into(),
    };
    if let Some(p) = &chip.profile {
        let c = profile_report::causes(p, &chip);
        rep.json["profile"] = profile_report::profile_json(p, &c);
        if let Some(check) = profile_report::CostCheck::of(p, &c, &chip) {
            rep.json["profile"]["cost_model"] = json!({
                "node_visit": check.node_visit,
                "leaf_loop": check.leaf_loop,
                "object_risc": check.object_risc,
                "model": {
                    "node_visit": firmware::tracer::layout::packet_nodes::PK_NODE_COST,
                    "leaf_loop": firmware::tracer::layout::packet_nodes::PK_LEAF_COST,
                    "object_risc": firmware::tracer::layout::packet_nodes::PK_OBJECT_RISC,
                },
            });
        }
    }
    if let Some(why) = chip.firmware_count_disagrees() {
        let w = firmware::scene::Warning {
            feature: "cycle-count".into(),
            file: program
                .as_ref()
                .map_or_else(|| "the tracer firmware".into(), |(n, _)| n.clone()),
            line: 0,
            count: 0,
            message: why,
        };
        eprintln!("{w}");
        if let Some(list) = rep.json["warnings"].as_array_mut() {
            list.push(serde_json::to_value(&w)?);
        }
    }
    rep.json["datapath_choice"] = serde_json::Value::String(datapath_reason.clone());
    rep.json["argv"] = a.argv.clone().into();
    rep.json["stepping"] = if a.plain { "plain" } else { "fast" }.into();
    rep.json["inputs"] = inputs;
    let (width, height) = (opt.width, opt.height);
    if let Some(h) = &a.hits {
        crate::output::write(
            h,
            &crate::cmd_scene::hit_map_bytes(width, height, &chip.hits),
        )?;
        crate::note!("wrote {}", h.display());
    }
    crate::output::write(&out, &png_bytes(width, height, &chip.rgb8)?)
        .with_context(|| format!("writing {}", out.display()))?;
    crate::note!("wrote {}", out.display());
    print_report(&scene, &opt, &chip, &rep.json, &datapath_reason);
    if let Some(p) = &chip.profile {
        let c = profile_report::causes(p, &chip);
        profile_report::print_profile(p, &c, profile_report::CostCheck::of(p, &c, &chip));
    }
    if let Some(p) = &a.json {
        let text = serde_json::to_string_pretty(&rep.json)?;
        crate::output::write(p, text.as_bytes())?;
        crate::note!("wrote {}", p.display());
    }
    Ok(())
}

impl RenderArgs {
    /// Every file the render reads and writes, checked before the frame
    /// is rendered; the image's path.
    fn check_files(&self, scene: &firmware::scene::Scene) -> Result<PathBuf> {
        let out_path = self
            .out
            .clone()
            .unwrap_or_else(|| default_out(Path::new(&scene.source)));
        let mut files = crate::output::Files::new();
        files.input(
            &self
                .scene
                .clone()
                .unwrap_or_else(crate::cmd_scene::default_scene),
            "SCENE",
        );
        for (p, what) in [(&self.firmware, "--firmware"), (&self.timing, "--timing")] {
            if let Some(p) = p {
                files.input(p, what);
            }
        }
        files.output(&out_path, "--out");
        for (p, what) in [
            (&self.json, "--json"),
            (&self.hits, "--hits"),
            (&self.emit_asm, "--emit-asm"),
        ] {
            if let Some(p) = p {
                files.output(p, what);
            }
        }
        if let Some(v) = &self.vcd {
            files.waveform(v, "--vcd");
        }
        files.check()?;
        Ok(out_path)
    }

    /// The packet traversal's knobs this command line sets otherwise than
    /// their defaults while it asks for the paper's traversal, which
    /// ignores them (as `--OPTION VALUE`).
    fn paper_ignores(&self) -> Vec<String> {
        if self.traversal != firmware::tracer::Traversal::Paper {
            return Vec::new();
        }
        let d = Options::default();
        [
            (
                "collapse",
                self.collapse.to_string(),
                d.collapse.to_string(),
            ),
            (
                "leaf-pieces",
                self.leaf_pieces.to_string(),
                d.pieces.to_string(),
            ),
            (
                "shadow-packets",
                self.shadow_packets.to_string(),
                d.shadows.to_string(),
            ),
            (
                "test-cuts",
                self.test_cuts.to_string(),
                d.test_cuts.to_string(),
            ),
            (
                "child-order",
                self.child_order.to_string(),
                d.child_order.to_string(),
            ),
        ]
        .into_iter()
        .filter(|(_, given, default)| given != default)
        .map(|(name, given, _)| format!("--{name} {given}"))
        .collect()
    }

    /// The tracer's options and the RC arithmetic's knobs this command
    /// line asks for, in one place (clap has checked every range; the
    /// datapath is the 16-bit chip's until `--datapath` is decided, and
    /// `--test-cuts auto` is resolved for the timing's issue model).
    pub fn options(&self, timing: &rtl::Timing) -> (Options, Numerics) {
        let (width, height) = self.size.unwrap_or((256, 256));
        let opt = Options {
            width,
            height,
            ways: self.ways,
            depth: self.depth,
            bsp: BspParams {
                max_depth: self.max_depth,
                max_leaf: self.max_leaf,
                rule: match self.split.as_str() {
                    "sah" => firmware::bsp::SplitRule::Sah,
                    "chip" => firmware::bsp::SplitRule::Chip,
                    "median" => firmware::bsp::SplitRule::Median,
                    _ => firmware::bsp::SplitRule::Auto,
                },
                ..BspParams::default()
            },
            layout: self.layout,
            datapath: rtl::rc::Datapath::W16,
            traversal: self.traversal,
            collapse: self.collapse,
            pieces: self.leaf_pieces,
            shadows: self.shadow_packets,
            test_cuts: self.test_cuts.for_issue(timing.risc.issue),
            child_order: self.child_order,
            sub_edges: self.sub_edges,
            positions: self.positions,
        };
        let nm = Numerics {
            newton_steps: self.newton_steps,
            table_entries: self.table_entries,
            guard_bits: self.guard_bits,
            eps_lsb: self.ray_offset_lsb,
            normals: self.normals,
        };
        (opt, nm)
    }

    /// The waveform asked for (`--vcd`), a window of the first work
    /// item's chip unless `--trace-cycles` says otherwise.
    fn trace_config(&self) -> Option<rtl::trace::TraceConfig> {
        self.vcd.clone().map(|p| {
            let mut c = self.window.config(p);
            if self.window.trace_scope.is_none() {
                c.scope = crate::cli::RENDER_SCOPE.to_string();
            }
            // A frame runs for millions of cycles: without --trace-cycles the
            // waveform covers a window of the first work item's chip, not the whole
            // frame (whose size would be refused anyway).
            if c.count.is_none() {
                c.count = Some(DEFAULT_TRACE_CYCLES);
                c.max_bytes = rtl::trace::MAX_TRACE_BYTES;
                eprintln!(
                    "tracing cycles {}..{} of the chip on the first 32 tiles (--trace-from / --trace-cycles to change)",
                    c.first,
                    c.first + DEFAULT_TRACE_CYCLES
                );
            }
            c
        })
    }
}

/// The chip (`--datapath`) and the firmware for it: generated, or the
/// `--firmware` file's program on the chip its `.datapath` names; why
/// that chip. Writes `--emit-asm`.
fn build(
    a: &RenderArgs,
    scene: &firmware::scene::Scene,
    opt: &mut Options,
    nm: &Numerics,
    timing: &rtl::Timing,
    program: Option<&(String, String)>,
) -> Result<(firmware::tracer::Firmware, String)> {
    let mut choice = a.datapath;
    if let Some((name, text)) = program {
        let d = crate::render::source_datapath(text);
        match choice {
            crate::cli::DatapathChoice::Fixed(f) if f != d => anyhow::bail!(
                "{name}: the firmware is for the {}-bit datapath (`.datapath`), --datapath {} asks for {}",
                d.bits(),
                f.bits(),
                f.bits()
            ),
            _ => choice = crate::cli::DatapathChoice::Fixed(d),
        }
    }
    if let (Some((_, text)), Positions::Auto) = (program, opt.positions) {
        // The file's header says whether it was emitted for local positions.
        let local = text
            .lines()
            .nth(1)
            .is_some_and(|l| l.contains("local positions"));
        opt.positions = if local {
            Positions::Local
        } else {
            Positions::Global
        };
    }
    let (datapath, positions, mut datapath_reason, built) =
        choose_datapath(scene, opt, nm, choice, timing)?;
    opt.datapath = datapath;
    opt.positions = positions;
    let mut built = match built {
        Some(fw) => fw,
        None => crate::render::choose_firmware(scene, opt, nm, timing)?,
    };
    if let Some((name, text)) = program {
        built = crate::render::firmware_from_source(built, text, name)?;
        datapath_reason = format!("{name}: .datapath {}", datapath.bits());
    }
    for w in firmware::tracer::chip_warnings(scene, &built.report.notes) {
        eprintln!("{w}");
    }
    if let Some(p) = &a.emit_asm {
        crate::output::write(p, built.source.as_bytes())?;
        crate::note!("wrote {}", p.display());
    }
    Ok((built, datapath_reason))
}

/// The render's figures as `morphosys render` prints them: what was
/// rendered and how, then what it measured.
fn print_report(
    scene: &firmware::scene::Scene,
    opt: &Options,
    chip: &crate::render::ChipRender,
    j: &serde_json::Value,
    datapath_reason: &str,
) {
    let (width, height) = (opt.width, opt.height);
    crate::report!("scene                    {}", scene.source);
    crate::report!(
        "size                     {width}x{height}, {} ways, depth {}",
        opt.ways,
        opt.depth
    );
    crate::report!(
        "datapath                 {} bits ({datapath_reason}), format {}{}",
        opt.datapath.bits(),
        j["format"].as_str().unwrap_or("?"),
        if j["positions"] == "local" {
            ", local positions (spheres, triangles, cylinders, cones, and rectangles and discs where most are small, in frames of their own; polygons' crossing test on the hit point to 2^-14 LSB; origins and eye-ray directions with remainders)"
        } else {
            ""
        }
    );
    crate::report!(
        "node layout              {} ({} FB words of BSP nodes, {} in all{})",
        if opt.traversal == firmware::tracer::Traversal::Packet {
            "packet".to_string()
        } else {
            opt.layout.to_string()
        },
        j["resident_node_words"],
        j["resident_fb_words"],
        if chip.firmware.layout.stream.is_some() {
            ": over FB set 0, streamed"
        } else {
            ""
        }
    );
    crate::report!(
        "bsp                      {} split, depth limit {}: {} nodes, depth {}",
        j["bsp_split"].as_str().unwrap_or("?"),
        j["bsp_depth_limit"],
        j["bsp_nodes"],
        j["bsp_max_depth"]
    );
    if firmware::tracer::shadows::applies(opt, &chip.firmware.layout) {
        crate::report!(
            "shadow packets           {} (the reflection levels' shadow rays: {}{})",
            chip.firmware.shadows,
            match chip.firmware.shadows {
                firmware::tracer::ShadowPackets::Merged =>
                    "every light's in as few packets as hold them",
                _ => "a packet per light",
            },
            if opt.shadows == firmware::tracer::ShadowPackets::Auto {
                "; auto: the faster on the probe"
            } else {
                ""
            }
        );
    }
    if opt.traversal == firmware::tracer::Traversal::Packet {
        crate::report!(
            "child order              {} (where a packet's awake rays go both ways along a node's axis{})",
            chip.firmware.child_order.describe(),
            if opt.child_order == firmware::tracer::ChildOrder::Auto {
                "; auto: per axis the way most of the view's sampled rays that end go, and the rules the probe runs faster"
            } else {
                ""
            }
        );
        crate::report!(
            "object tests             {}",
            match (chip.firmware.layout.test_cuts, chip.firmware.layout.cut_runs) {
                (true, true) =>
                    "in parts (the broadcast unit ends a test's run at a cut where no awake ray can still hit the object)",
                (true, false) =>
                    "in parts steered by TinyRISC (each part after a cut where some awake ray can still hit the object)",
                _ => "whole (--test-cuts off)",
            }
        );
    }
    print_figures(opt, chip, j);
}

/// The render's measurements: cycles and frame rate, image quality, rays,
/// the array's use, the streamed scene's traffic, host speed.
fn print_figures(opt: &Options, chip: &crate::render::ChipRender, j: &serde_json::Value) {
    crate::report!("cycles                   {}", j["cycles"]);
    crate::report!(
        "fps                      {:.2} at {:.0} MHz ({})",
        j["fps"].as_f64().unwrap_or(0.0),
        j["clock_mhz"].as_f64().unwrap_or(0.0),
        j["clock"].as_str().unwrap_or("?")
    );
    crate::report!(
        "fps at 300 MHz           {:.2} (the paper's clock, for comparison)",
        j["fps_at_300mhz"].as_f64().unwrap_or(0.0)
    );
    crate::report!(
        "psnr (dB)                {:.2}",
        j["psnr_db"].as_f64().unwrap_or(0.0)
    );
    crate::report!(
        "hit agreement            {:.4}",
        j["hit_agreement"].as_f64().unwrap_or(0.0)
    );
    crate::report!(
        "eye rays misclassified   {:.3}% (hit a different object than the reference's)",
        100.0 * j["eye_misclassified"].as_f64().unwrap_or(0.0)
    );
    let rs = &j["reference_rays"];
    let spd_count = rs["reflect_rays"] != rs["live_reflect_rays"];
    crate::report!(
        "rays traced on the chip  eye {}, shadow {}, reflect {}, refract {} (reference: {}, {}, {}, {}{}",
        j["eye_rays"], j["shadow_rays"], j["reflect_rays"], j["refract_rays"],
        rs["eye_rays"], rs["live_shadow_rays"], rs["live_reflect_rays"], rs["live_refract_rays"],
        if spd_count { ";" } else { ")" }
    );
    if spd_count {
        crate::report!(
            "                         counted as the SPD does, with the zero-weight reflections of Ks = 0 surfaces: {}, {}, {})",
            rs["shadow_rays"], rs["reflect_rays"], rs["refract_rays"]
        );
    }
    crate::report!(
        "active RC fraction       {:.3}",
        j["active_rc_fraction"].as_f64().unwrap_or(0.0)
    );
    crate::report!(
        "dma stall cycles         {} ({:.1}% of the cycles; the array idle in {:.1}%)",
        j["dma_stall_cycles"],
        100.0 * j["dma_stall_share"].as_f64().unwrap_or(0.0),
        100.0 * j["array_idle_on_dma"].as_f64().unwrap_or(0.0)
    );
    crate::report!(
        "array idle on control    {:.1}% of the cycles",
        100.0 * j["array_idle_on_control"].as_f64().unwrap_or(0.0)
    );
    if let Some(st) = &chip.firmware.layout.stream {
        crate::report!(
            "scene streamed           {} KiB in main memory ({} BSP nodes), {}",
            st.image.len().div_ceil(1024),
            st.nodes,
            if chip.leaf_cache.is_some() {
                let p = chip.firmware.pieces;
                format!(
                    "leaves moved by DMA in pieces of whole records (at least one each) into FB banks 1 and 0: {}{}",
                    match p.second_or_rest() {
                        s if s < p.rest => format!(
                            "the first of up to {} words, the second {}, the others {}",
                            p.first, s, p.rest
                        ),
                        _ => format!(
                            "the first of up to {} words, the others {}",
                            p.first, p.rest
                        ),
                    },
                    if opt.pieces.second.is_none() {
                        " (auto: the second piece the faster on the probe)"
                    } else {
                        ""
                    }
                )
            } else {
                "leaf blocks by DMA into FB bank 1".to_string()
            }
        );
    }
    if let Some(c) = chip.leaf_cache {
        crate::report!(
            "leaf fetches             {} of {} leaves reached had their first piece in the leaf cache ({:.1}%); {} pieces waited for their DMA",
            c.hits,
            c.hits + c.misses,
            100.0 * c.hits as f64 / (c.hits + c.misses).max(1) as f64,
            chip.stats.dma_waits_watched
        );
    }
    crate::report!(
        "objects tested per ray   {:.2} broadcast per packet pass, {:.2} tested per ray traced",
        j["objects_tested_per_ray"].as_f64().unwrap_or(0.0),
        j["ray_tests_per_ray"].as_f64().unwrap_or(0.0)
    );
    crate::report!(
        "simd efficiency          {:.1}% of the object tests broadcast to a pass's rays were ones the ray needed",
        100.0 * j["simd_efficiency"].as_f64().unwrap_or(0.0)
    );
    crate::report!(
        "host seconds             {:.2}",
        j["host_seconds"].as_f64().unwrap_or(0.0)
    );
    crate::report!(
        "array cycles / host s    {:.3e}",
        j["array_cycles_per_host_second"].as_f64().unwrap_or(0.0)
    );
}

/// The probe's figures of the firmware chosen for `o` (its own probe, or
/// one run for them): the firmware, PSNR (99 where identical) and hit
/// agreement against the f64 reference on the probe's pixels.
fn probe_figures(
    scene: &firmware::scene::Scene,
    o: &Options,
    nm: &firmware::tracer::Numerics,
    timing: &rtl::Timing,
) -> Result<(firmware::tracer::Firmware, f64, f64)> {
    let (fw, p) = crate::render::choose_firmware_probed(scene, o, nm, timing)?;
    let p = match p {
        Some(p) => p,
        None => crate::render::probe(&fw, o, timing)?,
    };
    let (r8, rh) = match &p.reference {
        Some(r) => r.clone(),
        None => reference::render_pixels(scene, o.width, o.height, o.depth, &p.pixels),
    };
    let psnr = metrics::psnr(&p.rgb8, &r8);
    Ok((
        fw,
        if psnr.is_finite() { psnr } else { 99.0 },
        metrics::hit_agreement(&p.hits, &rh),
    ))
}

/// A probe's firmware, PSNR and hit agreement ([`probe_figures`]).
type Probed = (firmware::tracer::Firmware, f64, f64);

/// The 16-bit chip's probe with positions `p` (`measured` of the options
/// `on` gives), and with `auto` local ones instead where `p`'s fail or
/// fall under the positions' bar ([`crate::cli::POSITIONS_MIN_PSNR`],
/// [`crate::cli::POSITIONS_MIN_HITS`]) and local ones pass it or do better
/// in both.
fn measure_16(
    measured: &dyn Fn(&Options) -> Result<Probed>,
    on: &dyn Fn(rtl::rc::Datapath, Positions) -> Options,
    p: Positions,
    auto: bool,
) -> Result<(Probed, Positions)> {
    use crate::cli::{POSITIONS_MIN_HITS, POSITIONS_MIN_PSNR};
    let passes = |p: f64, h: f64| p >= POSITIONS_MIN_PSNR && h >= POSITIONS_MIN_HITS;
    let w16 = rtl::rc::Datapath::W16;
    let m16 = measured(&on(w16, p)).map(|m| (m, p));
    if !auto || matches!(&m16, Ok(((_, p, h), _)) if passes(*p, *h)) {
        return m16;
    }
    match (measured(&on(w16, Positions::Local)), &m16) {
        (Ok(l), Ok(((_, p, h), _))) if passes(l.1, l.2) || (l.1 > *p && l.2 >= *h) => {
            Ok((l, Positions::Local))
        }
        (Ok(l), Err(_)) => Ok((l, Positions::Local)),
        _ => m16,
    }
}

/// The chip for `--datapath` and the positions for `--positions`, the
/// firmware built where a probe chose them, and why.
///
/// Datapath `auto`: the paper's 16-bit chip, unless it cannot hold the
/// scene, or its render of the probe (1/16 of the frame's tiles,
/// [`crate::render::probe`]) falls under the project's bar
/// ([`crate::cli::AUTO_MIN_PSNR`] dB and [`crate::cli::AUTO_MIN_HITS`] hit
/// agreement against the f64 reference on the same pixels) while the
/// 32-bit chip's does better. Positions `auto` on the 16-bit chip: global,
/// unless the scene's format cannot hold the scene or the probe with them
/// falls under the positions' bar (40 dB, 99.9%), and local positions hold
/// it or do better ([`Positions`]); on the 32-bit chip, global.
fn choose_datapath(
    scene: &firmware::scene::Scene,
    opt: &Options,
    nm: &firmware::tracer::Numerics,
    choice: crate::cli::DatapathChoice,
    timing: &rtl::Timing,
) -> Result<(
    rtl::rc::Datapath,
    Positions,
    String,
    Option<firmware::tracer::Firmware>,
)> {
    use crate::cli::{AUTO_MIN_HITS, AUTO_MIN_PSNR};
    use rtl::rc::Datapath;
    let auto_positions = opt.positions == Positions::Auto;
    let fixed = |p: Positions| {
        if p == Positions::Auto {
            Positions::Global
        } else {
            p
        }
    };
    if let crate::cli::DatapathChoice::Fixed(d) = choice {
        if !(auto_positions && d == Datapath::W16) {
            return Ok((
                d,
                fixed(opt.positions),
                format!("--datapath {}", d.bits()),
                None,
            ));
        }
    }
    let on = |d: Datapath, p: Positions| Options {
        datapath: d,
        positions: p,
        ..*opt
    };
    let measured = |o: &Options| probe_figures(scene, o, nm, timing);
    let passes = |p: f64, h: f64| p >= AUTO_MIN_PSNR && h >= AUTO_MIN_HITS;
    let m16 = measure_16(&measured, &on, fixed(opt.positions), auto_positions);
    let local_note = |p: Positions| {
        if p == Positions::Local && auto_positions {
            ", local positions: global ones cannot hold the scene or fall under 40 dB or 99.9% hit agreement"
        } else {
            ""
        }
    };
    if let crate::cli::DatapathChoice::Fixed(_) = choice {
        let (_, p) = m16.as_ref().map_err(|e| anyhow::anyhow!("{e:#}"))?;
        let p = *p;
        let ((fw, ..), _) = m16?;
        let why = match local_note(p) {
            "" => String::new(),
            n => format!(" ({})", n.trim_start_matches(", ")),
        };
        return Ok((Datapath::W16, p, format!("--datapath 16{why}"), Some(fw)));
    }
    let ((fw16, p16, h16), pos16) = match m16 {
        Ok(m) => m,
        Err(e16) => {
            // A scene the 16-bit format cannot hold may still fit the
            // 32-bit chip's (16 more fraction bits).
            let (fw32, ..) = match measured(&on(Datapath::W32, Positions::Global)) {
                Ok(m) => m,
                Err(e32) => anyhow::bail!(
                    "neither chip can render the scene (--datapath auto): the 16-bit chip: \
                     {e16:#}; the 32-bit chip: {e32:#}"
                ),
            };
            return Ok((
                Datapath::W32,
                Positions::Global,
                "auto: the 16-bit chip cannot hold the scene (`--datapath 16` says why); the 32-bit chip can".into(),
                Some(fw32),
            ));
        }
    };
    let m16 = format!(
        "the 16-bit chip ({}{}) renders the probe (1/16 of the tiles) at {p16:.1} dB, {:.2}% hit agreement",
        fw16.format(),
        local_note(pos16),
        100.0 * h16
    );
    if passes(p16, h16) {
        return Ok((Datapath::W16, pos16, format!("auto: {m16}"), Some(fw16)));
    }
    let bar = format!(
        "under the {AUTO_MIN_PSNR} dB / {}% bar",
        100.0 * AUTO_MIN_HITS
    );
    match measured(&on(Datapath::W32, Positions::Global)) {
        Ok((fw32, p32, h32)) if p32 > p16 => Ok((
            Datapath::W32,
            Positions::Global,
            format!(
                "auto: {m16}, {bar}; the 32-bit chip ({}) at {p32:.1} dB, {:.2}%; --datapath 16 forces the paper's chip",
                fw32.format(),
                100.0 * h32
            ),
            Some(fw32),
        )),
        Ok(_) => Ok((
            Datapath::W16,
            pos16,
            format!("auto: {m16}, {bar}, and the 32-bit chip does no better"),
            Some(fw16),
        )),
        Err(e) => Ok((
            Datapath::W16,
            pos16,
            format!("auto: {m16}, {bar}, and the 32-bit chip cannot render it ({e:#})"),
            Some(fw16),
        )),
    }
}
