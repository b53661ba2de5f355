; Case-insensitive names, and a scope far away, are not for this
; assembler.
        .case   off
.proc   faraway: far
        rts
.endproc
