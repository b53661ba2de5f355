; Unknown names get a "did you mean" where one is close: an instruction, a
; macro, a directive, a symbol (a swapped pair of letters counts as one).
.macro blink count
        ldx #count
.endmacro
counter = $40
        lad #1                  ; lda
        LDZ #1                  ; LDA or LDX or LDY: the first
        blinkk 3                ; blink
        .bytee 1                ; .byte
        inc countr              ; counter
        lda Counter             ; counter: case is only a hint
        lda total               ; nothing close
