; `.local @j` in a macro: each expansion's own cheap local.
; bytes: EA A2 03 CA D0 FD A2 03 CA D0 FD
.macro spin
        .local @j
        ldx #3
@j:     dex
        bne @j
.endmacro
start:  nop
        spin
        spin
