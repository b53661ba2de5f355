; test program
        .segment "ZEROPAGE"
ptr:    .res 2
        .code
start:  lda #<msg
        sta ptr
        lda #>msg
        sta ptr+1
        ldy #0
@loop:  lda (ptr),y
        beq @done
        jsr putch
        iny
        bne @loop
@done:  rts
        lda fwd
        lda fwd+1
        jmp ($12FF)
putch:  rts
fwdzp = $12
fwd = $1234
        .rodata
msg:    .byte "Hello", 0
        .word start, msg+1
        .dbyt $1234
