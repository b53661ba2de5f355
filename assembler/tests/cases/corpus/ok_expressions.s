; Every operator of ca65's precedence table, with and without parentheses.
.struct Rec
        ra      .byte
        rb      .word
        rc      .res 3
.endstruct
        .code
a1 = 7
b1 = 3
c1 = $F0
        .byte a1 + b1 & c1, (a1 + b1) & c1      ; & binds tighter than +
        .byte a1 - b1 - 1, a1 * b1 + 1, a1 * (b1 + 1)
        .byte a1 / b1, a1 .mod b1, -a1 / 2 & $FF, <(-7 .mod 3)
        .byte 1 << 3 | 1, 1 << (3 | 1), c1 >> 4, <(-16 >> 2)
        .byte a1 ^ b1, a1 | b1, ~a1 & $FF, <~0
        .byte a1 = 7, a1 <> 7, a1 < b1, a1 > b1, a1 <= 7, a1 >= 8
        .byte 1 + 2 = 3, 2 * 3 < 7 + 1
        .byte 1 && 0, 1 || 0, 1 .xor 1, 0 .xor 1, 1 .and 2, 0 .or 0
        .byte !0, !1 = 0, !(1 = 0), .not 1, .not 0 = 1
        .byte 2 .bitand 3, 2 .bitor 1, 2 .bitxor 3, <(.bitnot 0), 1 .shl 4, 16 .shr 2
        .byte <$1234, >$1234, ^$123456, .lobyte($ABCD), .hibyte($ABCD), .bankbyte($ABCDEF)
        .word .loword($12345678), .hiword($12345678)
        .byte 'A', 'z' - 'a', "Q"
        .byte %1010, $0A, 10, 0Ah, 0ah, 12H
        .byte +5, -(-5), --5, - - 5
        .word $FFFF, 65535, 1 << 15
        .dword $12345678, $FFFFFFFF, 100000
        .byte <(1 + 2 * 3 - 4 / 2 .mod 3 << 1)
        .byte (1 + 2) * (3 - 4 / 2) .mod 3 << 1
        .byte .sizeof(Rec), Rec::rb, Rec::rc
        .byte .defined(a1), .defined(nothing), .const(a1 + 1)
        .byte .strlen("hello"), .blank(), .blank(x)
