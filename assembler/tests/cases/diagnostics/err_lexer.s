        lda #"unterminated
        lda #$1G
        lda ?
        .byte @
        lda #99999999999
