; Cheap locals live between two normal symbol definitions; unnamed labels
; are found by counting.
first:  ldx #2
@loop:  dex
        bne @loop
second: ldy #2
@loop:  dey                     ; a different @loop
        bne @loop
:       inx
        bne :-
        beq :+
        nop
:       bcc :++
        bcs :+
:       nop
:       jmp :---
