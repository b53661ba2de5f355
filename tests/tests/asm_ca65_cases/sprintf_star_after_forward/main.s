; `*` under `.org` after an instruction whose operand is defined later:
; known at once, as in ca65 (the operand is absolute).
; bytes: AD 03 20 60
; out: at 2003
        .org $2000
        lda fwd
        .out .sprintf("at %04X", *)
fwd:    rts
