; The answer both extensions give: K and the sum in A (low) and X (high)
; as four hex digits (K015F), then the command is done.
        .include "scorpion.inc"
        .export answer_sum

        .bss
sum:    .res 2

        .code
answer_sum:
        sta sum
        stx sum+1
        lda #'K'
        jsr PUTCH
        lda sum+1
        jsr PUTHEX
        lda sum
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE
