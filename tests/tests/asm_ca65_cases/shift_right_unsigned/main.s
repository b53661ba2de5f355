; ca65 folds `<<` and `>>` of constants with cc65's shl_l/shr_l: a right
; shift is logical (a negative number's sign is not copied in) and the
; count is C's `unsigned` (its low 32 bits). The bytes differ from an
; arithmetic shift only past 55 bits, or with counts past 63 or negative.
; bytes: 0F FF 00 01 01 F0 00 00 00 02 FF 80 23 0F
big = $10000 * $10000
        .byte <(-16 >> 60), <(-16 >> 56), <(-16 >> 64), <(-16 >> 63)
        .byte <((-1 >> 1) >> 62)
        .byte <(-256 >> 4), <(-256 >> $FFFFFFFF)
        .byte <(-16 << -4), <(16 >> -2)
        .byte <(1 << (big + 1)), <(-1 >> (big + 4))
        .byte <(1 << 63 >> 56), <($123 >> 0)
value = -16
shifted = value >> 60
        .byte <shifted
