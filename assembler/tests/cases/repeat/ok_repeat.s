.repeat 3, i
        .byte i * 2
.endrepeat
.repeat 2, row
.repeat 2, col
        .byte row * 10 + col
.endrepeat
.endrepeat
.repeat 0
        .byte $FF               ; never
.endrepeat
.repeat 2
        nop
.endrepeat
