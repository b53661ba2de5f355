; linefollow.s: an operating system in RAM that follows a line on the
; floor (reflective tape on a dark floor) to its end.
;
;   /2L1   start following          /2L0   stop
;
; Like patrol (examples/patrol), it takes HOOK_LOOP and HOOK_UNKNOWN and
; chains to the ROM's loop on every pass, so the robot answers every
; command meanwhile. /2L1 lights the ground-tracker lamps; then each pass,
; once the ROM has taken its last commands (PENDING), it reads the two
; phototransistors at SENSE ($C021: bit 0 the right one, bit 1 the left)
; and, when what they see has changed, steers with the motor commands:
;
;   both lit    both drives on                 (on the line)
;   left only   left drive stopped, right on   (the line turns left)
;   right only  right drive stopped, left on   (the line turns right)
;   neither     both stopped, lamps off, done  (the line's end)
;
; Neither lit before the line was seen once is waiting, not the end (the
; lamps come on a moment after /2L1).
;
;   scorpion build examples/linefollow/linefollow.s -o linefollow.elf --target scorpion-os

        .include "scorpion.inc"

SENSE           = $C021         ; the phototransistors: bit 0 right, bit 1 left
LOST            = $FF           ; `last` before anything was seen

        .zeropage
text:           .res 2

        .data
following:      .byte 0         ; 1 while following
seen:           .byte 0         ; 1 once a tracker saw the line
last:           .byte LOST      ; what the trackers saw when we last steered

        .rodata
lamps:          .byte "/3Y00/3ZFF/2G1", 0
ahead:          .byte "/4C+40/4D+40", 0
left:           .byte "/4C+00/4D+40", 0
right:          .byte "/4C+40/4D+00", 0
halt:           .byte "/4C+00/4D+00/2G0", 0

        .code

; ---- every pass of the control loop ------------------------------------
        SCORPION_LOOP_HANDLER
follow:
        lda following
        beq rom
        jsr PENDING
        bne rom                 ; our last commands are not all taken yet
        lda SENSE
        and #3
        cmp last
        beq rom                 ; nothing new: the drives go on as they are
        sta last
        tax
        beq @neither
        lda #1
        sta seen
        cpx #3
        beq @both
        cpx #2
        beq @left
        ldx #<right
        ldy #>right
        jsr say
        jmp rom
@left:  ldx #<left
        ldy #>left
        jsr say
        jmp rom
@both:  ldx #<ahead
        ldy #>ahead
        jsr say
        jmp rom
@neither:
        lda seen
        beq rom                 ; the lamps are not on yet
        jsr stop
rom:
        SCORPION_CHAIN_LOOP

; Both drives and the lamps off: following ends.
stop:
        lda #0
        sta following
        ldx #<halt
        ldy #>halt
        jmp say

; ---- /2L1 and /2L0 ------------------------------------------------------
        SCORPION_UNKNOWN_HANDLER
command:
        cpx #2
        bne not_mine
        cmp #'L'
        bne not_mine
        lda CMDBUF+1
        cmp #'1'
        beq @start
        cmp #'0'
        bne @malformed
        jsr stop
        jmp CMD_DONE
@start: lda #1
        sta following
        lda #0
        sta seen
        lda #LOST
        sta last
        ldx #<lamps
        ldy #>lamps
        jsr say
        jmp CMD_DONE
@malformed:
        lda CMDBUF
        ldx CMDLEN
not_mine:
        SCORPION_CHAIN_UNKNOWN

; Feeds the zero-terminated command text at X (low) / Y (high) to the
; ROM's parser (INJECT), as if the host had sent it; said only when
; PENDING shows the queue empty, and every text here fits the queue.
say:
        stx text
        sty text+1
        ldy #0
@next:  lda (text),y
        beq @end
        jsr INJECT
        bcs @end
        iny
        bne @next
@end:   rts
