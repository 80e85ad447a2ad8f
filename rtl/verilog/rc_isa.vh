/* verilator lint_off UNUSEDPARAM */
// The RC context word's opcodes, operand A sources and guards
// (docs/isa.md, section 1), written from the operation table in
// rtl/src/rc/context.rs by rtl/src/rc/isa_vh.rs. Included by the unit
// files.

// Opcodes, with the unit each runs on.
localparam [5:0]
    OP_NOP   = 6'h00,  // none
    OP_ADD   = 6'h01,  // ALU
    OP_ADC   = 6'h02,  // ALU
    OP_SUB   = 6'h03,  // ALU
    OP_SBC   = 6'h04,  // ALU
    OP_RSB   = 6'h05,  // ALU
    OP_ADDS  = 6'h06,  // ALU
    OP_SUBS  = 6'h07,  // ALU
    OP_AND   = 6'h08,  // ALU
    OP_OR    = 6'h09,  // ALU
    OP_XOR   = 6'h0A,  // ALU
    OP_NOT   = 6'h0B,  // ALU
    OP_MOV   = 6'h0C,  // ALU
    OP_MOVB  = 6'h0D,  // ALU
    OP_MIN   = 6'h0E,  // ALU
    OP_MAX   = 6'h0F,  // ALU
    OP_ABS   = 6'h10,  // ALU
    OP_ABSD  = 6'h11,  // ALU
    OP_NEG   = 6'h12,  // ALU
    OP_CMP   = 6'h13,  // ALU
    OP_SEL   = 6'h14,  // ALU
    OP_CLZ   = 6'h15,  // ALU
    OP_SLL   = 6'h18,  // shifter
    OP_SRL   = 6'h19,  // shifter
    OP_SRA   = 6'h1A,  // shifter
    OP_ASL   = 6'h1B,  // shifter
    OP_MUL   = 6'h20,  // multiplier
    OP_MAC   = 6'h21,  // multiplier
    OP_MSU   = 6'h22,  // multiplier
    OP_ACC   = 6'h23,  // multiplier
    OP_ACCH  = 6'h24,  // multiplier
    OP_ACCL  = 6'h25,  // multiplier
    OP_LDACC = 6'h26,  // multiplier
    OP_LD    = 6'h28,  // RAM
    OP_ST    = 6'h29,  // RAM
    OP_SLEEP = 6'h30,  // sleep flag
    OP_WAKE  = 6'h31;  // sleep flag

// Operand A sources (asrc): the RC's own register, its own output
// register; everything else (neighbours, lanes, FB) arrives on `ext`.
localparam [2:0] ASRC_REG = 3'd0, ASRC_OUT = 3'd1;

// Guards.
localparam [1:0] GUARD_ALWAYS = 2'd0, GUARD_F = 2'd1, GUARD_NOT_F = 2'd2;
/* verilator lint_on UNUSEDPARAM */
