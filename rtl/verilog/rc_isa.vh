/* verilator lint_off UNUSEDPARAM */
// The RC context word's opcodes (docs/isa.md, section 1; the Rust source
// is rtl/src/rc/context.rs). Included by the unit files.
localparam [5:0] OP_NOP   = 6'h00, OP_ADD  = 6'h01, OP_ADC  = 6'h02, OP_SUB   = 6'h03,
                 OP_SBC   = 6'h04, OP_RSB  = 6'h05, OP_ADDS = 6'h06, OP_SUBS  = 6'h07,
                 OP_AND   = 6'h08, OP_OR   = 6'h09, OP_XOR  = 6'h0A, OP_NOT   = 6'h0B,
                 OP_MOV   = 6'h0C, OP_MOVB = 6'h0D, OP_MIN  = 6'h0E, OP_MAX   = 6'h0F,
                 OP_ABS   = 6'h10, OP_ABSD = 6'h11, OP_NEG  = 6'h12, OP_CMP   = 6'h13,
                 OP_SEL   = 6'h14, OP_CLZ  = 6'h15,
                 OP_SLL   = 6'h18, OP_SRL  = 6'h19, OP_SRA  = 6'h1A, OP_ASL   = 6'h1B,
                 OP_MUL   = 6'h20, OP_MAC  = 6'h21, OP_MSU  = 6'h22, OP_ACC   = 6'h23,
                 OP_ACCH  = 6'h24, OP_ACCL = 6'h25, OP_LDACC = 6'h26,
                 OP_LD    = 6'h28, OP_ST   = 6'h29,
                 OP_SLEEP = 6'h30, OP_WAKE = 6'h31;

// Operand A sources (asrc): the RC's own register, its own output
// register; everything else (neighbours, lanes, FB) arrives on `ext`.
localparam [2:0] ASRC_REG = 3'd0, ASRC_OUT = 3'd1;

// Guards.
localparam [1:0] GUARD_ALWAYS = 2'd0, GUARD_F = 2'd1, GUARD_NOT_F = 2'd2;
/* verilator lint_on UNUSEDPARAM */
