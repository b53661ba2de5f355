; `.res` and `.org` whose values depend on positions the layout passes
; decide (instructions before them name labels defined later): their sizes
; and addresses follow the placement, as ca65 (one pass) gets them.
        .org    $1D00
start:  lda     later
        jmp     later
        .res    $1E00 - *, $EA
        .org    $1E00
later:  rts
table:  .byte   1, 2
        .org    table + 256
after:  .word   after, table
        .res    $1F10 - *
last:   .byte   <last
