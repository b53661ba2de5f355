; Data directives in every segment, strings with .charmap, .res, .align.
        .segment "ZEROPAGE"
zvar:   .res 1
        .code
        lda zvar
        lda table
        lda buffer
        .byte "plain", 0
        .asciiz "zero"
        .charmap $41, $61
        .byte "ABC", 'A'
        .asciiz "A"
        .charmap $41, $41
        .byte "A"
        .word $1234, table, table + 1
        .addr buffer
        .dbyt $1234, table
        .lobytes table, buffer, $1234
        .hibytes table, buffer, $1234
        .bankbytes table, $123456
        .dword $DEADBEEF
        .res 3
        .res 2, $EA
        .align 8
aligned: .byte $AA
        .align 2, $FF
        .byte $BB
        .rodata
table:  .byte 1, 2, 3
        .word aligned
        .data
        .byte 9
ptrs:   .word table, buffer, ptrs
        .bss
buffer: .res 16
more:   .res 1
