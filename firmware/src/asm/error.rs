//! The assembler's errors: each at `file:line:col` with the offending
//! line and a caret, and a program's errors together (the first few shown,
//! then how many more).

use std::fmt;

/// An assembly error at `file:line:col`, with the offending line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AsmError {
    pub file: String,
    pub line: usize,
    pub col: usize,
    pub message: String,
    pub text: String,
}

impl fmt::Display for AsmError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "{}:{}:{}: error: {}",
            self.file, self.line, self.col, self.message
        )?;
        // Control characters shown as the replacement character, one
        // column each, so the caret stays under its column.
        let shown: String = self
            .text
            .chars()
            .map(|c| {
                if c.is_control() && c != '\t' {
                    '\u{FFFD}'
                } else {
                    c
                }
            })
            .collect();
        writeln!(f, "{:>5} | {shown}", self.line)?;
        let pad: String = self
            .text
            .chars()
            .take(self.col.saturating_sub(1))
            .map(|c| if c == '\t' { '\t' } else { ' ' })
            .collect();
        write!(f, "      | {pad}^")
    }
}

impl std::error::Error for AsmError {}

/// All errors of one assembly, printable as one block.
#[derive(Clone, Debug)]
pub struct AsmErrors(pub Vec<AsmError>);

/// Errors shown in full (each with its source line); the rest are
/// summed up in one line.
const ERRORS_SHOWN: usize = 3;

impl fmt::Display for AsmErrors {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, e) in self.0.iter().take(ERRORS_SHOWN).enumerate() {
            if i > 0 {
                writeln!(f)?;
            }
            write!(f, "{e}")?;
        }
        let rest = &self.0[self.0.len().min(ERRORS_SHOWN)..];
        if !rest.is_empty() {
            let mut undefined: Vec<&str> = Vec::new();
            for name in rest
                .iter()
                .filter_map(|e| e.message.strip_prefix("undefined symbol `"))
                .filter_map(|m| m.split('`').next())
            {
                if !undefined.contains(&name) {
                    undefined.push(name);
                }
            }
            let lines: Vec<usize> = rest.iter().map(|e| e.line).collect();
            write!(
                f,
                "\n... and {} more error{} (lines {}..={})",
                rest.len(),
                if rest.len() == 1 { "" } else { "s" },
                lines.iter().min().unwrap_or(&0),
                lines.iter().max().unwrap_or(&0)
            )?;
            if !undefined.is_empty() {
                let shown = undefined.len().min(8);
                write!(
                    f,
                    "; undefined: {}{}",
                    undefined[..shown].join(", "),
                    if undefined.len() > shown { ", ..." } else { "" }
                )?;
                if undefined.len() >= 10 {
                    write!(f, " (is the file cut short?)")?;
                }
            }
            writeln!(f)?;
        }
        Ok(())
    }
}

impl std::error::Error for AsmErrors {}
