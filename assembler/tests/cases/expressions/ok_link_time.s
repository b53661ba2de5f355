; Arithmetic on addresses that no ELF relocation can carry: the object
; lists each field with its expression (.scorpion.exprs) and the linker
; computes it, as ld65 finishes ca65's expressions.
        .code
start:  lda #<(start * 2 / 256)
        .word data_end - start
        .word data_end + start - $0800
        .byte <(start & $FF)
        .word $10000 - start
        lda #<(data_end / 256)
        .dbyt data_end * 2 - start
        .dword start * 3
        .rodata
data:   .byte 1
data_end:
