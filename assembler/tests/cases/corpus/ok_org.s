; .org and .reloc inside a relocatable segment: labels after .org are
; absolute, the bytes stay in sequence.
        .code
        lda #0
        jmp relocated
        .org $2000
abs1:   lda abs1
        jmp abs2
        bne abs1
abs2:   .word abs1, *
        .org $0080
zp1:    lda zp1
        .reloc
relocated:
        lda abs1
        lda zp1
        rts
        .org $4000
        .byte <*, >*
