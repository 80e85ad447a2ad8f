.text
  addi r1, r0, 0x7fffffffffffffffffff
  j 0x10000000
loop: beq r0, r0, loop
