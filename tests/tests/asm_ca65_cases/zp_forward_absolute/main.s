; A zero-page symbol used before it is defined: ca65 is one pass and
; assembles the operand as absolute (and warns that zero page was
; possible); we do the same by default.
; bytes: AD 12 00 9D 12 00 AD 00 00 BE 12 00 A5 34 94 12
; warns: asm::zp-forward
        lda zp
        sta zp,x
        lda zv
        ldx zp,y
        lda <fwd
        sty zp,x                ; sty has no absolute,x: zero page
zp = $12
fwd = $1234
        .zeropage
zv:     .res 1
