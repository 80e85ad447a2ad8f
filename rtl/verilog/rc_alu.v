// The RC's arithmetic-logic unit (rtl/src/rc/alu.rs), W bits two's
// complement. Combinational: the operation's result and its C / V, and the
// condition of `cmp`.
//
// C is the carry out of the top bit for additions and the borrow for
// subtractions (the unsigned subtrahend plus borrow-in exceeds the
// minuend); V the signed overflow, or for the saturating operations
// (adds subs abs absd) whether the result saturated, with C = 0.
module rc_alu #(
    parameter W = 16
) (
    input  wire [5:0]   op,
    input  wire [3:0]   cond,     // the `rd` field of `cmp`
    input  wire [W-1:0] a,
    input  wire [W-1:0] b,
    input  wire         f,        // the RC's flags as they are this cycle
    input  wire         c,
    input  wire         v,
    output reg  [W-1:0] res,
    output reg          c_out,
    output reg          v_out,
    output reg          cond_true
);
`include "rc_isa.vh"

    localparam [W-1:0] MAX = {1'b0, {(W-1){1'b1}}};
    localparam [W-1:0] MIN = {1'b1, {(W-1){1'b0}}};

    // One adder for add, adc and the subtractions (x - y - bin is
    // x + ~y + ~bin), W + 1 bits wide for the carry.
    reg          sub;
    reg [W-1:0]  x, y;
    reg          cin;
    always @* begin
        sub = 1'b0; x = a; y = b; cin = 1'b0;
        case (op)
            OP_ADC: cin = c;
            OP_SUB: sub = 1'b1;
            OP_SBC: begin sub = 1'b1; cin = c; end
            OP_RSB: begin sub = 1'b1; x = b; y = a; end
            OP_NEG: begin sub = 1'b1; x = {W{1'b0}}; y = a; end
            default: ;
        endcase
    end
    wire [W:0]   sum = {1'b0, x} + {1'b0, sub ? ~y : y} + {{W{1'b0}}, sub ? ~cin : cin};
    wire [W-1:0] s = sum[W-1:0];
    wire         carry = sub ? ~sum[W] : sum[W];          // borrow for subtractions
    wire         ovf = sub ? ((x[W-1] ^ y[W-1]) & (x[W-1] ^ s[W-1]))
                           : (~(x[W-1] ^ y[W-1]) & (x[W-1] ^ s[W-1]));

    // Saturating add / subtract: the wrapped sum clamped on overflow
    // towards the sign of a.
    wire [W-1:0] wadd = a + b;
    wire [W-1:0] wsub = a - b;
    wire         oadd = ~(a[W-1] ^ b[W-1]) & (a[W-1] ^ wadd[W-1]);
    wire         osub = (a[W-1] ^ b[W-1]) & (a[W-1] ^ wsub[W-1]);
    wire [W-1:0] clamp = a[W-1] ? MIN : MAX;

    // Signed comparisons.
    wire lt  = $signed(a) < $signed(b);
    wire ltu = a < b;
    wire eq  = a == b;

    // |a - b| as an unsigned word: the larger minus the smaller.
    wire [W-1:0] d_hi   = lt ? b : a;
    wire [W-1:0] d_lo = lt ? a : b;
    wire [W-1:0] d_abs  = d_hi - d_lo;
    wire         d_sat = d_abs[W-1];                    // above MAX

    // Leading zeros.
    /* verilator lint_off WIDTH */
    localparam [W-1:0] WV = W;
    /* verilator lint_on WIDTH */
    reg [W-1:0] lz;
    reg         found;
    integer     i;
    always @* begin
        lz = WV;
        found = 1'b0;
        for (i = W - 1; i >= 0; i = i - 1)
            if (!found && a[i]) begin
                lz = WV - 1 - i[W-1:0];
                found = 1'b1;
            end
    end

    always @* begin
        case (cond)
            4'd0:  cond_true = eq;
            4'd1:  cond_true = ~eq;
            4'd2:  cond_true = lt;
            4'd3:  cond_true = ~lt;
            4'd4:  cond_true = lt | eq;
            4'd5:  cond_true = ~(lt | eq);
            4'd6:  cond_true = ltu;
            4'd7:  cond_true = ~ltu;
            4'd8:  cond_true = ltu | eq;
            4'd9:  cond_true = ~(ltu | eq);
            4'd10: cond_true = c;
            4'd11: cond_true = v;
            4'd12: cond_true = 1'b1;
            4'd13: cond_true = 1'b0;
            4'd14: cond_true = |(a & b);
            default: cond_true = ~|(a & b);
        endcase
    end

    always @* begin
        res = s;
        c_out = carry;
        v_out = ovf;
        case (op)
            OP_ADDS: begin res = oadd ? clamp : wadd; c_out = 1'b0; v_out = oadd; end
            OP_SUBS: begin res = osub ? clamp : wsub; c_out = 1'b0; v_out = osub; end
            OP_ABS: begin
                res = (a == MIN) ? MAX : (a[W-1] ? -a : a);
                c_out = 1'b0;
                v_out = a == MIN;
            end
            OP_ABSD: begin res = d_sat ? MAX : d_abs; c_out = 1'b0; v_out = d_sat; end
            OP_AND:  res = a & b;
            OP_OR:   res = a | b;
            OP_XOR:  res = a ^ b;
            OP_NOT:  res = ~a;
            OP_MOV:  res = a;
            OP_MOVB: res = b;
            OP_MIN:  res = lt ? a : b;
            OP_MAX:  res = lt ? b : a;
            OP_SEL:  res = f ? a : b;
            OP_CLZ:  res = lz;
            default: ;
        endcase
    end
endmodule
