.proc one
        rts
.endscope
.endproc
.endproc
.scope two
        nop
