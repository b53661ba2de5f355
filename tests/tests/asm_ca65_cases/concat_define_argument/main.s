; String functions on a parameterised `.define`'s argument, also to name
; an include.
; bytes: 72 78 07
.define NAME(b) .concat(b, "x")
        .byte NAME "r"
.define PART(n) .concat("part_", n, ".inc")
        .include PART "a"
