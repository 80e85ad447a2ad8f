// The RC context decoder (rtl/src/rc/context.rs): one 32-bit context word
// into its fields, and whether the word is legal.
//
//  31    26 25 24 23 22   19 18  16 15  12 11 10           0
// +--------+-----+--+-------+------+------+--+--------------+
// |   op   |guard|we|  rd   | asrc |  ra  |bs|      f       |
// +--------+-----+--+-------+------+------+--+--------------+
//
// bs = 1: operand B is the 11-bit signed immediate f, the multiplier shift
// is 0. bs = 0: B is register f[3:0], the shift f[8:4] (W = 32: f[10] is
// its bit 5; W = 16: f[10] is reserved and a word with it set is illegal),
// f[9] truncates instead of rounding.
module rc_context #(
    parameter W = 16
) (
    input  wire [31:0]  ctx,
    output wire [5:0]   op,
    output wire [1:0]   guard,
    output wire         we,
    output wire [3:0]   rd,
    output wire [2:0]   asrc,
    output wire [3:0]   ra,
    output wire         bs,
    output wire [3:0]   rb,
    output wire [W-1:0] imm,
    output wire [5:0]   sh,
    output wire         trunc,
    output wire         illegal
);
`include "rc_isa.vh"

    wire [10:0] f = ctx[10:0];
    assign op    = ctx[31:26];
    assign guard = ctx[25:24];
    assign we    = ctx[23];
    assign rd    = ctx[22:19];
    assign asrc  = ctx[18:16];
    assign ra    = ctx[15:12];
    assign bs    = ctx[11];
    assign rb    = f[3:0];
    assign imm   = {{(W-11){f[10]}}, f};
    assign sh    = bs ? 6'd0 : {(W == 32) & f[10], f[8:4]};
    assign trunc = ~bs & f[9];

    reg legal_op;
    always @* begin
        case (op)
            OP_NOP, OP_ADD, OP_ADC, OP_SUB, OP_SBC, OP_RSB, OP_ADDS, OP_SUBS,
            OP_AND, OP_OR, OP_XOR, OP_NOT, OP_MOV, OP_MOVB, OP_MIN, OP_MAX,
            OP_ABS, OP_ABSD, OP_NEG, OP_CMP, OP_SEL, OP_CLZ,
            OP_SLL, OP_SRL, OP_SRA, OP_ASL,
            OP_MUL, OP_MAC, OP_MSU, OP_ACC, OP_ACCH, OP_ACCL, OP_LDACC,
            OP_LD, OP_ST, OP_SLEEP, OP_WAKE: legal_op = 1'b1;
            default: legal_op = 1'b0;
        endcase
    end
    assign illegal = ~legal_op | (guard == 2'd3) | (~bs & f[10] & (W == 16));
endmodule
