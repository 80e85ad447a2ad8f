; Conformance program: cbcc, column mode: column j executes word j of each group (with an FB stream)
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .data
v:      .half 1000
        .ctx
ctx_start:
g0:
        movb r1, #0
        movb r1, #3
        movb r1, #6
        movb r1, #9
        movb r1, #12
        movb r1, #15
        movb r1, #18
        movb r1, #21
g1:
        add r1, fb0, r1         ; column 0 reads the FB datum
        add r1, r1, #1
        add r1, r1, #2
        add r1, r1, #3
        add r1, r1, #4
        add r1, r1, #5
        add r1, r1, #6
        add r1, r1, #7
ctx_end:
        .text
_start:
        li r10, ctx_start
        li r11, 0
        ldctxt r10, r11, (ctx_end - ctx_start) / 4
        dwait
        li r10, v
        li r11, 0x0040
        ldfb r10, r11, 1
        dwait
        cbcc r0, r11, 2
        li r2, 1
        li r4, 0
loop:   andi r5, r4, 7          ; column
        li r6, 4
        mul r6, r6, r5          ; 3 j + j
        bnez r5, notzero
        li r6, 1000
notzero:
        rcrisc r7, r4, 0
        bne r7, r6, fail
        addi r4, r4, 1
        slti r7, r4, 64
        bnez r7, loop

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
