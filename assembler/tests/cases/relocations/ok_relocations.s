; Every relocation the assembler writes.
        .import far, near_fn
        .importzp zpext
        .code
start:  lda #<far               ; R_MOS_ADDR16_LO
        lda #>far               ; R_MOS_ADDR16_HI
        lda #^far               ; R_MOS_ADDR24_BANK
        lda #<(far + 300)       ; addend
        lda #>far + 1           ; (>far) + 1 = >(far + 256)
        lda #far                ; R_MOS_IMM8
        lda zpext               ; R_MOS_ADDR8
        lda (zpext),y
        lda far                 ; R_MOS_ADDR16
        jsr near_fn
        jmp local + 2           ; section symbol + offset
        beq near_fn             ; R_MOS_PCREL_8 to an import
        bne other               ; another section: R_MOS_PCREL_8
        bne $1000               ; a fixed address from relocatable code
local:  rts
        .word far, local
        .byte <far, >local
        .dbyt far
        .word <far
        .rodata
other:  .byte 0
