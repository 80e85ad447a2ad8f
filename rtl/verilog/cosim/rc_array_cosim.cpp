// Co-simulation harness for the Verilog array (rtl/verilog/rc_array.v),
// built by Verilator; the Rust side is tb/src/testbench/cosim.rs.
//
// stdin, one record per cycle (little-endian):
//   u32 control (bit 0 active, bits 2:1 mode), u32 ctx[8], u32 0,
//   u64 fb0, u64 fb1
// stdout, one record per cycle, after the clock edge:
//   u64 out[64], u64 masks f c v sleep executed fault
// At the end of the input: u64 regs[64][16], u64 acc[64], u64 ram[512][64].
//
// `rc_array_cosim --bench N` reads the whole stream first, then runs it N
// times and prints "cycles seconds" (the model alone, no comparison).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <vector>

#include "Vrc_array.h"
#include "verilated.h"
#include "bits.h"

#ifndef RC_W
#error "RC_W (16 or 32) must be defined"
#endif

struct In {
    uint32_t control, ctx[8], pad;
    uint64_t fb0, fb1;
};

static void drive(Vrc_array* a, const In& in) {
    a->active = in.control & 1;
    a->mode = (in.control >> 1) & 3;
    for (int k = 0; k < 8; ++k) a->ctx[k] = in.ctx[k];
    a->fb0 = in.fb0;
    a->fb1 = in.fb1;
}

static void cycle(Vrc_array* a) {
    a->clk = 0;
    a->eval();
    a->clk = 1;
    a->eval();
}

int main(int argc, char** argv) {
    auto context = std::make_unique<VerilatedContext>();
    auto a = std::make_unique<Vrc_array>(context.get());
    static char inbuf[1 << 16], outbuf[1 << 16];
    setvbuf(stdin, inbuf, _IOFBF, sizeof inbuf);
    setvbuf(stdout, outbuf, _IOFBF, sizeof outbuf);
    a->clk = 0;
    a->eval();
    In in;

    if (argc == 3 && std::strcmp(argv[1], "--bench") == 0) {
        long repeat = std::atol(argv[2]);
        std::vector<In> stream;
        while (fread(&in, sizeof in, 1, stdin) == 1) stream.push_back(in);
        auto t0 = std::chrono::steady_clock::now();
        for (long r = 0; r < repeat; ++r)
            for (const In& s : stream) {
                drive(a.get(), s);
                cycle(a.get());
            }
        double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        // keep the model's work observable
        uint64_t sum = 0;
        for (int i = 0; i < 64; ++i) sum += field(a->outs, i * RC_W, RC_W);
        printf("%ld %.6f %llu\n", (long)stream.size() * repeat, secs, (unsigned long long)sum);
        return 0;
    }

    uint64_t rec[70];
    while (fread(&in, sizeof in, 1, stdin) == 1) {
        drive(a.get(), in);
        a->clk = 0;
        a->eval();
        uint64_t executed = a->executed, fault = a->fault;
        a->clk = 1;
        a->eval();
        for (int i = 0; i < 64; ++i) rec[i] = field(a->outs, i * RC_W, RC_W);
        rec[64] = a->f;
        rec[65] = a->c;
        rec[66] = a->v;
        rec[67] = a->sleep;
        rec[68] = executed;
        rec[69] = fault;
        if (fwrite(rec, sizeof rec, 1, stdout) != 1) return 1;
    }
    // The final state through the peek ports: registers, accumulators.
    a->clk = 0;
    static uint64_t regs[64][16], acc[64];
    for (int k = 0; k < 18; ++k) {
        a->peek_sel = k;
        a->eval();
        for (int i = 0; i < 64; ++i) {
            uint64_t w = field(a->peek_state, i * RC_W, RC_W);
            if (k < 16)
                regs[i][k] = w;
            else
                acc[i] |= w << (k == 17 ? RC_W : 0);
        }
    }
    if (fwrite(regs, sizeof regs, 1, stdout) != 1 || fwrite(acc, sizeof acc, 1, stdout) != 1) return 1;
    for (int addr = 0; addr < 512; ++addr) {
        a->peek_addr = addr;
        a->eval();
        for (int i = 0; i < 64; ++i) {
            uint64_t w = field(a->peek, i * RC_W, RC_W);
            if (fwrite(&w, sizeof w, 1, stdout) != 1) return 1;
        }
    }
    fflush(stdout);
    a->final();
    return 0;
}
