//! The sections of `docs/results.md`: each runs its renders through the
//! [`Runner`] and returns its body (the command of one row, the table).

use std::process::Command;

use anyhow::{anyhow, bail, Result};

use super::*;

/// The chip a render ran on: its bits, and `local` with local positions.
fn chip(j: &Value) -> String {
    let local = if j["positions"] == "local" {
        " local"
    } else {
        ""
    };
    format!("{}{local}", u(j, "datapath_bits"))
}

pub(super) fn headline(r: &mut Runner) -> Result<String> {
    let mut rows = Vec::new();
    for s in SMALL {
        let (p, k) = both_traversals(r, s)?;
        rows.push(vec![
            format!("`{}`", short(s)),
            thousands(u(&k, "objects")),
            if chip(&p) == chip(&k) {
                chip(&k)
            } else {
                format!("{} (paper's: {})", chip(&k), chip(&p))
            },
            fps(&p),
            psnr(&p),
            hits(&p),
            format!("**{}**", fps(&k)),
            psnr(&k),
            hits(&k),
        ]);
    }
    body(
        one_row("morphosys render scenes/spd/jacks-1.nff --traversal paper --json out.json"),
        &[
            "scene",
            "objects",
            "bits",
            "paper's traversal: frames/s",
            "PSNR (dB)",
            "hits",
            "packet traversal: frames/s",
            "PSNR (dB)",
            "hits",
        ],
        &rows,
    )
}

/// `scene` rendered with the paper's traversal and with the default one.
fn both_traversals(r: &mut Runner, scene: &str) -> Result<(Value, Value)> {
    Ok((
        r.render(scene, &["--traversal", "paper"])?,
        r.render(scene, &[])?,
    ))
}

pub(super) fn traversal(r: &mut Runner) -> Result<String> {
    let mut rows = Vec::new();
    for s in SMALL {
        let (p, k) = both_traversals(r, s)?;
        rows.push(vec![
            format!("`{}`", short(s)),
            thousands(u(&p, "cycles")),
            thousands(u(&k, "cycles")),
            format!(
                "{:.2}",
                u(&p, "cycles") as f64 / u(&k, "cycles").max(1) as f64
            ),
            format!(
                "{:.2} / {:.2}",
                f(&p, "objects_tested_per_ray"),
                f(&k, "objects_tested_per_ray")
            ),
            format!(
                "{:.1} / {:.1}",
                f(&p, "ray_tests_per_ray"),
                f(&k, "ray_tests_per_ray")
            ),
            format!(
                "{:.0}% / {:.0}%",
                100.0 * f(&p, "array_idle_on_control"),
                100.0 * f(&k, "array_idle_on_control")
            ),
        ]);
    }
    body(
        one_row("morphosys render scenes/spd/tetra-1.nff --json out.json"),
        &[
            "scene",
            "paper: cycles",
            "packet: cycles",
            "speed-up",
            "broadcast paper / packet",
            "tests per ray paper / packet",
            "idle paper / packet",
        ],
        &rows,
    )
}

pub(super) fn large(r: &mut Runner) -> Result<String> {
    let mut rows = Vec::new();
    for s in LARGE {
        for (name, args) in [
            ("paper", &["--traversal", "paper"][..]),
            ("packet", &[][..]),
        ] {
            let j = r.render(s, args)?;
            rows.push(vec![
                format!("`{}`", short(s)),
                thousands(u(&j, "objects")),
                name.into(),
                u(&j, "datapath_bits").to_string(),
                thousands(u(&j, "cycles")),
                fps(&j),
                psnr(&j),
                hits(&j),
                format!("{:.1}", f(&j, "objects_tested_per_ray")),
                format!("{:.1}", f(&j, "ray_tests_per_ray")),
                pct(u(&j, "dma_stall_cycles") as f64 / u(&j, "cycles").max(1) as f64),
            ]);
        }
    }
    body(
        one_row("morphosys render scenes/spd/tetra-6.nff --json out.json"),
        &[
            "scene",
            "objects",
            "traversal",
            "bits",
            "cycles",
            "frames/s",
            "PSNR (dB)",
            "hits",
            "broadcast",
            "tests per ray",
            "DMA stall",
        ],
        &rows,
    )
}

pub(super) fn datapath(r: &mut Runner) -> Result<String> {
    let cost = crate::cost::Synthesis::committed();
    let mut rows = Vec::new();
    for s in PAPER_SCENES {
        for bits in ["16", "32"] {
            let j = r.render(s, &["--datapath", bits])?;
            let dp = rtl::rc::Datapath::from_bits(bits.parse()?).expect("16 or 32");
            let clock = cost.clock_mhz(dp);
            let at_clock = f(&j, "fps_at_300mhz") * clock / crate::cost::CLOCK_MHZ_16;
            rows.push(vec![
                format!("`{}`", short(s)),
                bits.into(),
                j["format"].as_str().unwrap_or("?").into(),
                thousands(u(&j, "cycles")),
                fps_at_300mhz(&j),
                format!("{clock:.0}"),
                sig3(at_clock),
                format!(
                    "{:.2}",
                    at_clock / (cost.array_transistors(dp) as f64 / 1e6)
                ),
                psnr(&j),
                hits(&j),
            ]);
        }
    }
    body(
        one_row("morphosys render scenes/spd/jacks-1.nff --datapath 32 --json out.json"),
        &[
            "scene",
            "bits",
            "format",
            "cycles",
            "frames/s at 300 MHz",
            "clock est. (MHz)",
            "frames/s at that clock",
            "per M array transistors",
            "PSNR (dB)",
            "hits",
        ],
        &rows,
    )
}

pub(super) fn ways(r: &mut Runner) -> Result<String> {
    let ways = ["4", "8", "16", "32", "64"];
    let mut rows = Vec::new();
    for s in &PAPER_SCENES[..3] {
        let mut fr = vec![format!("`{}` frames/s", short(s))];
        let mut ob = vec![format!("`{}` objects tested per ray", short(s))];
        for w in ways {
            let j = if w == "64" {
                r.render(s, &["--traversal", "paper"])?
            } else {
                r.render(s, &["--traversal", "paper", "--ways", w])?
            };
            fr.push(fps(&j));
            ob.push(format!("{:.2}", f(&j, "objects_tested_per_ray")));
        }
        rows.push(fr);
        rows.push(ob);
    }
    let mut head = vec!["ways"];
    head.extend(ways);
    body(
        one_row(
            "morphosys render scenes/spd/tetra-1.nff --traversal paper --ways 16 --json out.json",
        ),
        &head,
        &rows,
    )
}

pub(super) fn issue(r: &mut Runner) -> Result<String> {
    let m1 = r.dir.path().join("m1.toml");
    let out = Command::new(&r.bin)
        .args(["--quiet", "timing", "--issue", "instruction", "--out"])
        .arg(&m1)
        .output()?;
    if !out.status.success() {
        bail!(
            "`morphosys timing --issue instruction` failed: {}",
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let m1 = m1.display().to_string();
    let mut rows = Vec::new();
    for s in SMALL {
        let mut row = vec![format!("`{}`", short(s))];
        for t in [&["--traversal", "paper"][..], &[][..]] {
            let run = r.render(s, t)?;
            let mut a: Vec<&str> = t.to_vec();
            a.extend(["--timing", &m1]);
            let ins = r.render(s, &a)?;
            row.push(format!("{} / {}", fps(&run), fps(&ins)));
            row.push(format!(
                "{:.0}%",
                100.0 * f(&ins, "fps_at_300mhz") / f(&run, "fps_at_300mhz")
            ));
        }
        rows.push(row);
    }
    body(
        "One row: `morphosys timing --issue instruction --out m1.toml`, then \
         `morphosys render scenes/spd/tetra-1.nff --timing m1.toml --json out.json`.\n\n"
            .to_string(),
        &[
            "scene",
            "paper: run / M1 (frames/s)",
            "M1 keeps",
            "packet: run / M1",
            "M1 keeps",
        ],
        &rows,
    )
}

pub(super) fn whitted(r: &mut Runner) -> Result<String> {
    let mut rows = Vec::new();
    for fam in FAMILIES {
        let s = r.spd(fam, Some(2))?;
        let d2 = r.render(&s, &[])?;
        let d5 = r.render(&s, &["--depth", "5"])?;
        rows.push(vec![
            format!("{fam}-2"),
            thousands(u(&d2, "objects")),
            u(&d2, "datapath_bits").to_string(),
            fps(&d2),
            fps(&d5),
            format!("{} / {}", psnr(&d2), psnr(&d5)),
            hits(&d2),
            thousands(u(&d5, "refract_rays")),
        ]);
    }
    body(
        "One row: `morphosys spd mount --size 2 --out mount-2.nff`, then \
         `morphosys render mount-2.nff --depth 5 --json out.json`.\n\n"
            .to_string(),
        &[
            "scene",
            "objects",
            "bits",
            "frames/s depth 2",
            "depth 5",
            "PSNR (dB) depth 2 / 5",
            "hits",
            "refracted rays (depth 5)",
        ],
        &rows,
    )
}

pub(super) fn positions(r: &mut Runner) -> Result<String> {
    let mut rows = Vec::new();
    for fam in ["balls", "jacks", "lattice", "rings", "shells", "tree"] {
        let s = r.spd(fam, None)?;
        let mut row = vec![fam.to_string()];
        for args in [
            ["--datapath", "16", "--positions", "global"],
            ["--datapath", "16", "--positions", "local"],
            ["--datapath", "32", "--positions", "global"],
        ] {
            row.push(match r.render(&s, &args) {
                Ok(j) => format!("{} dB, {}, {}", psnr(&j), hits(&j), fps(&j)),
                Err(_) => "refused".into(),
            });
        }
        rows.push(row);
    }
    body(
        "One row: `morphosys spd balls --out balls.nff`, then \
         `morphosys render balls.nff --datapath 16 --positions local --json out.json`.\n\n"
            .to_string(),
        &[
            "scene",
            "16-bit, global: PSNR, hits, frames/s",
            "16-bit, local",
            "32-bit",
        ],
        &rows,
    )
}

pub(super) fn spd(r: &mut Runner) -> Result<String> {
    let mut rows = Vec::new();
    for fam in FAMILIES {
        let s = r.spd(fam, None)?;
        let j = r.render(&s, &[])?;
        let cycles = u(&j, "cycles").max(1) as f64;
        rows.push(vec![
            fam.to_string(),
            firmware::scene::spd::default_size(fam)
                .map_err(|e| anyhow!(e))?
                .to_string(),
            thousands(u(&j, "objects")),
            chip(&j),
            thousands(u(&j, "cycles")),
            fps(&j),
            psnr(&j),
            hits(&j),
            format!(
                "{:.1} / {:.1}",
                f(&j, "objects_tested_per_ray"),
                f(&j, "ray_tests_per_ray")
            ),
            pct(f(&j, "simd_efficiency")),
            pct(f(&j, "active_rc_fraction")),
            pct(u(&j, "dma_stall_cycles") as f64 / cycles),
            pct(f(&j, "array_idle_on_control")),
            format!(
                "{}, depth {}",
                j["bsp_split"].as_str().unwrap_or("?"),
                u(&j, "bsp_max_depth")
            ),
        ]);
    }
    body(
        "One row: `morphosys spd tetra --out tetra.nff`, then \
         `morphosys render tetra.nff --json out.json`.\n\n"
            .to_string(),
        &[
            "scene",
            "size",
            "objects",
            "bits",
            "cycles",
            "frames/s",
            "PSNR (dB)",
            "hits",
            "broadcast / tests per ray",
            "SIMD efficiency",
            "active RCs",
            "DMA stall",
            "idle",
            "BSP",
        ],
        &rows,
    )
}

pub(super) fn normals(r: &mut Runner) -> Result<String> {
    let mut rows = Vec::new();
    for fam in ["jacks", "balls"] {
        let s = r.spd(fam, Some(2))?;
        let mut row = vec![format!("{fam}-2")];
        for n in ["coarse", "fine"] {
            let j = r.render(&s, &["--datapath", "16", "--normals", n])?;
            row.push(format!("{} dB, {}, {}", psnr(&j), hits(&j), fps(&j)));
        }
        rows.push(row);
    }
    body(
        "One row: `morphosys spd jacks --size 2 --out jacks-2.nff`, then \
         `morphosys render jacks-2.nff --datapath 16 --normals coarse --json out.json`.\n\n"
            .to_string(),
        &[
            "scene",
            "coarse: PSNR, hits, frames/s",
            "fine: PSNR, hits, frames/s",
        ],
        &rows,
    )
}

pub(super) fn layouts(r: &mut Runner) -> Result<String> {
    let mut rows = Vec::new();
    for s in &PAPER_SCENES[..3] {
        let mut row = vec![format!("`{}`", short(s))];
        let mut words = Vec::new();
        for l in ["fig5", "compact"] {
            let j = r.render(s, &["--traversal", "paper", "--layout", l])?;
            row.push(format!("{} ({})", thousands(u(&j, "cycles")), fps(&j)));
            words.push(format!(
                "{} ({})",
                thousands(u(&j, "resident_fb_words")),
                thousands(u(&j, "resident_node_words"))
            ));
        }
        row.extend(words);
        rows.push(row);
    }
    body(
        one_row("morphosys render scenes/spd/tetra-1.nff --traversal paper --layout compact --json out.json"),
        &[
                "scene",
                "Fig. 5: cycles (frames/s)",
                "compact: cycles (frames/s)",
                "FB words Fig. 5",
                "compact",
            ],
        &rows,
    )
}

pub(super) fn published(r: &mut Runner) -> Result<String> {
    let mut rows = Vec::new();
    for s in PAPER_SCENES {
        let j = r.render(s, &["--traversal", "paper", "--normals", "coarse"])?;
        rows.push(vec![
            format!("`{}`", short(s)),
            thousands(u(&j, "firmware_cycles")),
            thousands(u(&j, "cycles")),
            fps(&j),
            psnr(&j),
            hits(&j),
            pct(f(&j, "active_rc_fraction")),
            format!("{:.2}", f(&j, "objects_tested_per_ray")),
            j["format"].as_str().unwrap_or("?").into(),
        ]);
    }
    body(
        one_row("morphosys render scenes/spd/tetra-1.nff --traversal paper --normals coarse --json out.json"),
        &[
                "scene",
                "firmware: cycles",
                "cycles",
                "frames/s",
                "PSNR (dB)",
                "hits",
                "active RCs",
                "objects tested per ray",
                "format",
            ],
        &rows,
    )
}

/// The charts `sweep` draws, as this document shows them.
pub(super) const CHARTS: &[(&str, &str)] = &[
    ("pareto", "PSNR against frames/s, one knob at a time, each scene's Pareto front; the triangles mark the paper's configuration, the hollow markers the 32-bit chip"),
    ("pareto_cost", "The same points with the silicon's price on the speed axis: frames/s at each datapath's estimated clock per million transistors of its array (`morphosys cost`); the 32-bit chip's points (hollow) move left by its larger, slower RCs"),
    ("fig8", "Frames/s against rays in parallel (the paper's Fig. 8), with the paper's 13.3 frames/s at 64 ways"),
    ("fig8_active", "Active RCs per ray lane against ways (set-up contexts run on all 64 RCs before the unused ones sleep)"),
    ("scaling", "Cycles per frame against objects, SPD families at sizes 1 to 4 (64x64), both traversals; the legend gives each series' fitted log-log slope"),
];

pub(super) fn charts(r: &mut Runner) -> Result<String> {
    let out = r.dir.path().join("sweep");
    crate::note!(
        "report charts: morphosys sweep scenes/default.toml scenes/spd/jacks-1.nff scenes/spd/tetra-1.nff --out-dir ..."
    );
    let st = Command::new(&r.bin)
        .args([
            "--quiet",
            "sweep",
            "scenes/default.toml",
            "scenes/spd/jacks-1.nff",
            "scenes/spd/tetra-1.nff",
            "--out-dir",
        ])
        .arg(&out)
        .status()?;
    if !st.success() {
        bail!("section charts: the sweep failed");
    }
    let docs = r.docs.clone();
    let img = docs.join("img/sweep");
    std::fs::create_dir_all(&img)?;
    let mut t = String::from(
        "Written by `morphosys sweep scenes/default.toml scenes/spd/jacks-1.nff \
         scenes/spd/tetra-1.nff --out-dir out` (256x256; the size sweep at 64x64).\n\n",
    );
    for (name, caption) in CHARTS {
        let from = out.join(format!("{name}.png"));
        if !from.is_file() {
            bail!("section charts: the sweep wrote no {name}.png");
        }
        crate::output::write(&img.join(format!("{name}.png")), &std::fs::read(&from)?)?;
        t.push_str(&format!(
            "{caption}:\n\n![{name}](img/sweep/{name}.png)\n\n"
        ));
    }
    let results = docs.join("results");
    std::fs::create_dir_all(&results)?;
    crate::output::write(
        &results.join("results.csv"),
        &std::fs::read(out.join("results.csv"))?,
    )?;
    Ok(t)
}
