; questions.s: the questions. Each answer is its letter, its fields, and a
; carriage return (answer_done).

; /1B: Bhh, a bit per closed bumper.
ask_bumpers:
        jsr put_bumpers
        jmp answer_done

; /1E: E#.
ask_eyes:
        jsr put_eyes
        jmp answer_done

; /1G: G#.
ask_lamps:
        jsr put_lamps
        jmp answer_done

; /1T: T#, the ground-tracker phototransistors (1 right, 2 left, 3 both).
ask_tracker:
        jsr put_tracker
        jmp answer_done

; /1M: Ms####s####, left then right, since the last /1M or /1P; the counts
; restart from zero and the answer's counts stay in LASTMOVE.
ask_moves:
        jsr put_moves
        jmp answer_done

; /1X: Xhh, the busy byte.
ask_busy:
        jsr put_busy
        jmp answer_done

; /1C, /1D: C####, D####: steps left in that motor's specific move.
ask_remaining:
        lda CMDBUF
        jsr motor_index
        jsr put_remaining
        jmp answer_done

; /1P: P Bhh E# G# T# Ms####s#### Yhh Xhh C#### D####, without spaces.
ask_all:
        lda #'P'
        jsr putch
        jsr put_bumpers
        jsr put_eyes
        jsr put_lamps
        jsr put_tracker
        jsr put_moves
        lda #'Y'
        jsr putch
        lda IOBYTE
        jsr puthex
        jsr put_busy
        lda #'C'
        ldx #0
        jsr put_remaining
        lda #'D'
        ldx #1
        jsr put_remaining
        jmp answer_done

; /1S: Sd and the scanner buffer in hex.
ask_scan:
        lda #'S'
        jsr putch
        lda SCANLETTER
        jsr putch
        ldx #0
@byte:  lda SCANBUF,x
        jsr puthex
        inx
        cpx SCANLEN
        bne @byte
        jmp answer_done

; /7Raaaa##: R and ## bytes from aaaa in hex.
ask_memory:
        jsr get_address
        bcs @bad
        lda #2
        jsr getdec              ; Y is 5: the count, 00-99
        bcs @bad
        sta TMP
        lda #'R'
        jsr putch
        ldy #0
@byte:  cpy TMP
        beq @done
        lda (PTR),y
        jsr puthex
        iny
        bne @byte
@done:  jmp answer_done
@bad:   jmp unknown

put_bumpers:
        lda #'B'
        jsr putch
        lda VIA_ORA_NH          ; not ORA: that would clear the CA1 flag
        eor #$FF
        jmp puthex

put_eyes:
        lda #'E'
        jsr putch
        lda EYES
        jmp put_digit

put_lamps:
        lda #'G'
        jsr putch
        lda LAMPS
        jmp put_digit

put_tracker:
        lda #'T'
        jsr putch
        lda SENSE
        and #$03
put_digit:
        ora #'0'
        jmp putch

put_busy:
        lda #'X'
        jsr putch
        lda BUSY
        jmp puthex

; A = the letter, X = the motor: the letter and the steps left.
put_remaining:
        jsr putch
        php
        sei
        ldy REMHI,x
        lda REMLO,x
        plp
        tax
        jmp putdec4

; M and both counts; the counts move to LASTMOVE and restart from zero.
put_moves:
        php
        sei
        lda CNTLO
        sta LASTMOVE
        lda CNTHI
        sta LASTMOVE+1
        lda CNTLO+1
        sta LASTMOVE+2
        lda CNTHI+1
        sta LASTMOVE+3
        lda #0
        sta CNTLO
        sta CNTHI
        sta CNTLO+1
        sta CNTHI+1
        plp
        lda #'M'
        jsr putch
        ldx #0
        jsr put_count
        ldx #2
        ; fall through for the right motor

; X = 0 or 2: the sign and four digits of the count at LASTMOVE+X.
put_count:
        lda LASTMOVE+1,x
        bmi @minus
        lda #'+'
        jsr putch
        ldy LASTMOVE+1,x
        lda LASTMOVE,x
        tax
        jmp putdec4
@minus: lda #'-'
        jsr putch
        sec
        lda #0
        sbc LASTMOVE,x
        sta TMP
        lda #0
        sbc LASTMOVE+1,x
        tay
        ldx TMP
        jmp putdec4
