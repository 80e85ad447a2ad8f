//! Argument groups shared by several subcommands.

use clap::Args;

/// Which cycles and scopes a waveform records.
#[derive(Args, Clone, Debug, Default)]
pub struct TraceWindow {
    /// First cycle to trace.
    #[arg(long, value_name = "C", default_value_t = 0)]
    pub trace_from: u64,
    /// Number of cycles to trace (default: to the end).
    #[arg(long, value_name = "L")]
    pub trace_cycles: Option<u64>,
    /// Trace only these scopes: comma-separated dotted paths with `*` and
    /// `?` globs, e.g. `rc.alu,rc.flags` or `array.rc_r*_c0`.
    #[arg(long, value_name = "S", default_value = "", value_parser = parse_scope)]
    pub trace_scope: String,
}

fn parse_scope(s: &str) -> Result<String, String> {
    rtl::trace::check_scope_patterns(s)?;
    Ok(s.to_string())
}

impl TraceWindow {
    pub fn config(&self, path: std::path::PathBuf) -> rtl::trace::TraceConfig {
        let mut c = rtl::trace::TraceConfig::new(path);
        c.first = self.trace_from;
        c.count = self.trace_cycles;
        c.scope = self.trace_scope.clone();
        c
    }
}

/// `--datapath 16|32`: the RC datapath width of the simulated chip.
pub fn parse_datapath(s: &str) -> Result<rtl::rc::Datapath, String> {
    s.trim()
        .parse::<u32>()
        .ok()
        .and_then(rtl::rc::Datapath::from_bits)
        .ok_or_else(|| {
            format!("`{s}` is not a datapath width: 16 (the paper's chip) or 32 (the wide variant)")
        })
}
