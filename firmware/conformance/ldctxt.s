; Conformance program: ldctxt, DMA of context words into both banks of the context memory
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .ctx
ctx_start:
k_a:    movb out, #11
        nop
        nop
        movb out, #-1           ; 4 words
k_b:    movb out, #22
k_long: movb r1, #0
        .rept 63
        add r1, r1, #1
        .endr
ctx_end:
        .text
_start: li r10, k_a
        li r11, 4096            ; bank 1
        li r2, 1
        rdcyc r8
        ldctxt r10, r11, 4
        dwait
        rdcyc r9
        sub r9, r9, r8
        ; rdcyc, ldctxt, setup 10 + 4 words at 1 word/cycle, dwait, rdcyc
        li r6, 17
        bne r9, r6, fail
        li r10, k_b
        li r11, 0               ; bank 0
        ldctxt r10, r11, 1
        dwait
        li r2, 2
        li r11, 4096
        cbcast r11, 1           ; bank 1, first word: 11
        rcrisc r5, r0, 63
        li r6, 11
        bne r5, r6, fail
        li r2, 3
        cbcast r0, 1            ; bank 0: 22
        rcrisc r5, r0, 0
        li r6, 22
        bne r5, r6, fail
        li r2, 4
        cbcast r11, 4           ; the whole run: ends with -1
        rcrisc r5, r0, 17
        li r6, -1
        bne r5, r6, fail
        ; DMA loads bank 1 while the array streams 64 contexts from bank 0
        li r10, k_long
        li r12, 8               ; context address 8 (bank 0)
        ldctxt r10, r12, 64
        dwait
        li r10, k_a
        li r11, 4096
        rdcyc r8
        cbcast r12, 64          ; bank 0 streams ...
        ldctxt r10, r11, 4      ; ... while bank 1 is loaded
        dwait
        rcall r5
        rdcyc r9
        sub r9, r9, r8
        li r2, 5
        rcrisc r5, r0, 30
        li r6, 63
        bne r5, r6, fail
        li r2, 6                ; overlapped: cbcast at +1 runs +2..+65, the
        li r6, 68               ; transfer +3..+16; rcall at +66 (2), rdcyc +68
        bne r9, r6, fail
        li r2, 7
        cbcast r11, 1           ; the newly loaded bank 1 word
        rcrisc r5, r0, 5
        li r6, 11
        bne r5, r6, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
