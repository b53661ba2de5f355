; A missing include is one error, at its line, naming every place searched
; and the built-in file whose name is close. As in ca65, it ends the
; assembly: the lines below use what the include would have defined, and
; errors there would only repeat this one.
        .include "bultin.inc"
        builtin_macro
        lda #BUILTIN_VALUE
        jmp not_defined_anywhere
        .if
