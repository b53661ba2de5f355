.repeat later
        nop
.endrepeat
later = 2
.repeat -1
        nop
.endrepeat
.endrepeat
.repeat 2
        nop
