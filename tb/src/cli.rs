//! Argument groups shared by several subcommands.

use clap::Args;

/// Which cycles and scopes a waveform records.
#[derive(Args, Clone, Debug, Default)]
pub struct TraceWindow {
    /// First cycle to trace.
    #[arg(long, value_name = "CYCLE", default_value_t = 0)]
    pub trace_from: u64,
    /// Number of cycles to trace (default: to the end of the run, and for
    /// `render` the first 100,000 cycles of the chip on the first 32 tiles). A
    /// window left open stops at 256 MB of waveform, with a warning; one
    /// asked for is refused up front when its estimate passes 4 GB.
    #[arg(long, value_name = "CYCLES", value_parser = parse_count::<u64>)]
    pub trace_cycles: Option<u64>,
    /// Trace only these scopes: comma-separated dotted paths with `*` and
    /// `?` globs, e.g. `rc.alu,rc.flags` or `array.rc_r*_c0`; `all` for
    /// every signal. Default: every signal, except for `render`: what an
    /// architect looks at first (TinyRISC pc, instruction and state, the
    /// broadcast unit, DMA, the array's context, awake and flag masks, and
    /// RC (0,0)), see `RENDER_SCOPE`.
    #[arg(long, value_name = "SCOPE", value_parser = parse_scope)]
    pub trace_scope: Option<String>,
}

/// The signals a render's waveform records unless `--trace-scope` says
/// otherwise: the control path and one RC, 52 signals of the 1,842
/// (`--trace-scope all` records every one).
pub(crate) const RENDER_SCOPE: &str = "tinyrisc.pc,tinyrisc.ir,tinyrisc.state,broadcast,dma,\
array.active,array.mode,array.active_rcs,array.ctx,array.op,array.awake,array.flag_f,\
array.fb0,array.fb1,array.rc_r0_c0";

fn parse_scope(s: &str) -> Result<String, String> {
    if s.trim() == "all" {
        return Ok(String::new());
    }
    // An empty list would be read as every signal (hundreds of MB).
    if s.split(',').all(|p| p.trim().is_empty()) {
        return Err("names no scope: give dotted paths such as `tinyrisc,array.rc_r0_c0`, or `all` for every signal".into());
    }
    rtl::trace::check_scope_patterns(s)?;
    Ok(s.to_string())
}

impl TraceWindow {
    pub fn config(&self, path: std::path::PathBuf) -> rtl::trace::TraceConfig {
        let mut c = rtl::trace::TraceConfig::new(path);
        c.partial_files = Some(crate::output::PARTIAL_FILES);
        c.first = self.trace_from;
        c.count = self.trace_cycles;
        c.scope = self.trace_scope.clone().unwrap_or_default();
        if c.count.is_none() {
            // A run that never halts must not fill the disk at ~6 MB/s.
            c.max_bytes = OPEN_WINDOW_MAX_BYTES;
        }
        c
    }
}

/// Where a waveform with no `--trace-cycles` stops (with a warning).
pub(crate) const OPEN_WINDOW_MAX_BYTES: u64 = 256 << 20;

#[cfg(test)]
mod tests {
    #[test]
    fn an_open_window_is_capped_and_an_asked_one_is_not() {
        let w = super::TraceWindow::default();
        assert_eq!(w.config("x.vcd".into()).max_bytes, 256 << 20);
        let w = super::TraceWindow {
            trace_cycles: Some(10),
            ..Default::default()
        };
        assert_eq!(
            w.config("x.vcd".into()).max_bytes,
            rtl::trace::MAX_TRACE_BYTES
        );
    }
}

/// `--datapath 16|32`: the RC datapath width of the simulated chip.
pub(crate) fn parse_datapath(s: &str) -> Result<rtl::rc::Datapath, String> {
    s.trim()
        .parse::<u32>()
        .ok()
        .and_then(rtl::rc::Datapath::from_bits)
        .ok_or_else(|| {
            format!("`{s}` is not a datapath width: 16 (the paper's chip) or 32 (the wide variant)")
        })
}

/// `render --datapath`: a width, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DatapathChoice {
    /// The paper's 16-bit chip unless it cannot hold the scene, or its
    /// render of a probe of the frame (1/16 of the tiles) falls under
    /// [`AUTO_MIN_PSNR`] dB or [`AUTO_MIN_HITS`] hit agreement against the
    /// f64 reference while the 32-bit chip's does better; then the 32-bit
    /// chip.
    Auto,
    Fixed(rtl::rc::Datapath),
}

/// The project's quality bar (every bundled scene meets it): the PSNR and
/// hit agreement against the f64 reference under which `--datapath auto`
/// tries the 32-bit chip. Measured, not guessed from feature sizes: a
/// scene's smallest parts in LSB do not tell how it renders
/// (`docs/results.md` has both chips on the bundled and SPD scenes).
pub(crate) const AUTO_MIN_PSNR: f64 = 30.0;
pub(crate) const AUTO_MIN_HITS: f64 = 0.99;

/// The bar of `--positions auto` on the 16-bit chip: where its probe with
/// global positions falls under this PSNR or hit agreement and local
/// positions do better, it takes local ones (they cost cycles, so a
/// scene global positions render this well keeps them).
pub(crate) const POSITIONS_MIN_PSNR: f64 = 40.0;
pub(crate) const POSITIONS_MIN_HITS: f64 = 0.999;

pub(crate) fn parse_datapath_choice(s: &str) -> Result<DatapathChoice, String> {
    if s.trim() == "auto" {
        return Ok(DatapathChoice::Auto);
    }
    parse_datapath(s)
        .map(DatapathChoice::Fixed)
        .map_err(|e| e.replace("a datapath width: 16", "a datapath width: auto, 16"))
}

/// A count of at least one (`--count`, `--repeat`, `--max-size`,
/// `--trace-cycles`): clap's value error names the argument.
pub fn parse_count<T>(s: &str) -> Result<T, String>
where
    T: std::str::FromStr + PartialOrd + From<u8>,
{
    match s.parse::<T>() {
        Ok(n) if n >= T::from(1) => Ok(n),
        _ => Err(format!(
            "expected a whole number of at least 1, found '{s}'"
        )),
    }
}

/// A number of seconds above zero.
pub(crate) fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(x) if x > 0.0 && x.is_finite() => Ok(x),
        _ => Err(format!("expected a number of seconds above 0, found '{s}'")),
    }
}

/// A bad argument found after parsing (one whose limits depend on another
/// argument, such as `spd NAME --size N`): like clap's own, one line and
/// exit code 2.
#[derive(Debug)]
pub struct UsageError {
    /// The subcommand whose `--help` the message points to.
    pub command: &'static str,
    pub message: String,
}

impl std::fmt::Display for UsageError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.message)
    }
}

impl std::error::Error for UsageError {}

/// `--table-entries`: the table sizes that fit a 128-word slot of an RC's RAM.
pub(crate) fn parse_table_entries(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n) if firmware::tracer::math::TABLE_SIZES.contains(&n) => Ok(n),
        _ => Err(format!(
            "expected 16, 32, 64 or 128 (each table has a 128-word slot of the RC's 512-word RAM), found '{s}'"
        )),
    }
}

/// `--ways`: 4, 8, 16, 32 or 64 rays in flight (a tile of 2x2 .. 8x8).
pub(crate) fn parse_ways(s: &str) -> Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n @ (4 | 8 | 16 | 32 | 64)) => Ok(n),
        _ => Err(format!("expected 4, 8, 16, 32 or 64, found '{s}'")),
    }
}

pub(crate) fn parse_depth(s: &str) -> Result<u32, String> {
    if s == "auto" {
        return Ok(0);
    }
    match s.parse::<u32>() {
        Ok(d) if (1..=firmware::scene_image::MAX_BSP_DEPTH).contains(&d) => Ok(d),
        _ => Err(format!(
            "expected auto or a depth 1..={}",
            firmware::scene_image::MAX_BSP_DEPTH
        )),
    }
}

/// The largest image side any command renders (host memory grows with the
/// pixels: about 40 bytes each, 670 MB at 4096x4096).
pub(crate) const MAX_SIDE: u64 = 4096;

/// `w` x `h` if each side is 1..=[`MAX_SIDE`]; otherwise what the request
/// would cost: about 40 bytes of host memory per pixel (images, hit maps,
/// f64 colours) and, on the chip, the frame's cycles at the simulator's
/// speed (`morphosys bench` measures both).
pub(crate) fn check_size(w: u64, h: u64) -> Result<(u32, u32), String> {
    if (1..=MAX_SIDE).contains(&w) && (1..=MAX_SIDE).contains(&h) {
        return Ok((w as u32, h as u32));
    }
    if w == 0 || h == 0 {
        return Err(format!("{w}x{h}: each side must be 1..={MAX_SIDE}"));
    }
    let px = w as f64 * h as f64;
    let long = if w > MAX_SIDE { "width" } else { "height" };
    if px <= (MAX_SIDE * MAX_SIDE) as f64 {
        // Few pixels, one side too long: the cost is not what refuses it.
        return Err(format!(
            "{w}x{h}: the {long} is over {MAX_SIDE}; each side must be 1..={MAX_SIDE}"
        ));
    }
    let mb = px * 40.0 / 1e6;
    let secs = px * 140.0 / 15e6;
    let mem = if mb >= 1000.0 {
        format!("{:.0} GB", mb / 1000.0)
    } else {
        format!("{mb:.0} MB")
    };
    let time = if secs >= 7200.0 {
        format!("{:.0} hours", secs / 3600.0)
    } else if secs >= 120.0 {
        format!("{:.0} minutes", secs / 60.0)
    } else {
        format!("{secs:.0} seconds")
    };
    Err(format!(
        "{w}x{h} is too large: each side must be 1..={MAX_SIDE} (this would need about {mem} of memory and, on the simulated chip, about {time} of host time)"
    ))
}

/// `--size WIDTHxHEIGHT`, each side 1..=[`MAX_SIDE`].
pub(crate) fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, e.g. 256x256, found '{s}'"))?;
    let n = |v: &str| v.trim().parse::<u64>().ok();
    match (n(w), n(h)) {
        (Some(w), Some(h)) => check_size(w, h),
        _ => Err(format!(
            "expected WIDTHxHEIGHT with each between 1 and {MAX_SIDE}, found '{s}'"
        )),
    }
}
