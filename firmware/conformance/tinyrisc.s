; Conformance program: TinyRISC scalar instructions: arithmetic, logic, shifts, loads/stores, branches, calls
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .data
w:      .word 0x80000001, 0
h:      .half 0xFFFE
b:      .byte 0x80, 0x7F
        .text
_start: li r2, 1
        li r3, 0x7FFFFFFF
        addi r4, r3, 1          ; wraps
        li r5, 0x80000000
        bne r4, r5, fail
        li r2, 2
        sub r4, r0, r3
        li r5, -0x7FFFFFFF
        bne r4, r5, fail
        li r2, 3
        li r3, 0xF0F0
        li r4, 0x0FF0
        and r5, r3, r4
        li r6, 0x00F0
        bne r5, r6, fail
        or r5, r3, r4
        li r6, 0xFFF0
        bne r5, r6, fail
        xor r5, r3, r4
        li r6, 0xFF00
        bne r5, r6, fail
        nor r5, r3, r4
        li r6, ~0xFFF0
        bne r5, r6, fail
        li r2, 4
        andi r5, r3, 0x3F0F
        li r6, 0x3000
        bne r5, r6, fail
        ori r5, r0, 0x3FFFF
        li r6, 0x3FFFF
        bne r5, r6, fail
        xori r5, r3, 0xFF
        li r6, 0xF00F
        bne r5, r6, fail
        li r2, 5
        li r3, -16
        srai r5, r3, 2
        li r6, -4
        bne r5, r6, fail
        srli r5, r3, 28
        li r6, 15
        bne r5, r6, fail
        slli r5, r3, 4
        li r6, -256
        bne r5, r6, fail
        li r4, 33               ; amount & 31 = 1
        sll r5, r3, r4
        li r6, -32
        bne r5, r6, fail
        srl r5, r3, r4
        li r6, 0x7FFFFFF8
        bne r5, r6, fail
        sra r5, r3, r4
        li r6, -8
        bne r5, r6, fail
        li r2, 6
        li r3, -5
        li r4, 3
        slt r5, r3, r4
        li r6, 1
        bne r5, r6, fail
        sltu r5, r3, r4
        bnez r5, fail
        slti r5, r3, -4
        beqz r5, fail
        sltiu r5, r4, -1        ; 3 < 0xFFFFFFFF
        beqz r5, fail
        li r2, 7
        li r3, 100000
        li r4, -3000
        mul r5, r3, r4
        li r6, -300000000
        bne r5, r6, fail
        lui r5, 3
        li r6, 3 << 14
        bne r5, r6, fail
        li r2, 8
        li r10, w
        lw r5, 0(r10)
        li r6, 0x80000001
        bne r5, r6, fail
        sw r5, 4(r10)
        lw r7, 4(r10)
        bne r7, r6, fail
        lh r5, 8(r10)
        li r6, -2
        bne r5, r6, fail
        lhu r5, 8(r10)
        li r6, 0xFFFE
        bne r5, r6, fail
        lb r5, 10(r10)
        li r6, -128
        bne r5, r6, fail
        lbu r5, 10(r10)
        li r6, 0x80
        bne r5, r6, fail
        sh r6, 4(r10)
        sb r6, 6(r10)
        lw r5, 4(r10)
        li r6, 0x80800080
        bne r5, r6, fail
        li r2, 9
        li r3, 1
        li r4, 2
        beq r3, r4, fail
        bne r3, r3, fail
        blt r4, r3, fail
        bge r3, r4, fail
        bltu r4, r3, fail
        li r5, -1
        bgeu r3, r5, fail
        bgt r3, r4, fail
        ble r4, r3, fail
        li r2, 10
        li r3, 0
        call add5
        call add5
        li r6, 10
        bne r3, r6, fail
        li r2, 11
        li r8, add5
        jalr r15, r8
        li r6, 15
        bne r3, r6, fail
        li r2, 12
        j pass
        b fail
add5:   addi r3, r3, 5
        jr r15

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
