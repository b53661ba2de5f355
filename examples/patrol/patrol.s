; patrol.s: an operating system in RAM that takes over the control loop.
;
; Patrol mode: the robot cruises forward; when a bumper closes it backs
; away, turns, and cruises on, on its own, with no host in the loop. The
; host switches it with a new command:
;
;   /2A1   start patrolling         /2A0   stop
;
; It takes both hooks: HOOK_LOOP, which the ROM's control loop jumps
; through on every pass, and HOOK_UNKNOWN for /2A#. Each pass it looks at
; the Master I/O byte (a closed bumper sets its bit 7) and the busy byte,
; then goes on to one pass of the ROM's own loop (SCORPION_CHAIN_LOOP), so
; the robot keeps answering every command of the protocol. Because of that
; chain, /1R still works; an operating system that does not chain owns the
; robot until power-off, as the article warns.
;
; It moves the robot with the ROM's own commands, fed to the ROM's parser
; with INJECT as if the host had sent them, and waits with PENDING until
; the ROM has taken them before it looks at the busy byte.
;
; It lives in KIM-bus expansion RAM (the scorpion-os target: code and data
; from $1000), its one pointer in the user zero page:
;
;   scorpion build examples/patrol/patrol.s -o patrol.elf --target scorpion-os

        .include "scorpion.inc"

CRUISING        = 1
BACKING         = 2
TURNING         = 3
DRIVES_BUSY     = $60           ; busy-byte bits 5 and 6

        .zeropage
text:           .res 2

        .data
state:          .byte 0         ; 0 stopped, or CRUISING, BACKING, TURNING

        .rodata
cruise:         .byte "/3Y00/3ZFF/4C+40/4D+40", 0
halt:           .byte "/4C+00/4D+00", 0
back_away:      .byte "/4C+00/4D+00/3Z7F/8C-400100/8D-400100", 0
turn:           .byte "/8C+400060/8D-400060", 0

        .code

; ---- every pass of the control loop ------------------------------------
        SCORPION_LOOP_HANDLER
patrol:
        lda state
        beq rom                 ; stopped: the ROM's loop only
        jsr PENDING
        bne rom                 ; our last commands are not all taken yet
        lda state
        cmp #CRUISING
        bne manoeuvre
        bit IOBYTE              ; bit 7: a bumper closed
        bpl rom
        ldx #<back_away
        ldy #>back_away
        jsr say
        lda #BACKING
        sta state
        jmp rom

manoeuvre:
        lda BUSY
        and #DRIVES_BUSY
        bne rom                 ; the move is still running
        lda state
        cmp #BACKING
        bne @turned
        ldx #<turn
        ldy #>turn
        jsr say
        lda #TURNING
        sta state
        jmp rom
@turned:
        ldx #<cruise
        ldy #>cruise
        jsr say
        lda #CRUISING
        sta state
rom:
        SCORPION_CHAIN_LOOP

; ---- /2A1 and /2A0 ------------------------------------------------------
        SCORPION_UNKNOWN_HANDLER
command:
        cpx #2
        bne not_mine
        cmp #'A'
        bne not_mine
        lda CMDBUF+1
        cmp #'1'
        beq @start
        cmp #'0'
        bne @malformed
        lda #0
        sta state
        ldx #<halt
        ldy #>halt
        jsr say
        jmp CMD_DONE
@start: lda #CRUISING
        sta state
        ldx #<cruise
        ldy #>cruise
        jsr say
        jmp CMD_DONE
@malformed:
        lda CMDBUF
        ldx CMDLEN
not_mine:
        SCORPION_CHAIN_UNKNOWN

; Feeds the zero-terminated command text at X (low) / Y (high) to the
; ROM's parser. INJECT's queue is the ROM's, apart from the host's bytes,
; and is parsed between commands only, so nothing here keeps the host out
; (interrupts stay on: the 6551 is served). Patrol says something only
; when PENDING shows the queue empty, and its longest text fits the queue.
say:
        stx text
        sty text+1
        ldy #0
@next:  lda (text),y
        beq @end
        jsr INJECT
        bcs @end                ; the queue is full (never, as used here)
        iny
        bne @next
@end:   rts
