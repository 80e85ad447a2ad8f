; Conformance program: cbcast, a run of contexts broadcast to all 64 RCs (SIMD)
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .ctx
ctx_start:
k_add:  movb r1, #5
        add r2, r1, #-3         ; r2 = 2
        add out, r2, r1         ; out = 7
ctx_end:
        .text
_start:
        li r10, ctx_start
        li r11, 0
        ldctxt r10, r11, (ctx_end - ctx_start) / 4
        dwait
        ; timing: issue (1 cycle), then 3 contexts in the next 3 cycles;
        ; rcall stalls until the run is done.
        li r2, 1
        rdcyc r8
        cbcast r0, 3             ; k_add is at context address 0
        rcall r5
        rdcyc r9
        sub r9, r9, r8
        li r6, 7                ; rdcyc, cbcast, 3 contexts, rcall (2), rdcyc
        bne r9, r6, fail
        li r2, 2
        li r4, 0
loop:   rcrisc r5, r4, 0        ; every RC's out must be 7
        bne r5, r6, fail
        addi r4, r4, 1
        slti r7, r4, 64
        bnez r7, loop
        ; back-to-back runs: the second is queued while the first streams
        li r2, 3
        rdcyc r8
        cbcast r0, 3
        cbcast r0, 3
        rcall r5
        rdcyc r9
        sub r9, r9, r8
        li r6, 10               ; rdcyc, issue, 6 contexts without a bubble, rcall (2), rdcyc
        bne r9, r6, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
