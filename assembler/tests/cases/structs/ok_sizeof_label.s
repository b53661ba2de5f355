; `.sizeof` of a label: what its own line emits (ca65's size of a label);
; a `.proc` is measured as a scope.
msg: .byte "hel"
 .byte "lo"
next: nop
 lda #.sizeof(msg)
 lda #.sizeof(next)
empty:
 lda #1
 lda #.sizeof(empty)
.proc p
 nop
 nop
.endproc
 lda #.sizeof(p)
