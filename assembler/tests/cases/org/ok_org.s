        .code
        jmp after
        .org $1000
fixed:  lda fixed
        jmp fixed2
        bne fixed
fixed2: .word fixed, *
        .org $0080
zp:     lda zp
        .reloc
after:  lda fixed
        lda zp
        rts
        .org $2000
        .align 256
page:   .byte <page, >page
