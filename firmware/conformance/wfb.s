; Conformance program: wfb, the 64 RC outputs written to the frame buffer
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .ctx
ctx_start:
; lane id: r1 = 8 row + column (row mode then column mode), r5 = row
g_row:
        movb r1, #0
        movb r1, #8
        movb r1, #16
        movb r1, #24
        movb r1, #32
        movb r1, #40
        movb r1, #48
        movb r1, #56
g_row5:
        movb r5, #0
        movb r5, #1
        movb r5, #2
        movb r5, #3
        movb r5, #4
        movb r5, #5
        movb r5, #6
        movb r5, #7
g_col:
        add r1, r1, #0
        add r1, r1, #1
        add r1, r1, #2
        add r1, r1, #3
        add r1, r1, #4
        add r1, r1, #5
        add r1, r1, #6
        add r1, r1, #7
k_sq:   mul out, r1, r1          ; out = lane^2
ctx_end:
        .text
_start:
        li r10, ctx_start
        li r11, 0
        ldctxt r10, r11, (ctx_end - ctx_start) / 4
        dwait
        li r3, (g_row - ctx_start) / 4
        cbcr r3, r0, 2
        li r3, (g_col - ctx_start) / 4
        cbcc r3, r0, 1
        li r3, (k_sq - ctx_start) / 4
        cbcast r3, 1
        li r11, 0x4000
        rdcyc r8
        wfb r11, 64             ; FB[0x4040 + lane]
        rdcyc r9
        li r2, 1
        sub r9, r9, r8
        li r6, 9                ; wfb takes 8 cycles (a row of 8 per cycle)
        bne r9, r6, fail
        li r2, 2
        li r4, 0
loop:   mul r6, r4, r4
        add r7, r11, r4
        lfb r7, 64(r7)
        bne r7, r6, fail
        addi r4, r4, 1
        slti r7, r4, 64
        bnez r7, loop

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
