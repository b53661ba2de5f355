; `.feature missing_char_term`: a character without its closing quote;
; `loose_char_term`: a character in double quotes (always accepted here).
        .feature missing_char_term, loose_char_term
        .byte 'a
        lda #'b
        lda #"c"
        .byte 'd', "e"
