.struct Bad
        field   .byte
        other   lda
        third   .res
.endstruct
        .tag Nothing
.enum E
        1
        ok
.endenum
.struct Open
        a1      .byte
