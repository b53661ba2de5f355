; The command /1K for the C function range_sum: it sums the four bytes of
; `table` and answers K and the sum in four hex digits (K015F).
        .include "scorpion.inc"
        .import answer_sum, _range_sum, _range_start, _range_length
        .exportzp ptr1

        .zeropage
ptr1:   .res 2                  ; the compiler's pointer cell

        .rodata
table:  .byte $10, $20, $30, $FF

        .code
        SCORPION_UNKNOWN_HANDLER
handler:
        cpx #1
        bne not_mine
        cmp #'K'
        bne not_mine
        lda #<table
        sta _range_start
        lda #>table
        sta _range_start+1
        lda #4
        sta _range_length
        jsr _range_sum          ; the sum in A (low) and X (high)
        jmp answer_sum
not_mine:
        SCORPION_CHAIN_UNKNOWN
