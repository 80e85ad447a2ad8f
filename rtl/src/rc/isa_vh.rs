//! The Verilog RC's `rc_isa.vh` (`rtl/verilog/`): the opcodes, the operand
//! A sources the RC itself serves and the guards, written from the
//! operation table ([`super::context`]) so that the Verilog and the Rust
//! RC decode the same words. A test holds the committed file to it
//! (`UPDATE_GOLDEN=1 cargo test -p morphosys-rtl --lib isa_vh` rewrites
//! it).

use std::fmt::Write;

use super::context::{ASrc, Guard, Unit, ALL_OPS};

/// The text of `rc_isa.vh`.
pub fn text() -> String {
    let mut s = String::from(
        "/* verilator lint_off UNUSEDPARAM */\n\
         // The RC context word's opcodes, operand A sources and guards\n\
         // (docs/isa.md, section 1), written from the operation table in\n\
         // rtl/src/rc/context.rs by rtl/src/rc/isa_vh.rs. Included by the unit\n\
         // files.\n\n\
         // Opcodes, with the unit each runs on.\n\
         localparam [5:0]\n",
    );
    let width = ALL_OPS
        .iter()
        .map(|o| o.mnemonic().len())
        .max()
        .unwrap_or(0);
    for (i, op) in ALL_OPS.iter().enumerate() {
        let name = format!("OP_{}", op.mnemonic().to_uppercase());
        let end = if i + 1 == ALL_OPS.len() { ';' } else { ',' };
        let unit = match op.unit() {
            Unit::None => "none",
            Unit::Alu => "ALU",
            Unit::Shifter => "shifter",
            Unit::Multiplier => "multiplier",
            Unit::Ram => "RAM",
            Unit::Power => "sleep flag",
        };
        let _ = writeln!(
            s,
            "    {name:<w$} = 6'h{:02X}{end}  // {unit}",
            *op as u8,
            w = width + 3
        );
    }
    let _ = write!(
        s,
        "\n// Operand A sources (asrc): the RC's own register, its own output\n\
         // register; everything else (neighbours, lanes, FB) arrives on `ext`.\n\
         localparam [2:0] ASRC_REG = 3'd{}, ASRC_OUT = 3'd{};\n\n\
         // Guards.\n\
         localparam [1:0] GUARD_ALWAYS = 2'd{}, GUARD_F = 2'd{}, GUARD_NOT_F = 2'd{};\n\
         /* verilator lint_on UNUSEDPARAM */\n",
        ASrc::Reg as u8,
        ASrc::Out as u8,
        Guard::Always as u8,
        Guard::IfF as u8,
        Guard::IfNotF as u8,
    );
    s
}

#[cfg(test)]
mod tests {
    /// The committed `rc_isa.vh` is the one the table writes.
    #[test]
    fn committed_isa_vh_matches_the_table() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/verilog/rc_isa.vh");
        let want = super::text();
        if std::env::var_os("UPDATE_GOLDEN").is_some() {
            std::fs::write(path, &want).unwrap();
        }
        let have = std::fs::read_to_string(path).unwrap();
        assert!(
            have == want,
            "{path} differs from what rtl/src/rc/isa_vh.rs writes (UPDATE_GOLDEN=1 cargo test -p morphosys-rtl --lib isa_vh)"
        );
    }
}
