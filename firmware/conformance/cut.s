; Conformance program: cut, the context after which the broadcast unit ends the run
; where no awake RC has F (the RCs execute it as a nop; the queued run starts next)
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .ctx
ctx_start:
; row mode: r1 = the RC's row
g_row:
        movb r1, #0
        movb r1, #1
        movb r1, #2
        movb r1, #3
        movb r1, #4
        movb r1, #5
        movb r1, #6
        movb r1, #7
k_none: cmp.lt r1, #0           ; F = 0 in every RC
        cut                     ; the run ends here
        movb r2, #5
        movb r2, #5
        movb r2, #5
        movb r2, #5
        movb r2, #5
        movb r2, #5
        movb r2, #5
        movb r2, #5
k_some: cmp.eq r1, #7           ; F in row 7 only
        cut                     ; the run goes on
        movb r3, #7
        movb r3, #7
        movb r3, #7
        movb r3, #7
        movb r3, #7
        movb r3, #7
        movb r3, #7
        movb r3, #7
k_r2:   cmp.eq r2, #5
k_r3:   cmp.eq r3, #7
k_slp:  cmp.ge r1, #4           ; rows 4..7 go to sleep with F = 1
        (f) sleep
        cmp.lt r1, #0           ; the awake rows: F = 0
        cut                     ; sleeping RCs' F does not count: the run ends
        movb r4, #9
k_wake: wake
k_r4:   cmp.eq r4, #9
ctx_end:
        .text
_start:
        li r10, ctx_start
        li r11, 0
        ldctxt r10, r11, (ctx_end - ctx_start) / 4
        dwait
        li r3, (g_row - ctx_start) / 4
        cbcr r3, r0, 1
        ; a cut with no F: rdcyc, issue, cmp, cut, rcall (2), rdcyc
        li r2, 1
        li r3, (k_none - ctx_start) / 4
        rdcyc r8
        cbcast r3, 10
        rcall r5
        rdcyc r9
        sub r9, r9, r8
        li r6, 6
        bne r9, r6, fail
        li r2, 2                ; the contexts after the cut did not run
        li r3, (k_r2 - ctx_start) / 4
        cbcast r3, 1
        rcany r7
        bnez r7, fail
        ; a cut with F in some RCs: all 10 contexts run
        li r2, 3
        li r3, (k_some - ctx_start) / 4
        rdcyc r8
        cbcast r3, 10
        rcall r5
        rdcyc r9
        sub r9, r9, r8
        li r6, 14               ; rdcyc, issue, 10 contexts, rcall (2), rdcyc
        bne r9, r6, fail
        li r2, 4
        li r3, (k_r3 - ctx_start) / 4
        cbcast r3, 1
        rcall r7
        li r6, 1
        bne r7, r6, fail
        ; the queued run starts in the cycle after the cut
        li r2, 5
        li r3, (k_none - ctx_start) / 4
        li r4, (k_some - ctx_start) / 4
        rdcyc r8
        cbcast r3, 10
        cbcast r4, 3
        rcall r5
        rdcyc r9
        sub r9, r9, r8
        li r6, 9                ; rdcyc, two issues, cmp and cut, 3 contexts, rcall (2), rdcyc
        bne r9, r6, fail
        ; sleeping RCs' F does not keep a run going
        li r2, 6
        li r3, (k_slp - ctx_start) / 4
        cbcast r3, 5
        li r3, (k_wake - ctx_start) / 4
        cbcast r3, 2
        rcany r7
        bnez r7, fail
        rcsh r7                 ; every RC awake again
        bnez r7, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
