; A name a scope does not define yet takes its address size from the
; nearest outer symbol of that name: zero page from the global `v` in
; `s`, but absolute in `i`, whose nearest outer `v` is `s`'s own, not
; defined yet (found by the generator, seed 42).
; bytes: A5 59 AD 59 00
v = $21
.proc s
        lda v
.scope i
        lda v
.endscope
v = $59
.endproc
