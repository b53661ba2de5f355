; loop.s: power-up, /1R, the control loop, the command parser, dispatch.

; Power-up: the 6551 is programmed from the DIP switches and the receive
; ring is emptied; then everything /1R does.
reset:
        sei
        cld
        ldx #$FF
        txs
        sta ACIA_STATUS         ; programmed reset
        lda SWITCHES
        and #$0F
        ora #ACIA_CTRL_8N1
        sta ACIA_CTRL
        lda #ACIA_CMD_RUN
        sta ACIA_CMD
        lda #0
        sta RXHEAD
        sta RXTAIL

; /1R: the power-up state of everything the ROM owns, hooks included. The
; 6551 keeps running and unread bytes stay in the ring, so a command sent
; right behind /1R is not lost. User RAM and user zero page are kept.
soft_reset:
        sei
        cld
        ldx #$FF
        txs
        lda #$7F
        sta VIA_IER             ; every VIA interrupt off
        sta VIA_IFR             ; every flag cleared
        lda #0
        sta TICKING             ; the motion tick is off
        ; Only the 6551 interrupts now, and with the tick off its handler
        ; touches only the receive ring: it keeps being served while the
        ; rest is reset, so a host byte that arrives meanwhile is never
        ; lost to an overrun.
        cli
        lda #0
        sta VIA_ACR
        sta VIA_PCR             ; CA1 interrupts on its falling edge
        sta VIA_DDRA            ; port A: the bumpers, inputs
        sta VIA_ORB
        sta DRIVE               ; lamps, motors, speaker off
        lda #$FF
        sta VIA_DDRB            ; port B: step and direction lines, outputs
        lda #0
        ldx #PTR
@zp:    sta 0,x                 ; the ROM's zero page, but the ring's indexes
        inx
        cpx #USER_ZP_START
        bne @zp
        ldx #ROMRAM_END - CMDLEN
@ram:   sta CMDLEN,x            ; the ROM's state in $0206-$021F
        dex
        bpl @ram
        lda #$4C                ; JMP
        sta HOOK_UNKNOWN
        sta HOOK_LOOP
        lda #<BAD_COMMAND
        sta HOOK_UNKNOWN+1
        lda #>BAD_COMMAND
        sta HOOK_UNKNOWN+2
        lda #<ROM_LOOP
        sta HOOK_LOOP+1
        lda #>ROM_LOOP
        sta HOOK_LOOP+2
        lda #$FF
        sta OBEYMASK
        lda #'H'                ; the scanner buffer: one byte, as a scan of 0
        sta SCANLETTER
        lda #1
        sta SCANLEN
        lda #0
        sta SCANBUF
        jsr check_bumpers
        jsr apply_io
        lda #$80 | IRQ_CA1      ; a bumper closing interrupts
        sta VIA_IER
        ; Nothing is installed, the hooks being the ROM's (clearing the
        ; flags bytes frees the entries), nothing injected, a host command
        ; next.
        lda #0
        .repeat EXTTAB_ENTRIES, entry
        sta EXTTAB + entry
        .endrepeat
        sta INJHEAD
        sta INJTAIL
        sta PSOURCE
        ; fall into the control loop

; The control loop. Every pass goes through HOOK_LOOP, which an operating
; system in RAM may take over; ROM_LOOP is its first target.
main_loop:
        jmp HOOK_LOOP

; Inside a command its bytes come from where it began, so neither the
; host's commands nor injected ones are ever cut by the other (the other's
; bytes wait in their queue). Between commands the two take turns: after
; an injected command the host's waiting bytes go first, after the host's
; an injected one, so neither starves the other. (The idle path only
; reads, so the emulator can skip it exactly.)
rom_loop:
        lda PSTATE
        beq @boundary
        lda PSOURCE
        bne @injected
        beq @host
@boundary:
        lda PSOURCE
        beq @inject_turn        ; the last command was the host's
        ldx RXTAIL
        cpx RXHEAD
        bne @host               ; the last was injected and the host waits
@inject_turn:
        ldx INJTAIL
        cpx INJHEAD
        beq @host               ; nothing injected: the host's turn
@injected:
        ldx INJTAIL
        cpx INJHEAD
        beq main_loop           ; the rest of the command is still being fed
        lda INJBUF,x
        inx
        pha
        txa
        and #INJBUF_SIZE - 1
        sta INJTAIL
        pla
        ldy #1                  ; Y: where the byte came from, for a new command
        bne @parse
@host:  ldx RXTAIL
        cpx RXHEAD
        beq main_loop           ; nothing received
        lda RXBUF,x
        inx
        stx RXTAIL
        ldy #0
@parse: cmp #'/'
        beq @slash              ; a slash always starts a command (resync)
        ldx PSTATE
        beq main_loop           ; outside a command: ignored
        dex
        bne @byte
        sec                     ; the count digit, 1-9
        sbc #'1'
        cmp #9
        bcs @drop
        adc #1
        sta PCOUNT
        lda #0
        sta CMDLEN
        lda #2
        sta PSTATE
        jmp main_loop
@drop:  lda #0
        sta PSTATE
        jmp main_loop
@slash: sty PSOURCE             ; the command's bytes come from here on
        lda #1
        sta PSTATE
        jmp main_loop
@byte:  ldx CMDLEN
        sta CMDBUF,x
        inx
        stx CMDLEN
        cpx PCOUNT
        beq dispatch
        jmp main_loop

; A whole command is in CMDBUF: find its handler by (count, letter).
dispatch:
        lda #0
        sta PSTATE
        ldy #0
@next:  lda commands,y
        beq unknown
        cmp CMDLEN
        bne @skip
        lda commands+1,y
        cmp CMDBUF
        bne @skip
        lda commands+2,y
        sta PTR
        lda commands+3,y
        sta PTR+1
        jmp (PTR)
@skip:  iny
        iny
        iny
        iny
        bne @next

; Unknown commands, and known ones with malformed arguments, go through
; HOOK_UNKNOWN with A = the letter and X = the count.
unknown:
        lda CMDBUF
        ldx CMDLEN
        jmp HOOK_UNKNOWN

; HOOK_UNKNOWN's first target: the command is dropped with no answer.
bad_command:
        jmp cmd_done

; Every command ends here: a closed bumper keeps setting master bit 7, the
; Master I/O byte is obeyed, and the loop goes on.
cmd_done:
        jsr check_bumpers
        jsr apply_io
        jmp main_loop

; An answer's carriage return, then cmd_done.
answer_done:
        jsr puteol
        jmp cmd_done

; Sets master bit 7 while any bumper is closed (port A reads 0 for a
; closed switch).
check_bumpers:
        lda VIA_ORA_NH
        cmp #$FF
        beq @open
        lda IOBYTE
        ora #$80
        sta IOBYTE
@open:  rts

; (count, letter, handler) for every command of docs/PROTOCOL.md section 2.
commands:
        .byte 1, 'R'
        .addr soft_reset
        .byte 1, 'B'
        .addr ask_bumpers
        .byte 1, 'S'
        .addr ask_scan
        .byte 1, 'E'
        .addr ask_eyes
        .byte 1, 'G'
        .addr ask_lamps
        .byte 1, 'T'
        .addr ask_tracker
        .byte 1, 'M'
        .addr ask_moves
        .byte 1, 'X'
        .addr ask_busy
        .byte 1, 'C'
        .addr ask_remaining
        .byte 1, 'D'
        .addr ask_remaining
        .byte 1, 'P'
        .addr ask_all
        .byte 2, 'E'
        .addr cmd_eyes
        .byte 2, 'G'
        .addr cmd_lamps
        .byte 3, 'Y'
        .addr cmd_setio
        .byte 3, 'Z'
        .addr cmd_obey
        .byte 3, 'K'
        .addr cmd_tone
        .byte 3, 'H'
        .addr cmd_scan
        .byte 3, 'V'
        .addr cmd_scan
        .byte 4, 'C'
        .addr cmd_continuous
        .byte 4, 'D'
        .addr cmd_continuous
        .byte 7, 'R'
        .addr ask_memory
        .byte 7, 'W'
        .addr cmd_write1
        .byte 8, 'C'
        .addr cmd_move
        .byte 8, 'D'
        .addr cmd_move
        .byte 9, 'W'
        .addr cmd_write2
        .byte 0
