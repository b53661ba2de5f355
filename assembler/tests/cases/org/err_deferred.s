; A `.res` that waited for placement and comes out negative: the code
; before it reaches past the address it pads to.
        .org    $1000
        lda     later
        .res    $1002 - *
later:  rts
