; rangefinder.s: a new command for a device on a KIM-bus card.
;
; The card: an ultrasonic rangefinder on the Scorpion's KIM bus, at $8000
; (the address is set by jumpers on the card). Four registers:
;
;   $8000  CONTROL  write 1: send a ping and time its echo
;   $8001  STATUS   bit 7: 1 while measuring; bit 0: 1 if no echo came back
;   $8002  RANGE_LO the distance to the nearest obstacle in centimetres,
;   $8003  RANGE_HI   valid once bit 7 of STATUS is 0
;
; The command: /1U answers U####, the distance in centimetres, or U----
; when nothing is in range. The ROM does not know /1U, so it reaches this
; handler through HOOK_UNKNOWN; any other command goes on down the chain.
;
; Build and try it on the virtual Scorpion, with the card's model
; (rangefinder.rhai, a script: its obstacle is 123 cm away):
;
;   scorpion build examples/rangefinder/rangefinder.s -o rangefinder.elf --target scorpion-ext
;   echo /1U | scorpion sim --image rangefinder.elf --card examples/rangefinder/rangefinder.rhai
;
; Everything comes from scorpion.inc: the hook macros, PUTCH and friends,
; CMD_DONE. The image needs no start-up code: the loader writes it into
; user RAM and then points HOOK_UNKNOWN at the handler.

        .include "scorpion.inc"

RANGER          = $8000
RANGER_CONTROL  = RANGER
RANGER_STATUS   = RANGER + 1
RANGER_LO       = RANGER + 2
RANGER_HI       = RANGER + 3

        .code

; HOOK_UNKNOWN lands here with A = the command letter, X = its count.
        SCORPION_UNKNOWN_HANDLER
rangefinder:
        cpx #1
        bne not_mine
        cmp #'U'
        bne not_mine

        lda #1
        sta RANGER_CONTROL      ; ping
        ldx #0                  ; 12 x 256 looks of 11 cycles: 34 ms, past
        ldy #12                 ; the card's 25 ms with no echo
@wait:  bit RANGER_STATUS       ; a round trip takes 58 us per centimetre;
        bpl @measured           ; interrupts keep receiving meanwhile
        dex
        bne @wait
        dey
        bne @wait
        beq @silent             ; still measuring: no card there

@measured:
        lda #'U'
        jsr PUTCH
        lda RANGER_STATUS
        lsr                     ; bit 0 into carry: no echo?
        bcs @nothing
        ldx RANGER_LO
        ldy RANGER_HI
        jsr PUTDEC4
        jmp @done
; Without the card STATUS reads whatever the bus floats to on a real robot
; (bit 7 set: measuring for ever); answer as for no echo rather than hold the
; robot's control loop.
@silent:
        lda #'U'
        jsr PUTCH
@nothing:
        lda #'-'
        ldx #4
@dash:  jsr PUTCH
        dex
        bne @dash
@done:  jsr PUTEOL
        jmp CMD_DONE

; Not ours: on to whatever HOOK_UNKNOWN pointed at before us, with A and X
; as they came.
not_mine:
        SCORPION_CHAIN_UNKNOWN
