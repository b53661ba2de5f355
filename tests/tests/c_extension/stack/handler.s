; The command /1K for the C function range_sum(start, length): it sets up
; the C stack, passes `table` and 4 as cc65 passes arguments (the first
; pushed, the last in A) and answers K and the sum in four hex digits.
        .include "scorpion.inc"
        .import answer_sum, _range_sum, pushax
        .importzp sp

        .bss
cstack: .res 32                 ; the C stack, growing down from its end
cstack_end:

        .rodata
table:  .byte $10, $20, $30, $FF

        .code
        SCORPION_UNKNOWN_HANDLER
handler:
        cpx #1
        bne not_mine
        cmp #'K'
        bne not_mine
        lda #<cstack_end
        sta sp
        lda #>cstack_end
        sta sp+1
        lda #<table
        ldx #>table
        jsr pushax              ; start
        lda #4                  ; length, in A
        jsr _range_sum          ; the sum in A (low) and X (high)
        jmp answer_sum
not_mine:
        SCORPION_CHAIN_UNKNOWN
