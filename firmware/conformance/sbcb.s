; Conformance program: sbcb, contexts with one FB datum stream
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .data
vals:   .half 3, 4, 100
        .ctx
ctx_start:
k:      movb r1, #0
        add r1, fb0, r1         ; + 3
        nop                     ; does not read the FB: the stream waits
        add r1, fb0, r1         ; + 4 = 7
        mul r2, fb0, r1         ; 100 * 7
k1:     movb r1, #3
        add r1, fb1, r1
ctx_end:
        .text
_start:
        li r10, ctx_start
        li r11, 0
        ldctxt r10, r11, (ctx_end - ctx_start) / 4
        dwait
        li r10, vals
        li r11, 0x0100
        ldfb r10, r11, 3
        dwait
        sbcb r0, r11, 5
        li r2, 1
        rcrisc r5, r0, 0
        li r6, 700
        bne r5, r6, fail
        li r2, 2
        rcrisc r5, r0, 63
        bne r5, r6, fail
        ; the same from set 1
        li r2, 3
        li r11, 0x8100
        ldfb r10, r11, 3
        dwait
        .equ K1, (k1 - ctx_start) / 4
        li r3, K1
        sbcb r3, r11, 2
        rcrisc r5, r0, 9
        li r6, 6                ; 3 + first word of set 1 (3)
        bne r5, r6, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
