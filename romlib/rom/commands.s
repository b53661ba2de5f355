; commands.s: the instructions (no answer). Each handler ends at cmd_done;
; a malformed argument sends the command to HOOK_UNKNOWN instead.

malformed:
        jmp unknown

; /3Yhh: the Master I/O byte (cmd_done then re-applies the bumper rule).
cmd_setio:
        ldy #1
        jsr gethex
        bcs malformed
        sta IOBYTE
        jmp cmd_done

; /3Zhh: the obey/ignore mask.
cmd_obey:
        ldy #1
        jsr gethex
        bcs malformed
        sta OBEYMASK
        jmp cmd_done

; /2E#: eyes, 0 off, 1 right, 2 left, 3 both.
cmd_eyes:
        lda CMDBUF+1
        sec
        sbc #'0'
        cmp #4
        bcs malformed
        sta EYES
        jmp cmd_done

; /2G#: tracker lamps, 0 off, 1 on.
cmd_lamps:
        lda CMDBUF+1
        sec
        sbc #'0'
        cmp #2
        bcs malformed
        sta LAMPS
        jmp cmd_done

; /3Khh: speaker tone; hh is the half period in units of 32 cycles (timer 1
; free-running on PB7 with a latch of hh * 32), 00 is silence.
cmd_tone:
        ldy #1
        jsr gethex
        bcs malformed
        sta TONE
        beq @off
        sta TMP
        asl
        asl
        asl
        asl
        asl
        sta VIA_T1CL            ; latch low
        lda TMP
        lsr
        lsr
        lsr
        sta VIA_T1CH            ; latch high, and the timer starts
@off:   jmp cmd_done

; /4Cdff, /4Ddff: continuous mode at speed ff (00 stops it).
cmd_continuous:
        jsr get_dir_speed
        bcs malformed
        jsr motor_index
        php
        sei
        sta CSPEED,x
        lda TMP
        sta CDIR,x
        plp
        jsr tick_start
        jmp cmd_done

; /8Cdff####, /8Ddff####: a specific move of #### steps. Inside continuous
; mode it runs, then continuous mode resumes, and it is not counted in
; /1M; from a standstill it is counted. Speed 00 cancels the specific move.
cmd_move:
        jsr get_dir_speed
        bcs @bad
        sta TMP2
        lda #4
        jsr getdec              ; Y is 4: the steps
        bcs @bad
        jsr motor_index
        php
        sei
        lda TMP2
        beq @cancel
        sta SSPEED,x
        lda TMP
        sta SDIR,x
        ldy #1
        lda CSPEED,x
        beq @counted
        dey
@counted:
        sty SCOUNT,x
        lda NUM
        sta REMLO,x
        lda NUM+1
        sta REMHI,x
        plp
        jsr tick_start
        jmp cmd_done
@cancel:
        lda #0
        sta REMLO,x
        sta REMHI,x
        plp
        jmp cmd_done
@bad:   jmp unknown

; /3H##, /3V##: a scan of ## steps each side (01-99). A scan asked for while
; one is running is ignored (it would overrun the buffer).
cmd_scan:
        lda SCANST
        bne @busy
        ldy #1
        lda #2
        jsr getdec
        bcs @bad
        cmp #1
        bcc @bad
        sta SCANN
        asl
        adc #1                  ; 2n+1 readings
        sta SCANLEN
        tax
        lda #0
@clear: sta SCANBUF-1,x
        dex
        bne @clear
        lda CMDBUF
        sta SCANLETTER
        ldx #$08                ; busy bit 3: the horizontal scanner
        cmp #'H'
        beq @axis
        ldx #$10                ; busy bit 4: the vertical scanner
@axis:  stx SCANBIT
        lda #0
        sta SCANPOS
        sta SCANIDX
        lda #1
        sta SCANDIV
        sta SCANST              ; phase 1: to -n
        jsr tick_start
@busy:  jmp cmd_done
@bad:   jmp unknown

; /7Waaaahh: write one byte.
cmd_write1:
        jsr get_address
        bcs malformed2
        jsr gethex
        bcs malformed2
        ldy #0
        sta (PTR),y
        jmp cmd_done

; /9Waaaahhhh: write two bytes in one go (interrupts off between them, so
; a hook's operand switches atomically).
cmd_write2:
        jsr get_address
        bcs malformed2
        jsr gethex
        bcs malformed2
        sta TMP
        jsr gethex
        bcs malformed2
        sta TMP2
        php
        sei
        ldy #0
        lda TMP
        sta (PTR),y
        iny
        lda TMP2
        sta (PTR),y
        plp
        jmp cmd_done

malformed2:
        jmp unknown

; X = 0 for a C (left) command, 1 for D (right). A is kept.
motor_index:
        ldx #0
        pha
        lda CMDBUF
        cmp #'C'
        beq @left
        inx
@left:  pla
        rts

; CMDBUF+1 is the direction (+ or -) into TMP (1 = +); CMDBUF+2..3 the
; decimal speed into A; Y ends at 4. Carry set if malformed.
get_dir_speed:
        ldx #1
        lda CMDBUF+1
        cmp #'+'
        beq @dir
        dex
        cmp #'-'
        bne @bad
@dir:   stx TMP
        ldy #2
        lda #2
        jmp getdec
@bad:   sec
        rts

; CMDBUF+1..4: a hex address into PTR; Y ends at 5. Carry set if malformed.
get_address:
        ldy #1
        jsr gethex
        bcs @bad
        sta PTR+1
        jsr gethex
        bcs @bad
        sta PTR
@bad:   rts
