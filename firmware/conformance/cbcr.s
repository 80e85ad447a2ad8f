; Conformance program: cbcr, row mode: row i executes word i of each 8-word group
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .ctx
ctx_start:
g0:
        movb r1, #1
        movb r1, #11
        movb r1, #21
        movb r1, #31
        movb r1, #41
        movb r1, #51
        movb r1, #61
        movb r1, #71
g1:
        add r1, r1, #0
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
        cbcr r0, r0, 2
        li r2, 1
        li r4, 0                ; lane
loop:   srli r5, r4, 3          ; row
        li r6, 11
        mul r6, r6, r5
        addi r6, r6, 1          ; expected 10 row + 1 + row
        rcrisc r7, r4, 0
        bne r7, r6, fail
        addi r4, r4, 1
        slti r7, r4, 64
        bnez r7, loop

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
