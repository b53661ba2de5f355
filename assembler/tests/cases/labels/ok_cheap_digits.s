; Cheap locals may start with a digit, as in ca65: `@1:`.
foo:
@1:     nop
        bne @1
@2x:    jmp @1
bar:    bne @1
@1:     rts
