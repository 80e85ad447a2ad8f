; Conformance program: an 8x8 transpose through the interconnect (express lanes)
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

; RC (r, c) holds A(r, c) = 8 r + c and ends with A(c, r) in r2. Each of the
; 8 steps uses both express lanes: the horizontal one brings A(r, k) to the
; diagonal, the vertical one takes it from (c, c) down column c to row k.
; One column-mode run of 32 groups: 32 array cycles.
        .ctx
        .org 0x20000
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
g_tr:
; step 0: row k of the result = column k of the input
        mov r3, xrow0          ; out = A(row, 0)
        mov r3, xrow0          ; out = A(row, 0)
        mov r3, xrow0          ; out = A(row, 0)
        mov r3, xrow0          ; out = A(row, 0)
        mov r3, xrow0          ; out = A(row, 0)
        mov r3, xrow0          ; out = A(row, 0)
        mov r3, xrow0          ; out = A(row, 0)
        mov r3, xrow0          ; out = A(row, 0)
        cmp.eq r5, #0
        cmp.eq r5, #0
        cmp.eq r5, #0
        cmp.eq r5, #0
        cmp.eq r5, #0
        cmp.eq r5, #0
        cmp.eq r5, #0
        cmp.eq r5, #0
        (f) mov r2, xcol0        ; lane (k, c) reads (c, c) = A(c, k)
        (f) mov r2, xcol1
        (f) mov r2, xcol2
        (f) mov r2, xcol3
        (f) mov r2, xcol4
        (f) mov r2, xcol5
        (f) mov r2, xcol6
        (f) mov r2, xcol7
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
; step 1: row k of the result = column k of the input
        mov r3, xrow1          ; out = A(row, 1)
        mov r3, xrow1          ; out = A(row, 1)
        mov r3, xrow1          ; out = A(row, 1)
        mov r3, xrow1          ; out = A(row, 1)
        mov r3, xrow1          ; out = A(row, 1)
        mov r3, xrow1          ; out = A(row, 1)
        mov r3, xrow1          ; out = A(row, 1)
        mov r3, xrow1          ; out = A(row, 1)
        cmp.eq r5, #1
        cmp.eq r5, #1
        cmp.eq r5, #1
        cmp.eq r5, #1
        cmp.eq r5, #1
        cmp.eq r5, #1
        cmp.eq r5, #1
        cmp.eq r5, #1
        (f) mov r2, xcol0        ; lane (k, c) reads (c, c) = A(c, k)
        (f) mov r2, xcol1
        (f) mov r2, xcol2
        (f) mov r2, xcol3
        (f) mov r2, xcol4
        (f) mov r2, xcol5
        (f) mov r2, xcol6
        (f) mov r2, xcol7
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
; step 2: row k of the result = column k of the input
        mov r3, xrow2          ; out = A(row, 2)
        mov r3, xrow2          ; out = A(row, 2)
        mov r3, xrow2          ; out = A(row, 2)
        mov r3, xrow2          ; out = A(row, 2)
        mov r3, xrow2          ; out = A(row, 2)
        mov r3, xrow2          ; out = A(row, 2)
        mov r3, xrow2          ; out = A(row, 2)
        mov r3, xrow2          ; out = A(row, 2)
        cmp.eq r5, #2
        cmp.eq r5, #2
        cmp.eq r5, #2
        cmp.eq r5, #2
        cmp.eq r5, #2
        cmp.eq r5, #2
        cmp.eq r5, #2
        cmp.eq r5, #2
        (f) mov r2, xcol0        ; lane (k, c) reads (c, c) = A(c, k)
        (f) mov r2, xcol1
        (f) mov r2, xcol2
        (f) mov r2, xcol3
        (f) mov r2, xcol4
        (f) mov r2, xcol5
        (f) mov r2, xcol6
        (f) mov r2, xcol7
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
; step 3: row k of the result = column k of the input
        mov r3, xrow3          ; out = A(row, 3)
        mov r3, xrow3          ; out = A(row, 3)
        mov r3, xrow3          ; out = A(row, 3)
        mov r3, xrow3          ; out = A(row, 3)
        mov r3, xrow3          ; out = A(row, 3)
        mov r3, xrow3          ; out = A(row, 3)
        mov r3, xrow3          ; out = A(row, 3)
        mov r3, xrow3          ; out = A(row, 3)
        cmp.eq r5, #3
        cmp.eq r5, #3
        cmp.eq r5, #3
        cmp.eq r5, #3
        cmp.eq r5, #3
        cmp.eq r5, #3
        cmp.eq r5, #3
        cmp.eq r5, #3
        (f) mov r2, xcol0        ; lane (k, c) reads (c, c) = A(c, k)
        (f) mov r2, xcol1
        (f) mov r2, xcol2
        (f) mov r2, xcol3
        (f) mov r2, xcol4
        (f) mov r2, xcol5
        (f) mov r2, xcol6
        (f) mov r2, xcol7
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
; step 4: row k of the result = column k of the input
        mov r3, xrow4          ; out = A(row, 4)
        mov r3, xrow4          ; out = A(row, 4)
        mov r3, xrow4          ; out = A(row, 4)
        mov r3, xrow4          ; out = A(row, 4)
        mov r3, xrow4          ; out = A(row, 4)
        mov r3, xrow4          ; out = A(row, 4)
        mov r3, xrow4          ; out = A(row, 4)
        mov r3, xrow4          ; out = A(row, 4)
        cmp.eq r5, #4
        cmp.eq r5, #4
        cmp.eq r5, #4
        cmp.eq r5, #4
        cmp.eq r5, #4
        cmp.eq r5, #4
        cmp.eq r5, #4
        cmp.eq r5, #4
        (f) mov r2, xcol0        ; lane (k, c) reads (c, c) = A(c, k)
        (f) mov r2, xcol1
        (f) mov r2, xcol2
        (f) mov r2, xcol3
        (f) mov r2, xcol4
        (f) mov r2, xcol5
        (f) mov r2, xcol6
        (f) mov r2, xcol7
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
; step 5: row k of the result = column k of the input
        mov r3, xrow5          ; out = A(row, 5)
        mov r3, xrow5          ; out = A(row, 5)
        mov r3, xrow5          ; out = A(row, 5)
        mov r3, xrow5          ; out = A(row, 5)
        mov r3, xrow5          ; out = A(row, 5)
        mov r3, xrow5          ; out = A(row, 5)
        mov r3, xrow5          ; out = A(row, 5)
        mov r3, xrow5          ; out = A(row, 5)
        cmp.eq r5, #5
        cmp.eq r5, #5
        cmp.eq r5, #5
        cmp.eq r5, #5
        cmp.eq r5, #5
        cmp.eq r5, #5
        cmp.eq r5, #5
        cmp.eq r5, #5
        (f) mov r2, xcol0        ; lane (k, c) reads (c, c) = A(c, k)
        (f) mov r2, xcol1
        (f) mov r2, xcol2
        (f) mov r2, xcol3
        (f) mov r2, xcol4
        (f) mov r2, xcol5
        (f) mov r2, xcol6
        (f) mov r2, xcol7
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
; step 6: row k of the result = column k of the input
        mov r3, xrow6          ; out = A(row, 6)
        mov r3, xrow6          ; out = A(row, 6)
        mov r3, xrow6          ; out = A(row, 6)
        mov r3, xrow6          ; out = A(row, 6)
        mov r3, xrow6          ; out = A(row, 6)
        mov r3, xrow6          ; out = A(row, 6)
        mov r3, xrow6          ; out = A(row, 6)
        mov r3, xrow6          ; out = A(row, 6)
        cmp.eq r5, #6
        cmp.eq r5, #6
        cmp.eq r5, #6
        cmp.eq r5, #6
        cmp.eq r5, #6
        cmp.eq r5, #6
        cmp.eq r5, #6
        cmp.eq r5, #6
        (f) mov r2, xcol0        ; lane (k, c) reads (c, c) = A(c, k)
        (f) mov r2, xcol1
        (f) mov r2, xcol2
        (f) mov r2, xcol3
        (f) mov r2, xcol4
        (f) mov r2, xcol5
        (f) mov r2, xcol6
        (f) mov r2, xcol7
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
; step 7: row k of the result = column k of the input
        mov r3, xrow7          ; out = A(row, 7)
        mov r3, xrow7          ; out = A(row, 7)
        mov r3, xrow7          ; out = A(row, 7)
        mov r3, xrow7          ; out = A(row, 7)
        mov r3, xrow7          ; out = A(row, 7)
        mov r3, xrow7          ; out = A(row, 7)
        mov r3, xrow7          ; out = A(row, 7)
        mov r3, xrow7          ; out = A(row, 7)
        cmp.eq r5, #7
        cmp.eq r5, #7
        cmp.eq r5, #7
        cmp.eq r5, #7
        cmp.eq r5, #7
        cmp.eq r5, #7
        cmp.eq r5, #7
        cmp.eq r5, #7
        (f) mov r2, xcol0        ; lane (k, c) reads (c, c) = A(c, k)
        (f) mov r2, xcol1
        (f) mov r2, xcol2
        (f) mov r2, xcol3
        (f) mov r2, xcol4
        (f) mov r2, xcol5
        (f) mov r2, xcol6
        (f) mov r2, xcol7
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
k_show: mov out, r2
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
        li r3, (g_tr - ctx_start) / 4
        rdcyc r8
        cbcc r3, r0, 32
        rcall r7
        rdcyc r9
        sub r3, r9, r8          ; r3: cycles, issue to status (1 + 32 + 2 + 1)
        li r2, 1
        li r6, 36
        bne r3, r6, fail
        li r3, (k_show - ctx_start) / 4
        cbcast r3, 1            ; out = r2
        li r2, 3
        li r4, 0
check:  srli r5, r4, 3          ; r
        andi r6, r4, 7          ; c
        slli r6, r6, 3
        add r6, r6, r5          ; expected 8 c + r
        rcrisc r7, r4, 0
        bne r7, r6, fail
        addi r4, r4, 1
        slti r7, r4, 64
        bnez r7, check
        li r3, 36

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
