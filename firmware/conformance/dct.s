; Conformance program: the 8x8 2D DCT, a classic MorphoSys kernel, with its cycle count
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

; Z = C X C^T with C[k][n] = round(1024 a(k) cos((2n+1) k pi / 16)) in Q10.
; RC (r, c) holds pixel x[r][c] (minus 128).
;   row pass, column mode: column k computes Y[r][k] = sum_n C[k][n] x[r][n],
;     reading x[r][n] on the horizontal express lane (xrow n), coefficient
;     C[k][n] as its own immediate; mac accumulates 32-bit, acc >>10 rounds.
;   column pass, row mode: row l computes Z[l][k] = sum_r C[l][r] Y[r][k]
;     over the vertical express lane (xcol r).
; Every operation writes `out`, which the lanes read, so each MAC step first
; restores `out` (2 cycles per step): 17 + 17 = 34 array cycles.
; Loading the 64 pixels: the FB broadcasts one datum per cycle, so the block
; is shifted in row by row (8 cycles per row plus 1 to freeze it): 74 cycles.
; Reported: r3 = DCT cycles (issue of the row pass to the status read after
; the column pass), r4 = load cycles, r5 = total (load, DCT, wfb, stfb).
        .data
pixels:
        .half 33, 10, -13, -36, -59, -82, -105, -128
        .half 92, 58, 24, 45, 11, -23, -57, -91
        .half -105, 106, 61, 71, 26, 36, -9, -54
        .half -101, -102, 98, 97, 96, 40, 39, -17
        .half -42, -54, -121, 123, 111, 99, 87, 20
        .half -38, -61, -84, -107, 126, 103, 80, 57
        .half 21, -13, -47, -26, -60, -94, -128, 94
        .half 80, 35, -10, 0, -45, -35, -80, -125
expect:
        .half -21, -39, -120, -49, 39, 18, -22, 22
        .half 14, -112, -89, 38, -70, -29, -24, -2
        .half -180, -313, 170, 12, 9, 13, 33, 19
        .half -42, 140, 90, -107, 73, 30, -1, -31
        .half -25, -14, -85, -27, 11, -99, -7, 1
        .half -82, 17, 16, 139, 6, 30, 64, -33
        .half 2, 48, -30, -58, -115, 47, -27, -27
        .half -16, -21, 20, 41, 23, 20, -59, 111
result: .space 128
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
g_load:
        cmp.true out, r0       ; F = 1: every row still loading
        cmp.true out, r0       ; F = 1: every row still loading
        cmp.true out, r0       ; F = 1: every row still loading
        cmp.true out, r0       ; F = 1: every row still loading
        cmp.true out, r0       ; F = 1: every row still loading
        cmp.true out, r0       ; F = 1: every row still loading
        cmp.true out, r0       ; F = 1: every row still loading
        cmp.true out, r0       ; F = 1: every row still loading
; load row 0: shift 8 data in from the FB (column 0) eastwards
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) cmp.ne r5, #0     ; row 0 is full: freeze it
        (f) cmp.ne r5, #0     ; row 0 is full: freeze it
        (f) cmp.ne r5, #0     ; row 0 is full: freeze it
        (f) cmp.ne r5, #0     ; row 0 is full: freeze it
        (f) cmp.ne r5, #0     ; row 0 is full: freeze it
        (f) cmp.ne r5, #0     ; row 0 is full: freeze it
        (f) cmp.ne r5, #0     ; row 0 is full: freeze it
        (f) cmp.ne r5, #0     ; row 0 is full: freeze it
; load row 1: shift 8 data in from the FB (column 0) eastwards
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) cmp.ne r5, #1     ; row 1 is full: freeze it
        (f) cmp.ne r5, #1     ; row 1 is full: freeze it
        (f) cmp.ne r5, #1     ; row 1 is full: freeze it
        (f) cmp.ne r5, #1     ; row 1 is full: freeze it
        (f) cmp.ne r5, #1     ; row 1 is full: freeze it
        (f) cmp.ne r5, #1     ; row 1 is full: freeze it
        (f) cmp.ne r5, #1     ; row 1 is full: freeze it
        (f) cmp.ne r5, #1     ; row 1 is full: freeze it
; load row 2: shift 8 data in from the FB (column 0) eastwards
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) cmp.ne r5, #2     ; row 2 is full: freeze it
        (f) cmp.ne r5, #2     ; row 2 is full: freeze it
        (f) cmp.ne r5, #2     ; row 2 is full: freeze it
        (f) cmp.ne r5, #2     ; row 2 is full: freeze it
        (f) cmp.ne r5, #2     ; row 2 is full: freeze it
        (f) cmp.ne r5, #2     ; row 2 is full: freeze it
        (f) cmp.ne r5, #2     ; row 2 is full: freeze it
        (f) cmp.ne r5, #2     ; row 2 is full: freeze it
; load row 3: shift 8 data in from the FB (column 0) eastwards
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) cmp.ne r5, #3     ; row 3 is full: freeze it
        (f) cmp.ne r5, #3     ; row 3 is full: freeze it
        (f) cmp.ne r5, #3     ; row 3 is full: freeze it
        (f) cmp.ne r5, #3     ; row 3 is full: freeze it
        (f) cmp.ne r5, #3     ; row 3 is full: freeze it
        (f) cmp.ne r5, #3     ; row 3 is full: freeze it
        (f) cmp.ne r5, #3     ; row 3 is full: freeze it
        (f) cmp.ne r5, #3     ; row 3 is full: freeze it
; load row 4: shift 8 data in from the FB (column 0) eastwards
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) cmp.ne r5, #4     ; row 4 is full: freeze it
        (f) cmp.ne r5, #4     ; row 4 is full: freeze it
        (f) cmp.ne r5, #4     ; row 4 is full: freeze it
        (f) cmp.ne r5, #4     ; row 4 is full: freeze it
        (f) cmp.ne r5, #4     ; row 4 is full: freeze it
        (f) cmp.ne r5, #4     ; row 4 is full: freeze it
        (f) cmp.ne r5, #4     ; row 4 is full: freeze it
        (f) cmp.ne r5, #4     ; row 4 is full: freeze it
; load row 5: shift 8 data in from the FB (column 0) eastwards
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) cmp.ne r5, #5     ; row 5 is full: freeze it
        (f) cmp.ne r5, #5     ; row 5 is full: freeze it
        (f) cmp.ne r5, #5     ; row 5 is full: freeze it
        (f) cmp.ne r5, #5     ; row 5 is full: freeze it
        (f) cmp.ne r5, #5     ; row 5 is full: freeze it
        (f) cmp.ne r5, #5     ; row 5 is full: freeze it
        (f) cmp.ne r5, #5     ; row 5 is full: freeze it
        (f) cmp.ne r5, #5     ; row 5 is full: freeze it
; load row 6: shift 8 data in from the FB (column 0) eastwards
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) cmp.ne r5, #6     ; row 6 is full: freeze it
        (f) cmp.ne r5, #6     ; row 6 is full: freeze it
        (f) cmp.ne r5, #6     ; row 6 is full: freeze it
        (f) cmp.ne r5, #6     ; row 6 is full: freeze it
        (f) cmp.ne r5, #6     ; row 6 is full: freeze it
        (f) cmp.ne r5, #6     ; row 6 is full: freeze it
        (f) cmp.ne r5, #6     ; row 6 is full: freeze it
        (f) cmp.ne r5, #6     ; row 6 is full: freeze it
; load row 7: shift 8 data in from the FB (column 0) eastwards
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, fb0
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) mov out, w
        (f) cmp.ne r5, #7     ; row 7 is full: freeze it
        (f) cmp.ne r5, #7     ; row 7 is full: freeze it
        (f) cmp.ne r5, #7     ; row 7 is full: freeze it
        (f) cmp.ne r5, #7     ; row 7 is full: freeze it
        (f) cmp.ne r5, #7     ; row 7 is full: freeze it
        (f) cmp.ne r5, #7     ; row 7 is full: freeze it
        (f) cmp.ne r5, #7     ; row 7 is full: freeze it
        (f) cmp.ne r5, #7     ; row 7 is full: freeze it
        mov r1, out
        mov r1, out
        mov r1, out
        mov r1, out
        mov r1, out
        mov r1, out
        mov r1, out
        mov r1, out
g_rowp:
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mul out, xrow0, #362
        mul out, xrow0, #502
        mul out, xrow0, #473
        mul out, xrow0, #426
        mul out, xrow0, #362
        mul out, xrow0, #284
        mul out, xrow0, #196
        mul out, xrow0, #100
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mac out, xrow1, #362
        mac out, xrow1, #426
        mac out, xrow1, #196
        mac out, xrow1, #-100
        mac out, xrow1, #-362
        mac out, xrow1, #-502
        mac out, xrow1, #-473
        mac out, xrow1, #-284
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mac out, xrow2, #362
        mac out, xrow2, #284
        mac out, xrow2, #-196
        mac out, xrow2, #-502
        mac out, xrow2, #-362
        mac out, xrow2, #100
        mac out, xrow2, #473
        mac out, xrow2, #426
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mac out, xrow3, #362
        mac out, xrow3, #100
        mac out, xrow3, #-473
        mac out, xrow3, #-284
        mac out, xrow3, #362
        mac out, xrow3, #426
        mac out, xrow3, #-196
        mac out, xrow3, #-502
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mac out, xrow4, #362
        mac out, xrow4, #-100
        mac out, xrow4, #-473
        mac out, xrow4, #284
        mac out, xrow4, #362
        mac out, xrow4, #-426
        mac out, xrow4, #-196
        mac out, xrow4, #502
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mac out, xrow5, #362
        mac out, xrow5, #-284
        mac out, xrow5, #-196
        mac out, xrow5, #502
        mac out, xrow5, #-362
        mac out, xrow5, #-100
        mac out, xrow5, #473
        mac out, xrow5, #-426
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mac out, xrow6, #362
        mac out, xrow6, #-426
        mac out, xrow6, #196
        mac out, xrow6, #100
        mac out, xrow6, #-362
        mac out, xrow6, #502
        mac out, xrow6, #-473
        mac out, xrow6, #284
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mov out, r1
        mac out, xrow7, #362
        mac out, xrow7, #-502
        mac out, xrow7, #473
        mac out, xrow7, #-426
        mac out, xrow7, #362
        mac out, xrow7, #-284
        mac out, xrow7, #196
        mac out, xrow7, #-100
        acc r3, >>10
        acc r3, >>10
        acc r3, >>10
        acc r3, >>10
        acc r3, >>10
        acc r3, >>10
        acc r3, >>10
        acc r3, >>10
g_colp:
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mul out, xcol0, #362
        mul out, xcol0, #502
        mul out, xcol0, #473
        mul out, xcol0, #426
        mul out, xcol0, #362
        mul out, xcol0, #284
        mul out, xcol0, #196
        mul out, xcol0, #100
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mac out, xcol1, #362
        mac out, xcol1, #426
        mac out, xcol1, #196
        mac out, xcol1, #-100
        mac out, xcol1, #-362
        mac out, xcol1, #-502
        mac out, xcol1, #-473
        mac out, xcol1, #-284
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mac out, xcol2, #362
        mac out, xcol2, #284
        mac out, xcol2, #-196
        mac out, xcol2, #-502
        mac out, xcol2, #-362
        mac out, xcol2, #100
        mac out, xcol2, #473
        mac out, xcol2, #426
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mac out, xcol3, #362
        mac out, xcol3, #100
        mac out, xcol3, #-473
        mac out, xcol3, #-284
        mac out, xcol3, #362
        mac out, xcol3, #426
        mac out, xcol3, #-196
        mac out, xcol3, #-502
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mac out, xcol4, #362
        mac out, xcol4, #-100
        mac out, xcol4, #-473
        mac out, xcol4, #284
        mac out, xcol4, #362
        mac out, xcol4, #-426
        mac out, xcol4, #-196
        mac out, xcol4, #502
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mac out, xcol5, #362
        mac out, xcol5, #-284
        mac out, xcol5, #-196
        mac out, xcol5, #502
        mac out, xcol5, #-362
        mac out, xcol5, #-100
        mac out, xcol5, #473
        mac out, xcol5, #-426
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mac out, xcol6, #362
        mac out, xcol6, #-426
        mac out, xcol6, #196
        mac out, xcol6, #100
        mac out, xcol6, #-362
        mac out, xcol6, #502
        mac out, xcol6, #-473
        mac out, xcol6, #284
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mov out, r3
        mac out, xcol7, #362
        mac out, xcol7, #-502
        mac out, xcol7, #473
        mac out, xcol7, #-426
        mac out, xcol7, #362
        mac out, xcol7, #-284
        mac out, xcol7, #196
        mac out, xcol7, #-100
        acc r4, >>10
        acc r4, >>10
        acc r4, >>10
        acc r4, >>10
        acc r4, >>10
        acc r4, >>10
        acc r4, >>10
        acc r4, >>10
ctx_end:
        .text
_start:
        li r10, ctx_start
        li r11, 0
        ldctxt r10, r11, (ctx_end - ctx_start) / 4
        dwait
        li r10, pixels
        li r11, 0x0000
        ldfb r10, r11, 64
        dwait
        li r3, (g_row - ctx_start) / 4
        cbcr r3, r0, 2          ; lane ids (r5 = row)
        rdcyc r12
        li r3, (g_load - ctx_start) / 4
        rdcyc r8
        cbcc r3, r11, 74        ; shift the pixels in
        rcall r7
        rdcyc r9
        sub r4, r9, r8
        li r3, (g_rowp - ctx_start) / 4
        li r6, (g_colp - ctx_start) / 4
        rdcyc r8
        cbcc r3, r0, 17         ; row pass
        cbcr r6, r0, 17         ; column pass, queued behind it
        rcall r7
        rdcyc r9
        sub r3, r9, r8
        li r11, 0x4000
        wfb r11, 0
        li r10, result
        stfb r10, r11, 64
        dwait
        rdcyc r9
        sub r5, r9, r12
        li r2, 1
        li r7, 0
check:  add r8, r7, r7
        li r6, expect
        add r6, r6, r8
        lh r6, 0(r6)
        add r8, r8, r10
        lh r8, 0(r8)
        bne r8, r6, fail
        addi r7, r7, 1
        slti r8, r7, 64
        bnez r8, check

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
