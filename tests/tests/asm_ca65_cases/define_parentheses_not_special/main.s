; A parameterised `.define` called with parentheses: ca65 does not strip
; them, `SQ(2+1)` is `(2+1)*(2+1)` (a silent difference once: 5).
; bytes: 09 05 04 04 04 04 07
.define SQ(v) v*v
        .byte SQ(2+1)
        .byte SQ 2+1
.define TW(p,q) p-q
        .byte TW 5, 1
        .byte TW {5}, {1}
        .byte (TW(5, 1))
        .byte SQ(2), 7
