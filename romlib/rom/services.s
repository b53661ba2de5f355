; services.s: serial output and input, and argument parsing. These are the
; jump table's targets; all keep X and Y unless they say otherwise.

; Sends A (A, X, Y kept). Transmission is polled, but reading the 6551's
; status clears its IRQ bit, so a byte that arrived meanwhile would never
; interrupt: the loop takes it into the ring itself, with interrupts off.
putch:
        pha
        txa
        pha
@poll:  sei
        lda ACIA_STATUS
        sta PUTST
        and #ST_RDRF
        beq @tx
        lda ACIA_DATA
        jsr rx_put
@tx:    cli
        lda PUTST
        and #ST_TDRE
        beq @poll
        pla
        tax
        pla
        sta ACIA_DATA
        rts

; Sends A as two upper-case hex digits (A, X, Y kept).
puthex:
        pha
        lsr
        lsr
        lsr
        lsr
        jsr @nibble
        pla
        pha
        and #$0F
        jsr @nibble
        pla
        rts
@nibble:
        cmp #10
        bcc @digit
        adc #6                  ; carry is set: A-F
@digit: adc #'0'
        jmp putch

; Sends X (low) / Y (high) as four decimal digits; 9999 if larger.
putdec4:
        stx NUM
        sty NUM+1
        txa
        pha
        tya
        pha
        lda NUM+1
        cmp #>10000
        bcc @fits
        bne @clamp
        lda NUM
        cmp #<10000
        bcc @fits
@clamp: lda #<9999
        sta NUM
        lda #>9999
        sta NUM+1
@fits:  ldy #0
@digit: lda #'0'
        sta DIGIT
@sub:   lda NUM
        sec
        sbc powers_lo,y
        tax
        lda NUM+1
        sbc powers_hi,y
        bcc @put
        sta NUM+1
        stx NUM
        inc DIGIT
        bne @sub
@put:   lda DIGIT
        jsr putch
        iny
        cpy #4
        bne @digit
        pla
        tay
        pla
        tax
        rts

powers_lo:
        .byte <1000, <100, <10, <1
powers_hi:
        .byte >1000, >100, >10, >1

; Ends an answer: the carriage return (A, X, Y kept).
puteol:
        pha
        lda #$0D
        jsr putch
        pla
        rts

; The two hex digits at CMDBUF+Y into A, Y advanced past them; carry set
; (and Y unchanged) if they are not hex. Lower case is accepted. X kept.
gethex:
        lda CMDBUF,y
        jsr hexdigit
        bcs @bad
        asl
        asl
        asl
        asl
        sta HTMP
        lda CMDBUF+1,y
        jsr hexdigit
        bcs @bad
        ora HTMP
        iny
        iny
        clc
@bad:   rts

; An ASCII hex digit in A to 0-15, carry clear; carry set if not hex.
hexdigit:
        cmp #'0'
        bcc @bad
        cmp #'9'+1
        bcc @decimal
        and #$DF                ; upper case
        cmp #'A'
        bcc @bad
        cmp #'F'+1
        bcs @bad
        sbc #'A'-11             ; carry is clear: A - 'A' + 10
        clc
        rts
@decimal:
        sbc #'0'-1              ; carry is clear: A - '0'
        clc
        rts
@bad:   sec
        rts

; A (1-4) decimal digits at CMDBUF+Y into A (low) and X (high), Y advanced
; past them; carry set if one is not a digit.
getdec:
        sta DIGIT
        lda #0
        sta NUM
        sta NUM+1
@digit: lda CMDBUF,y
        sec
        sbc #'0'
        cmp #10
        bcs @bad
        pha
        asl NUM                 ; NUM * 10 = NUM * 2 + NUM * 8
        rol NUM+1
        lda NUM
        ldx NUM+1
        asl NUM
        rol NUM+1
        asl NUM
        rol NUM+1
        clc
        adc NUM
        sta NUM
        txa
        adc NUM+1
        sta NUM+1
        pla
        clc
        adc NUM
        sta NUM
        bcc @next
        inc NUM+1
@next:  iny
        dec DIGIT
        bne @digit
        lda NUM
        ldx NUM+1
        clc
        rts
@bad:   sec
        rts

; A = the devices the Master I/O byte switches off now: device i is off iff
; (OBEYMASK_i and IOBYTE_i) or (OBEYMASK_7 and IOBYTE_7).
io_inhibit:
        lda IOBYTE
        and OBEYMASK
        bpl @some
        lda #$FF
@some:  rts

; Waits for the next received byte and returns it in A (X, Y kept). For
; extensions that read their own data after their command.
getch:
        jsr chkch
        bcs getch
        rts

; The next received byte in A with carry clear, or carry set if none.
chkch:
        stx GTMP
        ldx RXTAIL
        cpx RXHEAD
        beq @none
        lda RXBUF,x
        inx
        stx RXTAIL
        ldx GTMP
        clc
        rts
@none:  ldx GTMP
        sec
        rts

; INJECT: queues A for the command parser, so a program in RAM can give
; the ROM commands ("/4C+40"). Injected text has a queue of its own and is
; parsed between commands only: it never cuts into a command the host is
; sending, and the host's bytes are never lost or reordered by it. Carry
; set if the queue was full (A not queued: call again on a later pass);
; A, X, Y kept.
inject:
        pha
        stx GTMP
        ldx INJHEAD
        sta INJBUF,x            ; (harmless in the free slot when full)
        inx
        txa
        and #INJBUF_SIZE - 1
        cmp INJTAIL
        beq @full               ; one slot stays free
        sta INJHEAD
        pla
        ldx GTMP
        clc
        rts
@full:  pla
        ldx GTMP
        sec
        rts

; PENDING: how many received or injected bytes the parser has not seen
; yet. Zero means every command fed so far has been dispatched.
pending:
        lda RXHEAD
        sec
        sbc RXTAIL
        cmp #256 - INJBUF_SIZE
        bcs @many               ; the ring nearly full: the sum could wrap
        lda INJHEAD
        sec
        sbc INJTAIL
        and #INJBUF_SIZE - 1
        clc
        adc RXHEAD
        sec
        sbc RXTAIL
@many:  cmp #0                  ; Z set if none
        rts

; Puts A into the receive ring (X lost); a full ring drops it. Called with
; interrupts off.
rx_put:
        ldx RXHEAD
        sta RXBUF,x
        inx
        cpx RXTAIL
        beq @full
        stx RXHEAD
@full:  rts
