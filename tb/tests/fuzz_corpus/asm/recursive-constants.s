.equ A, B
.equ B, A
  addi r1, r0, A
