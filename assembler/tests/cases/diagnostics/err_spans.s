; Each error marks the part of the line that is wrong: the list item, the
; sub-expression or the symbol, the operand whose mode does not exist.
table = $1234
        .byte 1, 256, 3                 ; the second item
        .word table, missing + 1, 3     ; the undefined name
        lda table + absent * 2, x       ; the undefined name inside
        lda #1 + 2 / 0                  ; the division, not the operand
        .byte (4 - 4) + 7 .mod (3 - 3)  ; the .mod, not the sum
        stx table,x                     ; the operand: absolute,X
        sta #3                          ; the operand: immediate
        jmp ($12),y                     ; the operand: (indirect),Y
        lda (table)                     ; the operand: (indirect)
        .res 1 + later * 2              ; the name not defined yet
        .charmap 65, 300                ; the second code
        ldx ($1234,x)                   ; the operand: (indirect,X)
        lda ($1234,x)                   ; the pointer, out of zero page
later = 2
loop_a = loop_b + 1
loop_b = loop_a + 1
        .byte 1 + loop_a                ; the circular name
