; The listing shows macro and .repeat expansions with their arguments.
.macro store value, where
        lda #value
        sta where
.endmacro
        .segment "ZEROPAGE"
ptr:    .res 2
        .code
start:  store $12, ptr
        store {<start}, ptr+1
.repeat 2, i
        .byte i, i * 2
.endrepeat
        .byte 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20
        .res 40
        .org $C000
        lda $1234
.list off
        .byte $FF               ; not listed
.list on
        .byte $EE
