        lda #(1 + 2
        lda #1 +
        .byte 1 2
        lda #$
        .word %102
        lda #'ab'
        lda #"str"
