; Operands that open with `(` are indirect, as in ca65: a typo of `(zp),y`
; or `(zp,x)` is an error, never another addressing mode. Each line that
; must fail says so with ca65 2.19's first words for it;
; tests/tests/asm_ca65_refuses.rs checks that ca65 and we refuse exactly
; the lines marked `ca65:`.
        lda ($12),x             ; ca65: 'Y' expected
        lda ($12,y)             ; ca65: Syntax error
        sta ($12),y,x           ; ca65: Unexpected trailing garbage characters
        lda ($12)*2             ; ca65: Illegal addressing mode
        lda ($12                ; ca65: ')' expected
        lda ($12),y             ; fine
        lda ($12,x)             ; fine
        jmp ($1234)             ; fine
        lda 0+($12)*2           ; fine: the operand does not open with `(`
