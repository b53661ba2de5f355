        .byte 1 / 0
        .byte 5 .mod (2 - 2)
zero = 0
        lda #10 / zero
