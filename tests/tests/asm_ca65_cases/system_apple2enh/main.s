; `-t apple2enh` (a 65C02 system) with `.setcpu "6502"`: the system's
; symbols and characters.
; system: apple2enh
; bytes: A9 41 48 69 EE E2
        .setcpu "6502"
        lda #'A'
        .byte "Hi"
.ifdef __APPLE2ENH__
        .byte $EE
.endif
.ifdef __APPLE2__
        .byte $E2
.endif
