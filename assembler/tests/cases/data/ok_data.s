        .byte 1, $FF, "text", 'c'
        .asciiz "zero"
        .word $1234, label
        .addr label + 1
        .dbyt $1234, label
        .dword $12345678
        .lobytes $1234, $5678
        .hibytes $1234, $5678
        .bankbytes $123456
        .res 3
        .res 2, $EA
        .charmap $61, $41       ; 'a' -> 'A'
        .byte "abc", 'a'
label:  .align 4
        .byte $AA
        .align 4, $FF
        .byte $BB
