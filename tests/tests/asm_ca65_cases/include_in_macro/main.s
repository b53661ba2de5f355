; `.include` inside a macro or `.repeat` is read after the expansion, the
; last one first (ca65's input files are a stack of their own); it was
; read in place once, a silent difference.
; bytes: 01 03 06 02 04 05 05 02 02
.macro m
        .byte 1
        .include "two.inc"
        .include "six.inc"
        .byte 3
.endmacro
        m
        .byte 4
.repeat 2
        .include "two.inc"
        .byte 5
.endrepeat
