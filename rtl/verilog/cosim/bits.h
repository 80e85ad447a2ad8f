// What both Verilator harnesses share: reading a field of a wide signal.
#pragma once
#include <cstdint>

// Bits [bit, bit + width) of a signal held as 32-bit words (a Verilator
// VlWide, or any array of words), zero-extended.
template <typename T>
static uint64_t field(const T& words, int bit, int width) {
    uint64_t v = 0;
    for (int i = 0; i < width; ++i) {
        int b = bit + i;
        v |= (uint64_t)((words[b / 32] >> (b % 32)) & 1u) << i;
    }
    return v;
}
