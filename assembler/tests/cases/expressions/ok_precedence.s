; ca65 precedence: & binds tighter than +, ! looser than =.
        .byte 1 + 2 & 3             ; 1 + (2 & 3) = 3
        .byte (1 + 2) & 3           ; 3
        .byte 2 + 3 * 4             ; 14
        .byte 1 << 2 + 1            ; (1 << 2) + 1 = 5
        .byte 8 | 1 & 2             ; 8 | (1 & 2) = 8
        .byte 1 = 1 && 2 = 2        ; 1
        .byte !1 = 0                ; !(1 = 0) = 1
        .byte 3 > 2 > 0             ; (3 > 2) > 0 = 1
        .byte 1 .xor 0 && 1         ; 1
        .byte -7 / 2 & $FF          ; -3 & $FF = $FD
        .byte -7 .mod 2 & $FF       ; -1 & $FF = $FF
        .byte ~0 & $0F              ; $0F
        .byte <$1234, >$1234, ^$123456
        .word $1234 >> 4, 1 << 15
        .byte 'a', 'Z' - 'A'
        .byte $10, %1010, 10, 0Fh
