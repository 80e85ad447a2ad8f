// The RC interconnect (rtl/src/interconnect.rs): what operand A of each RC
// reads when its context names an interconnect source, from the output
// registers of the start of the cycle. RC i is row i / 8, column i % 8.
//
//   n s w e   (asrc 2, ra 0..3)  the neighbour north / south / west / east;
//                                edges wrap (the array is a torus)
//   qrowK     (asrc 3)           same row and quadrant, quadrant column K
//   qcolK     (asrc 4)           same column and quadrant, quadrant row K
//   xrowK     (asrc 5)           same row, column K
//   xcolK     (asrc 6)           same column, row K
//   fbK       (asrc 7)           the frame-buffer datum of set K
//
// Each RC selects with its own context's fields (in row or column mode
// the rows or columns run different contexts).
module rc_interconnect #(
    parameter W = 16
) (
    input  wire [64*W-1:0] outs,
    input  wire [64*3-1:0] asrc,
    input  wire [64*3-1:0] ra,       // each RC's ra[2:0]
    input  wire [W-1:0]    fb0,
    input  wire [W-1:0]    fb1,
    output wire [64*W-1:0] ext
);
    genvar i;
    generate
        for (i = 0; i < 64; i = i + 1) begin : lane
            localparam R = i / 8, C = i % 8;
            wire [2:0] s = asrc[3*i +: 3];
            wire [2:0] k = ra[3*i +: 3];
            // the sources' lane numbers
            localparam NORTH = ((R + 7) % 8) * 8 + C, SOUTH = ((R + 1) % 8) * 8 + C,
                       WEST = R * 8 + (C + 7) % 8, EAST = R * 8 + (C + 1) % 8,
                       QROW = R * 8 + (C / 4) * 4, QCOL = ((R / 4) * 4) * 8 + C;
            // Each source is a fixed wire: a multiplexer of the 26 outputs
            // this RC can reach (not of all 64).
            reg [W-1:0] a;
            always @* begin
                case (s)
                    3'd2: case (k[1:0])
                        2'd0: a = outs[W*NORTH +: W];
                        2'd1: a = outs[W*SOUTH +: W];
                        2'd2: a = outs[W*WEST +: W];
                        default: a = outs[W*EAST +: W];
                    endcase
                    3'd3: case (k[1:0])
                        2'd0: a = outs[W*(QROW + 0) +: W];
                        2'd1: a = outs[W*(QROW + 1) +: W];
                        2'd2: a = outs[W*(QROW + 2) +: W];
                        default: a = outs[W*(QROW + 3) +: W];
                    endcase
                    3'd4: case (k[1:0])
                        2'd0: a = outs[W*(QCOL + 0) +: W];
                        2'd1: a = outs[W*(QCOL + 8) +: W];
                        2'd2: a = outs[W*(QCOL + 16) +: W];
                        default: a = outs[W*(QCOL + 24) +: W];
                    endcase
                    3'd5: case (k)
                        3'd0: a = outs[W*(R*8 + 0) +: W];
                        3'd1: a = outs[W*(R*8 + 1) +: W];
                        3'd2: a = outs[W*(R*8 + 2) +: W];
                        3'd3: a = outs[W*(R*8 + 3) +: W];
                        3'd4: a = outs[W*(R*8 + 4) +: W];
                        3'd5: a = outs[W*(R*8 + 5) +: W];
                        3'd6: a = outs[W*(R*8 + 6) +: W];
                        default: a = outs[W*(R*8 + 7) +: W];
                    endcase
                    3'd6: case (k)
                        3'd0: a = outs[W*(0*8 + C) +: W];
                        3'd1: a = outs[W*(1*8 + C) +: W];
                        3'd2: a = outs[W*(2*8 + C) +: W];
                        3'd3: a = outs[W*(3*8 + C) +: W];
                        3'd4: a = outs[W*(4*8 + C) +: W];
                        3'd5: a = outs[W*(5*8 + C) +: W];
                        3'd6: a = outs[W*(6*8 + C) +: W];
                        default: a = outs[W*(7*8 + C) +: W];
                    endcase
                    3'd7: a = k[0] ? fb1 : fb0;
                    default: a = {W{1'b0}};          // rN, out: the RC's own
                endcase
            end
            assign ext[W*i +: W] = a;
        end
    endgenerate
endmodule
