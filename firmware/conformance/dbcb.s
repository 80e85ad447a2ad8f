; Conformance program: dbcb, contexts with both FB sets streaming (SIMD and row mode)
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .data
d0:     .half 10, 20
d1:     .half 1, 2
        .ctx
ctx_start:
k:      mov r1, fb0             ; 10  (set 0, first word)
        add r1, fb1, r1         ; + 1 (set 1, first word)
        add r1, fb1, r1         ; + 2
        add r1, fb0, r1         ; + 20 = 33
        .align 32               ; row-mode groups start at a multiple of 8 words
g_row:                          ; rows 0..3 read set 0, rows 4..7 set 1:
        add r2, fb0, r2         ; two data per cycle
        add r2, fb0, r2
        add r2, fb0, r2
        add r2, fb0, r2
        add r2, fb1, r2
        add r2, fb1, r2
        add r2, fb1, r2
        add r2, fb1, r2
        .rept 8
        add r2, r2, r2          ; x 2
        .endr
        .rept 4
        add r2, fb0, r2
        .endr
        .rept 4
        add r2, fb1, r2
        .endr
ctx_end:
        .text
_start:
        li r10, ctx_start
        li r11, 0
        ldctxt r10, r11, (ctx_end - ctx_start) / 4
        dwait
        li r10, d0
        li r11, 0x0010
        ldfb r10, r11, 2
        dwait
        li r10, d1
        li r12, 0x8010
        ldfb r10, r12, 2
        dwait
        dbcb r0, r11, r12, 4
        li r2, 1
        rcrisc r5, r0, 42
        li r6, 33
        bne r5, r6, fail
        ; row mode: 3 groups, each stream advances once per group;
        ; rows 0..3: 2 * 10 + 20 = 40, rows 4..7: 2 * 1 + 2 = 4
        li r3, (g_row - ctx_start) / 4
        dbcb r3, r11, r12, 3, row
        li r2, 2
        rcrisc r5, r0, 8 * 3 + 5
        li r6, 40
        bne r5, r6, fail
        li r2, 3
        rcrisc r5, r0, 8 * 7
        li r6, 4
        bne r5, r6, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
