; Token functions used wrongly: each named at its call.
        .byte .left(1)
        .byte .mid(-1, 1, {1, 2})
        .byte .concat("a", 1)
        .byte .sprintf("%d")
        .byte .sprintf("%q", 1)
        .byte .sprintf("%d", 1, 2)
        .byte .ident("not a name")
        .byte .string(1)
        .byte .left(1, {1, 2}
