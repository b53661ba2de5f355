; An address size the 6502 does not have.
        .import faraway: far
        .export here: long
here:   rts
