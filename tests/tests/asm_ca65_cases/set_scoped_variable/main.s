; `::name .set` and `scope::name .set`: a global counter bumped from
; inside a scope and a macro.
; bytes: 02 05
count .set 0
.macro bump
::count .set ::count + 1
.endmacro
.scope s
        bump
        bump
.endscope
        .byte count
.scope t
v = 1
.endscope
t::v2 .set 5
        .byte t::v2
