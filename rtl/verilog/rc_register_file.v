// The RC register file (rtl/src/rc/register_file.rs): 16 words of W bits,
// two read ports (operands A and B), one write port at the clock edge.
// `state` shows every register (for the co-simulation; unconnected in a
// chip it costs nothing).
module rc_register_file #(
    parameter W = 16
) (
    input  wire          clk,
    input  wire [3:0]    ra,
    input  wire [3:0]    rb,
    output wire [W-1:0]  a,
    output wire [W-1:0]  b,
    input  wire          we,
    input  wire [3:0]    rd,
    input  wire [W-1:0]  d,
    output wire [16*W-1:0] state
`ifdef COSIM
    ,
    input  wire [3:0]    peek_k,    // a third read port for the test bench
    output wire [W-1:0]  peek_q
`endif
);
    reg [W-1:0] r [0:15];

    assign a = r[ra];
    assign b = r[rb];

    always @(posedge clk)
        if (we) r[rd] <= d;

    genvar k;
    generate
        for (k = 0; k < 16; k = k + 1) begin : show
            assign state[k*W +: W] = r[k];
        end
    endgenerate

`ifdef COSIM
    assign peek_q = r[peek_k];
`endif
`ifndef SYNTHESIS
    integer i;
    initial for (i = 0; i < 16; i = i + 1) r[i] = {W{1'b0}};
`endif
endmodule
