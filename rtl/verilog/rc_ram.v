// The RC's local RAM (rtl/src/rc/ram.rs): 512 words of W bits (16-bit:
// 1 KB, 32-bit: 2 KB), one access per cycle: a read in the cycle (`ld`
// writes it to `out` at the edge) or a write at the clock edge (`st`).
// Address checks (0..511) are the RC's (rc.v), never a wrap here.
module rc_ram #(
    parameter W = 16
) (
    input  wire         clk,
    input  wire [8:0]   addr,
    output wire [W-1:0] q,
    input  wire         we,
    input  wire [W-1:0] d
`ifdef COSIM
    ,
    input  wire [8:0]   peek_addr,  // a second read port for the test bench
    output wire [W-1:0] peek
`endif
);
    reg [W-1:0] m [0:511];

    assign q = m[addr];

    always @(posedge clk)
        if (we) m[addr] <= d;

`ifdef COSIM
    assign peek = m[peek_addr];
`endif
`ifndef SYNTHESIS
    integer i;
    initial for (i = 0; i < 512; i = i + 1) m[i] = {W{1'b0}};
`endif
endmodule
