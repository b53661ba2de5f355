        jmp nowhere
        lda missing,x
first:  bne @later
second:
@later: rts
        bne :+
        jmp :--
