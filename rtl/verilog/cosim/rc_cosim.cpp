// Co-simulation harness for the Verilog RC (rtl/verilog/rc.v), built by
// Verilator. The Rust side (tb/src/testbench/cosim.rs) drives it through
// pipes and compares it with the Rust RC cycle by cycle.
//
// stdin, one record per cycle (little-endian):
//   u32 ctx, u32 lane_en, u64 ext
// stdout, one record per cycle, the state after the clock edge and what
// the cycle did:
//   u64 out, u64 regs[16], u64 acc, u64 ram_wdata,
//   u32 bits (f c v sleep illegal en fault ram_we, bit 0 first), u32 ram_addr
// At the end of the input: u64 ram[512], the whole RAM.
// Values are bit patterns, zero-extended.
#include <cstdint>
#include <cstdio>
#include <memory>

#include "Vrc.h"
#include "verilated.h"
#include "bits.h"

#ifndef RC_W
#error "RC_W (16 or 32) must be defined"
#endif

int main(int argc, char** argv) {
    auto context = std::make_unique<VerilatedContext>();
    context->commandArgs(argc, argv);
    auto rc = std::make_unique<Vrc>(context.get());
    static char inbuf[1 << 16], outbuf[1 << 16];
    setvbuf(stdin, inbuf, _IOFBF, sizeof inbuf);
    setvbuf(stdout, outbuf, _IOFBF, sizeof outbuf);

    rc->clk = 0;
    rc->eval();
    struct {
        uint32_t ctx, lane_en;
        uint64_t ext;
    } in;
    struct {
        uint64_t out, regs[16], acc, ram_wdata;
        uint32_t bits, ram_addr;
    } st;
    while (fread(&in, sizeof in, 1, stdin) == 1) {
        rc->ctx = in.ctx;
        rc->lane_en = in.lane_en & 1;
        rc->ext = in.ext;
        rc->clk = 0;
        rc->eval();
        // what the cycle does, before the edge
        uint32_t bits = (rc->illegal ? 16u : 0u) | (rc->en ? 32u : 0u) |
                        (rc->fault ? 64u : 0u) | (rc->ram_we ? 128u : 0u);
        st.ram_addr = rc->ram_addr;
        st.ram_wdata = rc->ram_wdata;
        rc->clk = 1;
        rc->eval();
        st.out = rc->out;
        for (int k = 0; k < 16; ++k) st.regs[k] = field(rc->regs, k * RC_W, RC_W);
        st.acc = rc->acc;
        st.bits = bits | (rc->f ? 1u : 0u) | (rc->c ? 2u : 0u) | (rc->v ? 4u : 0u) |
                  (rc->sleep ? 8u : 0u);
        if (fwrite(&st, sizeof st, 1, stdout) != 1) return 1;
    }
    rc->clk = 0;
    for (int a = 0; a < 512; ++a) {
        rc->peek_addr = a;
        rc->eval();
        uint64_t w = rc->peek;
        if (fwrite(&w, sizeof w, 1, stdout) != 1) return 1;
    }
    fflush(stdout);
    rc->final();
    return 0;
}
