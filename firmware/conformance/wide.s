; Conformance program for the 32-bit datapath (run with `morphosys run
; --datapath 32`): 32-bit FB words through DMA, lfb/sfb, the FB stream,
; the multiplier (shift above 31, acch/accl of the 64-bit accumulator),
; rcrisc and wfb. Expected values computed outside the chip (Python).
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .datapath 32
        .data
src:    .word 0x12345678, 0x01000000, 0x7FFFFFFF, 0x80000000, -100000
dst:    .space 256
        .ctx
ctx_start:
k_load: add r1, fb0, r0             ; r1 = 0x12345678
        add r2, fb0, r0             ; r2 = 2^24
        mul out, r1, r2, >>40       ; (0x12345678 << 24) >> 40 = 0x1234
k_acch: mul r3, r1, r1              ; ACC = 0x12345678^2 (64 bits)
        acch out
k_accl: accl out
k_big:  add out, r1, #-1024         ; 0x12345278
ctx_end:
        .text
_start:
        li r10, ctx_start
        li r11, 0
        ldctxt r10, r11, (ctx_end - ctx_start) / 4
        dwait
        ; 1: ldfb moves 4-byte words; lfb reads them whole
        li r2, 1
        li r10, src
        li r11, 0x0100
        ldfb r10, r11, 5
        dwait
        lfb r5, 0(r11)
        li r6, 0x12345678
        bne r5, r6, fail
        lfb r5, 3(r11)
        li r6, 0x80000000
        bne r5, r6, fail
        lfb r5, 4(r11)
        li r6, -100000
        bne r5, r6, fail
        ; 2: sfb stores all 32 bits
        li r2, 2
        li r6, 0x7654321F
        sfb r6, 8(r11)
        lfb r5, 8(r11)
        bne r5, r6, fail
        ; 3: the FB stream and a multiplier shift of 40
        li r2, 3
        li r3, (k_load - ctx_start) / 4
        sbcb r3, r11, 3
        rcrisc r5, r0, 37
        li r6, 0x1234
        bne r5, r6, fail
        ; 4: acch / accl of the 64-bit accumulator
        li r2, 4
        li r3, (k_acch - ctx_start) / 4
        cbcast r3, 2
        rcrisc r5, r0, 63
        li r6, 0x014B66DC
        bne r5, r6, fail
        li r3, (k_accl - ctx_start) / 4
        cbcast r3, 1
        rcrisc r5, r0, 0
        li r6, 0x1DF4D840
        bne r5, r6, fail
        ; 5: wfb writes 32-bit outputs, stfb moves 4-byte words out
        li r2, 5
        li r3, (k_big - ctx_start) / 4
        cbcast r3, 1
        li r11, 0x4000
        wfb r11, 0
        li r10, dst
        stfb r10, r11, 64
        dwait
        lw r5, 252(r10)
        li r6, 0x12345278
        bne r5, r6, fail
        lw r5, 0(r10)
        bne r5, r6, fail
pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
