; ca65's token functions: token lists cut (.left, .mid, .right), counted
; (.tcount) and compared (.match by kind, .xmatch by value), strings made
; (.concat, .string, .sprintf) and names made from strings (.ident).
        .byte .strlen("abc"), .blank(), .blank(x), .const(1), .tcount(a b c), .tcount({1, 2})
        .byte .match(a, b), .xmatch(1, 1), .match(+, -), .xmatch(a, b), .match(1, x)
        .byte .left(1, {1, 2, 3})
        .byte .mid(2, 1, {1, 2, 3})
        .byte .right(1, {1, 2, 3})
        .byte .concat("ab", "c"), .strlen(.concat("x", "yz"))
        .byte .string(foo), .string(3 + 4), .string(>.version)
        .word .version
.ident(.concat("lab", "el")):
        .word label
        .byte .sprintf("%d-%02x-%s-%c-%5d-%-3d|", 5, 10, "hi", 65, 42, 7)
        .byte .sprintf("%X%o%%", 255, 8)
.macro m arg
        .if .match({arg}, #)
        .byte 1
        .elseif .xmatch({arg}, 5)
        .byte 2
        .else
        .byte 3
        .endif
.endmacro
        m #
        m 5
        m 6
