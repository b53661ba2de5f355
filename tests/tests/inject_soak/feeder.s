; An operating system that gives the ROM a command through INJECT on every
; pass of the control loop, for ever: the hardest case for the host's own
; commands, which must never be cut, lost or reordered by injected text.
; It feeds "/7W050042" (a byte into user RAM) a character at a time, as
; far as INJECT's queue takes it, and goes on where it stopped on the next
; pass; `fed` counts the whole commands fed.
        .include "scorpion.inc"

        .data
pos:    .byte 0                 ; the next character of `text` to feed
fed:    .word 0                 ; whole commands fed

        .rodata
text:   .byte "/7W050042", 0

        .code
        SCORPION_LOOP_HANDLER
feed:   ldx pos
@next:  lda text,x
        beq @whole
        jsr INJECT
        bcs @later              ; the queue is full: go on next pass
        inx
        bne @next
@whole: ldx #0
        inc fed
        bne @later
        inc fed+1
@later: stx pos
        SCORPION_CHAIN_LOOP
