; A label before the first `.segment` (an empty CODE that holds only a
; symbol), linked with a configuration without CODE: ld65 links it, the
; label at 0.
; bytes: A9 01 4C 00 00
entry:
        .segment "MAIN"
        lda #1
        jmp entry
