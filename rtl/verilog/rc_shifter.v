// The RC's barrel shifter (rtl/src/rc/shifter.rs). The amount is operand
// B's low 5 bits (W = 16) or 6 bits (W = 32); shifts by W or more give 0
// (sll, srl) or the sign fill (sra). asl multiplies by 2^n and saturates,
// V = saturated. Nothing is wider than the word.
module rc_shifter #(
    parameter W = 16
) (
    input  wire [5:0]   op,
    input  wire [W-1:0] a,
    /* verilator lint_off UNUSEDSIGNAL */
    input  wire [W-1:0] b,                // the amount: its low bits
    /* verilator lint_on UNUSEDSIGNAL */
    output reg  [W-1:0] res,
    output wire         v_out
);
`include "rc_isa.vh"

    localparam AW = (W == 32) ? 6 : 5;                   // amount bits
    /* verilator lint_off WIDTH */
    localparam [AW-1:0] WN = W;                           // the width as an amount
    localparam [AW-1:0] WN1 = W - 1;
    /* verilator lint_on WIDTH */
    localparam [W-1:0] MAX = {1'b0, {(W-1){1'b1}}};
    localparam [W-1:0] MIN = {1'b1, {(W-1){1'b0}}};

    wire [AW-1:0] n = b[AW-1:0];
    wire          big = n >= WN;                           // the whole word out
    wire [AW-1:0] n_sra = big ? WN1 : n;

    // asl: a * 2^n saturates where shifting back does not give a again
    // (a bit unlike the sign left the word); a non-zero a shifted by W or
    // more always does, towards its sign.
    wire [W-1:0] up = a << n;
    wire         fits = ~big & (($signed(up) >>> n) == $signed(a));
    wire         sat = (a != {W{1'b0}}) & ~fits;
    assign v_out = sat;

    always @* begin
        case (op)
            OP_SLL:  res = big ? {W{1'b0}} : a << n;
            OP_SRL:  res = big ? {W{1'b0}} : a >> n;
            OP_SRA:  res = $signed(a) >>> n_sra;
            default: res = ~sat ? up : a[W-1] ? MIN : MAX;             // asl
        endcase
    end
endmodule
