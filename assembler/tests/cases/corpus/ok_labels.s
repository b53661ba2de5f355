; Labels: cheap locals, unnamed labels in both directions, scopes, procs,
; :: paths, forward references.
        .code
first:  ldx #3
@loop:  dex
        bne @loop
        beq @out
        nop
@out:   lda #0
second: ldy #4
@loop:  dey
        bne @loop
:       inx
        bne :-
        beq :+
        nop
:       nop
        bcc :++
        bcs :+
:       nop
:       nop
        jmp :--
        jmp :-
.proc outer
        lda #1
inner:  lda #2
        jsr helper
        rts
.proc helper
        lda inner
deep:   rts
.endproc
        jmp helper::deep
.endproc
        jsr outer
        jsr outer::inner
        jsr outer::helper
        jsr outer::helper::deep
        jmp ::first
.scope tables
data:   .byte 1, 2, 3
size = * - data
.endscope
        lda tables::data
        ldx #tables::size
        .byte .sizeof(outer), .sizeof(tables)
alias := second
        jmp alias
count .set 1
        .byte count
count .set count + 1
        .byte count
        jmp forward + 2
        .word forward, *, * + 2
forward: rts
        lda first - second + $8000
