; Conformance program: ldfb and dwait, DMA from main memory to the frame buffer
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .data
src:    .half 3, -4, 1000, -32768, 32767, 0, 7, 8, 9, 10
        .text
_start: li r10, src
        li r11, 0x4000          ; set 0, bank 1
        li r2, 1
        rdcyc r8
        ldfb r10, r11, 10
        dwait
        rdcyc r9
        sub r9, r9, r8
        ; rdcyc, ldfb, setup 10 + 20 bytes at 4 bytes/cycle, dwait, rdcyc
        li r6, 18
        bne r9, r6, fail
        li r2, 2
        li r4, 0
loop:   add r5, r4, r4
        add r5, r5, r10
        lh r6, 0(r5)            ; expected, from main memory
        add r7, r11, r4
        lfb r5, 0(r7)           ; what DMA put in the FB
        bne r5, r6, fail
        addi r4, r4, 1
        slti r7, r4, 10
        bnez r7, loop
        ; a count in a register plus an immediate
        li r2, 3
        li r3, 4
        li r11, 0x8000
        ldfb r10, r11, r3+6
        dwait
        lfb r5, 9(r11)
        li r6, 10
        bne r5, r6, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
