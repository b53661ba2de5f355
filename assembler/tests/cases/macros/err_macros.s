.macro two a1, a2
        lda #a1
        sta a2
.endmacro
        two 1, $10, 3
        two 300, $10
.macro two
.endmacro
.macro inner_error value
        lda #value
.endmacro
.macro outer_error value
        inner_error value
.endmacro
        outer_error 999
        .local x
        .exitmacro
.macro never_closed
        nop
