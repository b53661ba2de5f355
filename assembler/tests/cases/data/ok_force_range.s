; `.feature force_range`: values out of a field's range keep their low
; bits instead of being errors (newer ca65 also switch it off with `-`;
; 2.19 does not take the sign, so this case does not use it).
        .feature force_range
        lda #-1
        lda #$1234
        .byte 300, -200
        .word 70000
        lda #$12
