// The RC's multiplier with its accumulator (rtl/src/rc/multiplier.rs): a
// W x W signed multiplier into the 2W-bit accumulator ACC.
//
//   mul         ACC = a * b
//   mac / msu   ACC = sat(ACC +/- a * b)
//   ldacc       ACC = sat(a * 2^sh)
//   mul mac msu acc   result sat_W(round(ACC >> sh)), V = saturated
//                     (mac / msu: the accumulator's saturation too), C = 0
//   acch / accl       the accumulator's upper / lower word
//
// round adds 2^(sh-1) before the arithmetic shift (ties towards +inf);
// `trunc` floors. The new ACC is written at the clock edge when `acc_we`.
module rc_multiplier #(
    parameter W = 16
) (
    input  wire           clk,
    input  wire [5:0]     op,
    input  wire [W-1:0]   a,
    input  wire [W-1:0]   b,
    input  wire [5:0]     sh,
    input  wire           trunc,
    input  wire           acc_we,
    output reg  [W-1:0]   res,
    output reg            v_out,
    output reg  [2*W-1:0] acc
);
`include "rc_isa.vh"

    localparam A = 2 * W;                                 // accumulator bits
    /* verilator lint_off WIDTH */
    localparam [5:0] SMASK = A - 1;                       // shift field in use
    /* verilator lint_on WIDTH */
    localparam [A-1:0] AMAX = {1'b0, {(A-1){1'b1}}};
    localparam [A-1:0] AMIN = {1'b1, {(A-1){1'b0}}};
    localparam [W-1:0] MAX = {1'b0, {(W-1){1'b1}}};
    localparam [W-1:0] MIN = {1'b1, {(W-1){1'b0}}};

    // The full product (exact in 2W bits: MIN * MIN = 2^(2W-2)).
    wire signed [A-1:0] p = $signed(a) * $signed(b);

    // ACC +/- p, saturating.
    wire        msu = op == OP_MSU;
    wire [A-1:0] q = msu ? -p : p;
    wire [A-1:0] sum = acc + q;
    wire         acc_ovf = ~(acc[A-1] ^ q[A-1]) & (acc[A-1] ^ sum[A-1]);
    wire [A-1:0] acc_sat = acc_ovf ? (acc[A-1] ? AMIN : AMAX) : sum;

    // ldacc: a * 2^sh saturates where shifting back does not give a
    // again (sh < 2W: the shift field is masked to the accumulator).
    wire [5:0]   lsh = sh & SMASK;
    wire [A-1:0] a_ext = {{W{a[W-1]}}, a};
    wire [A-1:0] ld_up = a_ext << lsh;
    wire         ld_fits = ($signed(ld_up) >>> lsh) == $signed(a_ext);
    wire [A-1:0] ld = ld_fits ? ld_up : a[W-1] ? AMIN : AMAX;

    reg [A-1:0] acc_d;
    always @* begin
        case (op)
            OP_MUL:         acc_d = p;
            OP_MAC, OP_MSU: acc_d = acc_sat;
            OP_LDACC:       acc_d = ld;
            default:        acc_d = acc;
        endcase
    end

    // The output stage: the new accumulator (the old one for `acc`)
    // shifted right by sh, rounded unless truncating, saturated to W bits.
    wire [A-1:0]        x = (op == OP_ACC) ? acc : acc_d;
    wire [5:0]          s = sh & SMASK;
    /* verilator lint_off UNUSEDSIGNAL */
    wire [5:0]          s1 = s - 6'd1;
    /* verilator lint_on UNUSEDSIGNAL */
    wire signed [A-1:0] shifted = $signed(x) >>> s;
    wire                round = ~trunc & (s != 6'd0) & x[s1[$clog2(A)-1:0]];
    wire signed [A-1:0] w = shifted + {{(A-1){1'b0}}, round};
    wire scale_hi = w > $signed({{W{1'b0}}, MAX});
    wire scale_lo = w < $signed({{W{1'b1}}, MIN});
    wire [W-1:0] scaled = scale_hi ? MAX : scale_lo ? MIN : w[W-1:0];

    always @* begin
        res = scaled;
        v_out = scale_hi | scale_lo;
        case (op)
            OP_MAC, OP_MSU: v_out = scale_hi | scale_lo | acc_ovf;
            OP_ACCH:        res = acc[A-1:W];
            OP_ACCL:        res = acc[W-1:0];
            default: ;
        endcase
    end

    always @(posedge clk)
        if (acc_we) acc <= acc_d;

`ifndef SYNTHESIS
    initial acc = {A{1'b0}};
`endif
endmodule
