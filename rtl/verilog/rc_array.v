// The 8x8 RC array (rtl/src/array.rs): 64 RCs (rc.v) and the
// interconnect (rc_interconnect.v), in the three broadcast modes:
//
//   mode 0  SIMD: context word 0 drives all 64 RCs
//   mode 1  row mode: row i executes word i
//   mode 2  column mode: column j executes word j
//
// With `active` low no RC executes (the broadcast unit is idle).
// Each RC's state is shown for the test bench (outs, the flag masks;
// regs, acc and a RAM word of every RC under COSIM).
module rc_array #(
    parameter W = 16
) (
    input  wire             clk,
    input  wire             active,
    input  wire [1:0]       mode,
    input  wire [8*32-1:0]  ctx,
    input  wire [W-1:0]     fb0,
    input  wire [W-1:0]     fb1,
    output wire [64*W-1:0]  outs,
    output wire [63:0]      f,
    output wire [63:0]      c,
    output wire [63:0]      v,
    output wire [63:0]      sleep,
    output wire [63:0]      executed,
    output wire [63:0]      fault
`ifdef COSIM
    ,
    // the test bench reads every RC's state through these: RAM word
    // peek_addr, and register peek_sel (0..15) or the accumulator's low
    // (16) or high (17) word
    input  wire [8:0]         peek_addr,
    output wire [64*W-1:0]    peek,
    input  wire [4:0]         peek_sel,
    output wire [64*W-1:0]    peek_state
`endif
);
    wire [64*3-1:0] asrc;
    wire [64*3-1:0] ra;
    wire [64*W-1:0] ext;

    rc_interconnect #(.W(W)) ic (
        .outs(outs), .asrc(asrc), .ra(ra), .fb0(fb0), .fb1(fb1), .ext(ext)
    );

    genvar i;
    generate
        for (i = 0; i < 64; i = i + 1) begin : rcs
            localparam R = i / 8, C = i % 8;
            wire [31:0] word = mode == 2'd1 ? ctx[32*R +: 32]
                             : mode == 2'd2 ? ctx[32*C +: 32]
                             : ctx[31:0];
            assign asrc[3*i +: 3] = word[18:16];
            assign ra[3*i +: 3]   = word[14:12];
            /* verilator lint_off UNUSEDSIGNAL */
            wire [2*W-1:0] acc;                               // the test bench's
            /* verilator lint_on UNUSEDSIGNAL */
`ifdef COSIM
            wire [W-1:0] reg_q;
            assign peek_state[W*i +: W] = peek_sel == 5'd16 ? acc[W-1:0]
                                        : peek_sel == 5'd17 ? acc[2*W-1:W] : reg_q;
`endif
            /* verilator lint_off PINCONNECTEMPTY */
            rc #(.W(W)) rc (
                .clk(clk), .ctx(word), .ext(ext[W*i +: W]), .lane_en(active),
                .out(outs[W*i +: W]), .f(f[i]), .c(c[i]), .v(v[i]),
                .sleep(sleep[i]),
                .acc(acc), .regs(),
`ifdef COSIM
                .peek_addr(peek_addr), .peek(peek[W*i +: W]),
                .peek_reg(peek_sel[3:0]), .peek_reg_q(reg_q),
`endif
                .illegal(), .en(executed[i]), .fault(fault[i]),
                .ram_we(), .ram_addr(), .ram_wdata()
            );
            /* verilator lint_on PINCONNECTEMPTY */
        end
    endgenerate
endmodule
