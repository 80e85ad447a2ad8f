// The RC's barrel shifter (rtl/src/rc/shifter.rs). The amount is operand
// B's low 5 bits (W = 16) or 6 bits (W = 32); shifts by W or more give 0
// (sll, srl) or the sign fill (sra). asl multiplies by 2^n and saturates,
// V = saturated.
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

    // asl: a * 2^min(n, W) in 2W + 1 bits is exact (|a| <= 2^(W-1)); a
    // non-zero a shifted by W or more saturates either way.
    wire [AW-1:0]      n_asl = big ? WN : n;
    wire signed [2*W:0] wide = $signed({{(W+1){a[W-1]}}, a}) <<< n_asl;
    wire over  = wide > $signed({{(W+1){1'b0}}, MAX});
    wire under = wide < $signed({{(W+1){1'b1}}, MIN});
    assign v_out = over | under;

    always @* begin
        case (op)
            OP_SLL:  res = big ? {W{1'b0}} : a << n;
            OP_SRL:  res = big ? {W{1'b0}} : a >> n;
            OP_SRA:  res = $signed(a) >>> n_sra;
            default: res = over ? MAX : under ? MIN : wide[W-1:0];   // asl
        endcase
    end
endmodule
