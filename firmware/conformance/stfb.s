; Conformance program: stfb, DMA from the frame buffer to main memory
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .data
dst:    .space 32
        .text
_start: li r11, 0xC000          ; set 1, bank 3
        li r4, 0
        li r6, -100
fill:   add r7, r11, r4
        sfb r6, 0(r7)           ; FB[0xC000 + i] = -100 + 37 i
        addi r6, r6, 37
        addi r4, r4, 1
        slti r7, r4, 16
        bnez r7, fill
        li r10, dst
        stfb r10, r11, 16
        dwait
        li r2, 1
        li r4, 0
        li r6, -100
check:  add r5, r4, r4
        add r5, r5, r10
        lh r5, 0(r5)
        bne r5, r6, fail
        addi r6, r6, 37
        addi r4, r4, 1
        slti r7, r4, 16
        bnez r7, check
        li r2, 2
        lw r5, 32(r10)          ; nothing written past the 16 words
        bnez r5, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
