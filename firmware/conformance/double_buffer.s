; Conformance program: DMA double buffering: transfer and computation overlap
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

; 4 blocks of 64 FB words are summed by the array (one context per word,
; streamed from the FB with sbcb). Measured with rdcyc:
;   r5 = T_dma   one ldfb of a block, alone
;   r6 = T_comp  one block summed, alone
;   r3 = T_seq   all blocks, load then compute, one after the other
;   r4 = T_ovl   all blocks double-buffered: block k+1 is loaded into the
;                other FB bank while the array sums block k
; The program checks the sums and that T_ovl saves at least
; (NB - 1) * T_dma - 10 NB cycles over T_seq (all transfers but the first
; hidden; the bank swap costs the loop a few instructions per block), and
; that T_ovl <= T_dma + NB (T_comp + 16) (16: the loop's own instructions).
NB = 4
BLK = 64
        .data
blocks: .half 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4, 3, 2, 1, 0, 7, 6, 5, 4
        .ctx
ctx_start:
k_clear: movb r1, #0
k_sum:
        .rept BLK
        add r1, fb0, r1
        .endr
ctx_end:
        .text
_start:
        li r10, ctx_start
        li r11, 0
        ldctxt r10, r11, (ctx_end - ctx_start) / 4
        dwait
        li r13, (k_clear - ctx_start) / 4
        li r14, (k_sum - ctx_start) / 4
        ; expected sum, by TinyRISC from main memory
        li r10, blocks
        li r12, 0
        li r7, 0
esum:   add r8, r7, r7
        add r8, r8, r10
        lh r8, 0(r8)
        add r12, r12, r8
        addi r7, r7, 1
        slti r8, r7, NB * BLK
        bnez r8, esum
        ; T_dma
        li r11, 0
        rdcyc r8
        ldfb r10, r11, BLK
        dwait
        rdcyc r9
        sub r5, r9, r8
        ; T_comp
        cbcast r13, 1
        rdcyc r8
        sbcb r14, r11, BLK
        rcall r7
        rdcyc r9
        sub r6, r9, r8
        ; sequential
        cbcast r13, 1
        rdcyc r8
        li r7, 0                ; block
        mv r9, r10
seq:    ldfb r9, r0, BLK
        dwait
        sbcb r14, r0, BLK
        rcall r11               ; wait for the array
        addi r9, r9, 2 * BLK
        addi r7, r7, 1
        slti r11, r7, NB
        bnez r11, seq
        rdcyc r9
        sub r3, r9, r8
        li r2, 1
        rcrisc r7, r0, 0
        bne r7, r12, fail
        li r2, 2
        rcrisc r7, r0, 63
        bne r7, r12, fail
        ; double-buffered
        cbcast r13, 1
        rdcyc r8
        li r11, 0x0000          ; bank being summed
        li r9, 0x4000           ; bank being filled
        ldfb r10, r11, BLK
        dwait
        li r7, 1                ; next block to load
        addi r10, r10, 2 * BLK
ovl:    slti r15, r7, NB
        beqz r15, last
        ldfb r10, r9, BLK       ; load block k+1 into the other bank ...
last:   sbcb r14, r11, BLK      ; ... while the array sums block k
        rcall r15
        dwait
        mv r15, r11             ; swap the banks
        mv r11, r9
        mv r9, r15
        addi r10, r10, 2 * BLK
        addi r7, r7, 1
        slti r15, r7, NB + 1
        bnez r15, ovl
        rdcyc r9
        sub r4, r9, r8
        li r2, 3
        rcrisc r7, r0, 0
        bne r7, r12, fail
        li r2, 4                ; overlap: T_seq - T_ovl >= (NB - 1) T_dma - 10 NB
        sub r7, r3, r4          ; (the swap costs the loop a few instructions)
        li r9, NB - 1
        mul r8, r5, r9
        addi r8, r8, -10 * NB
        blt r7, r8, fail
        li r2, 5                ; and the overlapped run is bounded by compute
        li r8, NB
        mul r8, r8, r6
        add r8, r8, r5
        addi r8, r8, 16 * NB
        blt r8, r4, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
