// The RC's flag register (rtl/src/rc/flags.rs): F, the guard flag written
// by `cmp`; C carry / borrow and V overflow / saturation; sleep. Each is
// written at the clock edge only where the RC executed.
module rc_flags (
    input  wire clk,
    input  wire cv_we,      // an operation writing C and V executed
    input  wire c_d,
    input  wire v_d,
    input  wire f_we,       // `cmp` executed
    input  wire f_d,
    input  wire sleep_set,  // `sleep` executed
    input  wire sleep_clr,  // `wake` executed
    output reg  f,
    output reg  c,
    output reg  v,
    output reg  sleep
);
    always @(posedge clk) begin
        if (cv_we) begin
            c <= c_d;
            v <= v_d;
        end
        if (f_we) f <= f_d;
        if (sleep_set) sleep <= 1'b1;
        else if (sleep_clr) sleep <= 1'b0;
    end

`ifndef SYNTHESIS
    initial {f, c, v, sleep} = 4'b0;
`endif
endmodule
