; Conformance program: rcany, rcall, rcst, rcfl, rcfh, rcsl, rcsh: the status of all 64 RCs
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
k_lt40: cmp.lt r1, #40
k_ge0:  cmp.ge r1, #0
k_lt0:  cmp.lt r1, #0
k_slp:  cmp.ge r1, #32
        (f) sleep
        cmp.lt r1, #32          ; only the awake lanes 0..31 execute
k_ltx:  cmp.lt r1, #16
k_wake: wake
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
        li r3, (k_lt40 - ctx_start) / 4
        cbcast r3, 1
        li r2, 1
        rcany r7
        li r6, 1
        bne r7, r6, fail
        li r2, 2
        rcall r7
        bnez r7, fail
        li r2, 3
        rcfl r7
        li r6, -1
        bne r7, r6, fail
        li r2, 4
        rcfh r7
        li r6, 0xFF
        bne r7, r6, fail
        li r2, 11
        rcst r7                 ; some: 1
        li r6, 1
        bne r7, r6, fail
        li r2, 5
        li r3, (k_ge0 - ctx_start) / 4
        cbcast r3, 1
        rcall r7
        li r6, 1
        bne r7, r6, fail
        li r2, 12
        rcst r7                 ; all: 3
        li r6, 3
        bne r7, r6, fail
        li r2, 6
        li r3, (k_lt0 - ctx_start) / 4
        cbcast r3, 1
        rcst r7                 ; none: 0
        bnez r7, fail
        rcany r7
        bnez r7, fail
        rcall r7
        bnez r7, fail
        li r2, 7
        li r3, (k_slp - ctx_start) / 4
        cbcast r3, 3
        rcsl r7
        bnez r7, fail
        rcsh r7
        li r6, -1
        bne r7, r6, fail
        li r2, 8
        rcall r7                ; sleeping lanes do not count
        li r6, 1
        bne r7, r6, fail
        li r2, 9
        li r3, (k_ltx - ctx_start) / 4
        cbcast r3, 1
        rcall r7
        bnez r7, fail
        rcany r7
        beqz r7, fail
        li r2, 10
        li r3, (k_wake - ctx_start) / 4
        cbcast r3, 1
        rcsh r7
        bnez r7, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
