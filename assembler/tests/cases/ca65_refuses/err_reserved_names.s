; Names ca65 reserves: the registers wherever a name is declared, the
; instructions where a name starts a statement or names a macro. Each line
; that must fail says so with ca65 2.19's first words for it;
; tests/tests/asm_ca65_refuses.rs checks that ca65 and we refuse exactly
; the lines marked `ca65:`.
ADC = $9000                     ; ca65: Syntax error
adc:    nop                     ; ca65: Syntax error
lda := 5                        ; ca65: Syntax error
sta .set 1                      ; ca65: Syntax error
x = 5                           ; ca65: Unexpected trailing garbage characters
a:      nop                     ; ca65: Unexpected trailing garbage characters
        .import y               ; ca65: Identifier expected
        .define adc 5           ; ca65: Cannot use an instruction as macro name
        .macro jmp              ; ca65: Cannot use an instruction as macro name
        .endmacro
        .macro m x              ; ca65: Unexpected trailing garbage characters
        .endmacro
        .enum
        x                       ; ca65: Identifier expected
        .endenum
        .struct s
        y .byte                 ; ca65: Invalid storage allocator in struct/union
        .endstruct
; Accepted by ca65 and by us: instruction names where no statement starts.
        .proc adc
        .endproc
        .enum
        lda
        .endenum
        .scope sta
        .endscope
        .macro mm adc
        .endmacro
