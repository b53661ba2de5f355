; Range errors name the value and the allowed range.
        .byte 256
        .byte -1
        .word $10000
        lda #$100
        lda ($100),y
        stx $1234,y
        .res -1
        .res 2, 300
        .align 3
        .charmap 300, 1
        .dword -1
