// One Reconfigurable Cell (rtl/src/rc/mod.rs, docs/isa.md section 1),
// W = 16 (the paper's chip) or 32 (the wide variant). One context word a
// cycle; every operation takes one cycle: the operands are read, the unit
// computes, and at the rising edge the result goes to `out` (and to
// register rd with `we`), the flags, the accumulator or the RAM.
//
// Operand A is register ra, the RC's own `out`, or `ext`: the value the
// array around the RC routes to it for the interconnect sources (n s w e,
// qrowK, qcolK, xrowK, xcolK) and the frame-buffer datum (fbK).
// `lane_en` is the array's row / column mode enable.
//
// A context executes where its guard passes (always, F, !F) and the RC is
// awake (`wake` reaches sleeping RCs). An illegal word executes nowhere
// (the chip faults at its decode, `illegal`); a `ld` / `st` address outside
// 0..511 in an executing RC writes nothing and raises `fault` (the chip
// stops with a fault naming the RC).
module rc #(
    parameter W = 16
) (
    input  wire          clk,
    input  wire [31:0]   ctx,
    input  wire [W-1:0]  ext,
    input  wire          lane_en,
    output reg  [W-1:0]  out,
    // the state, for the array (out, the flags) and the test bench
    output wire          f,
    output wire          c,
    output wire          v,
    output wire          sleep,
    output wire [2*W-1:0] acc,
    output wire [16*W-1:0] regs,
    // this cycle
    output wire          illegal,
    output wire          en,        // the context executes here
    output wire          fault,
    output wire          ram_we,
    output wire [8:0]    ram_addr,
    output wire [W-1:0]  ram_wdata
`ifdef COSIM
    ,
    input  wire [8:0]    peek_addr,  // test bench: a RAM word
    output wire [W-1:0]  peek,
    input  wire [3:0]    peek_reg,   // and a register
    output wire [W-1:0]  peek_reg_q
`endif
);
`include "rc_isa.vh"

    // ---- decode ----
    wire [5:0] op;
    wire [1:0] guard;
    wire       we;
    wire [3:0] rd, ra, rb;
    wire [2:0] asrc;
    wire       bs, trunc;
    wire [W-1:0] imm;
    wire [5:0] sh;
    rc_context #(.W(W)) dec (
        .ctx(ctx), .op(op), .guard(guard), .we(we), .rd(rd), .asrc(asrc),
        .ra(ra), .bs(bs), .rb(rb), .imm(imm), .sh(sh), .trunc(trunc),
        .illegal(illegal)
    );

    // ---- operands ----
    wire [W-1:0] rf_a, rf_b;
    wire [W-1:0] a = (asrc == ASRC_REG) ? rf_a : (asrc == ASRC_OUT) ? out : ext;
    wire [W-1:0] b = bs ? imm : rf_b;

    // ---- guard and sleep ----
    wire pass = (guard == GUARD_ALWAYS) | (guard == GUARD_F & f) | (guard == GUARD_NOT_F & ~f);
    assign en = ~illegal & pass & lane_en & (op == OP_WAKE | ~sleep);

    // ---- units ----
    wire [W-1:0] alu_res, sh_res, mul_res, ram_q;
    wire         alu_c, alu_v, cond, sh_v, mul_v;
    rc_alu #(.W(W)) alu (
        .op(op), .cond(rd), .a(a), .b(b), .f(f), .c(c), .v(v),
        .res(alu_res), .c_out(alu_c), .v_out(alu_v), .cond_true(cond)
    );
    rc_shifter #(.W(W)) shifter (.op(op), .a(a), .b(b), .res(sh_res), .v_out(sh_v));

    // RAM address: ld [A + B], st [B]; checked, not wrapped.
    wire         is_ld = op == OP_LD;
    wire         is_st = op == OP_ST;
    wire [W:0]   addr_sum = is_st ? {b[W-1], b} : {a[W-1], a} + {b[W-1], b};
    wire         addr_ok = addr_sum[W:9] == 0;
    assign fault = en & (is_ld | is_st) & ~addr_ok;
    wire   ex = en & ~fault;                          // the clock edge writes

    wire is_mul = op == OP_MUL | op == OP_MAC | op == OP_MSU;
    rc_multiplier #(.W(W)) mul (
        .clk(clk), .op(op), .a(a), .b(b), .sh(sh), .trunc(trunc),
        .acc_we(ex & (is_mul | op == OP_LDACC)),
        .res(mul_res), .v_out(mul_v), .acc(acc)
    );

    assign ram_addr  = addr_sum[8:0];
    assign ram_we    = ex & is_st;
    assign ram_wdata = a;
    rc_ram #(.W(W)) ram (
        .clk(clk), .addr(ram_addr), .q(ram_q), .we(ram_we), .d(ram_wdata)
`ifdef COSIM
        , .peek_addr(peek_addr), .peek(peek)
`endif
    );

    // ---- result ----
    wire is_shift = op[5:2] == 4'b0110;                 // 0x18..0x1B
    wire is_mulres = op[5:3] == 3'b100;                 // 0x20..0x26
    wire [W-1:0] res = is_ld ? ram_q : is_mulres ? mul_res : is_shift ? sh_res : alu_res;
    wire has_result = ~(op == OP_NOP | op == OP_CMP | is_st | op == OP_SLEEP
                        | op == OP_WAKE | op == OP_LDACC);

    // Operations writing C and V: the add / subtract family, the
    // saturating ones, asl and the multiplier's scaled results.
    reg writes_cv;
    always @* begin
        case (op)
            OP_ADD, OP_ADC, OP_SUB, OP_SBC, OP_RSB, OP_NEG,
            OP_ADDS, OP_SUBS, OP_ABS, OP_ABSD, OP_ASL,
            OP_MUL, OP_MAC, OP_MSU, OP_ACC: writes_cv = 1'b1;
            default: writes_cv = 1'b0;
        endcase
    end
    wire c_d = is_mulres | op == OP_ASL ? 1'b0 : alu_c;
    wire v_d = is_mulres ? mul_v : op == OP_ASL ? sh_v : alu_v;

    rc_register_file #(.W(W)) regfile (
        .clk(clk), .ra(ra), .rb(rb), .a(rf_a), .b(rf_b),
        .we(ex & has_result & we), .rd(rd), .d(res), .state(regs)
`ifdef COSIM
        , .peek_k(peek_reg), .peek_q(peek_reg_q)
`endif
    );

    rc_flags flags (
        .clk(clk), .cv_we(ex & writes_cv), .c_d(c_d), .v_d(v_d),
        .f_we(ex & op == OP_CMP), .f_d(cond),
        .sleep_set(ex & op == OP_SLEEP), .sleep_clr(ex & op == OP_WAKE),
        .f(f), .c(c), .v(v), .sleep(sleep)
    );

    always @(posedge clk)
        if (ex & has_result) out <= res;

`ifndef SYNTHESIS
    initial out = {W{1'b0}};
`endif
endmodule
