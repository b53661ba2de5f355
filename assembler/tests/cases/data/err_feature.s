; A ca65 feature not implemented here (a warning), a name ca65 does not
; know (an error), and force_range switched off again.
        .feature force_range, c_comments
        .feature bogus
        .feature force_range -
        lda #-1
