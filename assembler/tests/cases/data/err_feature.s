; A name ca65 does not know (an error, listing its features), and
; force_range switched off again.
        .feature force_range, c_comments
        .feature bogus
        .feature force_range -
        lda #-1
