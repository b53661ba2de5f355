; Every error in the file is reported in one run.
        lda
        sta #1
        jmp ($12),y
        lda ($12,y)
        ldx $12,x
        lax $12
        frobnicate $12
        label_without_colon
        bne $12,x
        lda f:$123456
        lda q:$12
        .nonsense
        lda #1, 2
        .byte
