; `#` in a brace argument of a `.define` stays a token of its own, so
; the "is this operand immediate?" idiom sees it.
; bytes: 01 00 01 01
.define IV(arg) .match(.left(1,{arg}),#)
        .byte IV {#$12}         ; 01
        .byte IV {$12}          ; 00
        .byte IV {#<$1234}      ; 01
        .byte IV {#$12, x}      ; 01
