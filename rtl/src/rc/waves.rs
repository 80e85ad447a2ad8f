//! The array as a waveform shows it: its context (word and operation,
//! in disassembly through translate filters), which RCs are awake and
//! have F set, and per RC its registers, output, accumulator and flags.

use super::context::{Context, Op};
use super::lanes::Mask;
use super::{LaneNames, RcArray, Word};
use crate::trace::{Display, Field, Filter, Probe, Traced};

fn op_text(v: u64) -> Option<String> {
    Op::from_bits(v as u8).map(|o| o.mnemonic().to_string())
}

fn ctx_text(v: u64) -> Option<String> {
    Context::decode_wide(v as u32).ok().map(|c| c.to_string())
}

/// Translate filter: opcode field to mnemonic.
pub(crate) static OP_FILTER: Filter = Filter {
    name: "rc_op",
    text: op_text,
};
/// Translate filter: context word to its disassembly.
pub(crate) static CTX_FILTER: Filter = Filter {
    name: "rc_ctx",
    text: ctx_text,
};

const REG_NAMES: [&str; 16] = [
    "r0", "r1", "r2", "r3", "r4", "r5", "r6", "r7", "r8", "r9", "r10", "r11", "r12", "r13", "r14",
    "r15",
];

impl<const N: usize, W: Word> Traced for RcArray<N, W> {
    fn trace<P: Probe>(&self, p: &mut P) {
        let c = &self.ctx;
        let en = self.enabled();
        // The array at a glance: its context, and which RCs are awake and
        // which have F set (bit i: RC i, row-major).
        p.block_with(
            &|| {
                vec![
                    Field::new("", "ctx", 32, Display::Translate(&CTX_FILTER)),
                    Field::new("", "op", 6, Display::Translate(&OP_FILTER)),
                    Field::new("", "awake", N as u32, Display::Hex),
                    Field::new("", "flag_f", N as u32, Display::Hex),
                ]
            },
            |v| {
                *v = [
                    self.ctx_word as u64,
                    c.op as u64,
                    !self.flags.sleep & Self::FULL,
                    self.flags.f & Self::FULL,
                ]
            },
        );
        let bits = W::BITS;
        let mask = |b: u32| if b >= 64 { u64::MAX } else { (1u64 << b) - 1 };
        let sig = |x: W| x.to_i64() as u64 & mask(bits);
        // Ask once which lanes' scopes are traced, then enter only those.
        let names = self.names;
        let mut wanted = p.open_scopes(N, &mut |i| names.name(i));
        // The set bits only (a trace of one RC does not test 64 bits).
        while wanted != 0 {
            let i = wanted.trailing_zeros() as usize;
            wanted &= wanted - 1;
            if i >= N {
                break;
            }
            let open = match self.names {
                LaneNames::Single => p.scope(format_args!("rc")),
                LaneNames::Grid => p.scope(format_args!("rc_r{}_c{}", i / 8, i % 8)),
            };
            if !open {
                continue;
            }
            // Two blocks per RC: out, alu, mul, flags and the register
            // file; ram.
            let bit = |m: Mask| m >> i & 1;
            let fill = |v: &mut [u64; 26]| {
                v[0] = sig(self.out[i]);
                v[1] = sig(self.operand_a(i));
                v[2] = sig(self.operand_b(i));
                v[3] = sig(self.res[i]);
                v[4] = bit(en);
                v[5] = W::acc_i128(self.acc[i]) as u64 & mask(2 * bits);
                v[6] = bit(self.flags.f);
                v[7] = bit(self.flags.c);
                v[8] = bit(self.flags.v);
                v[9] = bit(self.flags.sleep);
                for (k, r) in v[10..].iter_mut().enumerate() {
                    *r = sig(self.regs.r[k][i]);
                }
            };
            p.block_with(
                &|| {
                    let mut f = vec![
                        Field::new("", "out", bits, Display::Signed),
                        Field::new("alu", "a", bits, Display::Signed),
                        Field::new("alu", "b", bits, Display::Signed),
                        Field::new("alu", "result", bits, Display::Signed),
                        Field::new("alu", "en", 1, Display::Bin),
                        Field::new("mul", "acc", 2 * bits, Display::Signed),
                        Field::new("flags", "f", 1, Display::Bin),
                        Field::new("flags", "c", 1, Display::Bin),
                        Field::new("flags", "v", 1, Display::Bin),
                        Field::new("flags", "sleep", 1, Display::Bin),
                    ];
                    f.extend(REG_NAMES.map(|r| Field::new("regfile", r, bits, Display::Signed)));
                    f
                },
                fill,
            );
            let mem = matches!(c.op, Op::Ld | Op::St) && en >> i & 1 != 0;
            p.block_with(
                &|| {
                    vec![
                        Field::new("ram", "addr", 9, Display::Hex),
                        Field::new("ram", "we", 1, Display::Bin),
                    ]
                },
                |v| {
                    *v = [
                        if mem { self.ram_addr(i) as u64 } else { 0 },
                        (mem && c.op == Op::St) as u64,
                    ]
                },
            );
            p.end();
        }
    }
}
