; Conformance program: lfb and sfb, TinyRISC's own frame-buffer port
; Runs on the model and checks its own results.
; Pass: halt with r1 = 1. Fail: r1 = 0xBAD, r2 = number of the failed check.

        .text
_start: li r11, 0x7FF0
        li r6, -2
        sfb r6, 15(r11)         ; FB[0x7fff]
        li r6, 0x12345
        sfb r6, -16(r11)        ; only the low 16 bits: 0x2345
        li r2, 1
        lfb r7, 15(r11)
        li r6, -2
        bne r7, r6, fail
        li r2, 2
        lfb r7, -16(r11)
        li r6, 0x2345
        bne r7, r6, fail
        li r2, 3
        li r6, 0x8000
        sfb r6, 0(r0)
        lfb r7, 0(r0)           ; sign-extended
        li r6, -32768
        bne r7, r6, fail

pass:   li r1, 1
        halt
fail:   li r1, 0xBAD
        halt
