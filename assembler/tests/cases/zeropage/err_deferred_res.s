; `.res`es that waited for placement and come out wrong: negative (the
; code before it reaches past the address it pads to), and too large.
        .org    $1000
        lda     later
        .res    $1002 - *
later:  rts
        .org    $2000
        lda     end
        .res    $FFFFFFFF * 2 - *
end:    rts
