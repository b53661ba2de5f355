; A `.set` variable used in a scope that has no name of its own for it:
; bound at the end to the outer variable, so its last value (as ca65).
; bytes: 02 A9 02
cnt .set 1
.proc p
        .byte cnt
        lda #cnt
.endproc
cnt .set 2
