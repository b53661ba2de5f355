; A constant that depends on code size: the layout passes settle it.
; `lda small` stays zero page only while `small` fits in a byte.
        .org $0000
start:  lda small
        lda big
        lda small
small = end - start + $F0
big = end - start + $FA
end:    rts
