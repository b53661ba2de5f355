; Every addressing mode, zero page chosen for symbols defined earlier and
; for constants, absolute forced with a:, zero page forced with z:.
        .segment "ZEROPAGE"
zp:     .res 2
ptr:    .res 2
        .code
abs = $1234
zpc = $42
start:  lda #1
        lda zp
        lda zp,x
        ldx zp,y
        lda abs
        lda abs,x
        lda abs,y
        lda (ptr,x)
        lda (ptr),y
        jmp (abs)
        jmp (vector)
        asl
        asl a
        asl zpc
        asl zpc,x
        asl abs
        asl abs,x
        lda a:zpc
        lda a:zpc,x
        sta a:zp
        lda z:zpc
        lda zpc+1
        lda <abs
        lda >abs,x
        stx zpc,y
        sty zpc,x
        lda (zpc),y
        lda (zpc,x)
        bit zpc
        bit abs
        ldy #<start
        ldy #>start
        lda start
        lda start,x
        lda later
        lda later,y
        jsr start
        jmp later
later:  rts
vector: .addr start, later
        brk
        nop
        rti
