; Widening one instruction moves the labels after it, which may widen
; the next: every pass only widens, so the passes end.
        .org $00F6
a0:     lda a1
a1:     lda a2
a2:     lda a3
a3:     lda a4
a4:     lda a5
a5:     lda a6
a6:     rts
