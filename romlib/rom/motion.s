; motion.s: the interrupt handler (serial receive, bumpers, the motion
; tick), the stepper and scanner state machines, and the Master I/O byte.

nmi:    rti                     ; NMI is not connected on the Scorpion

; IRQ: the 6551 (a byte received), the 6522's CA1 (a bumper closed) and
; its timer 2 (the 1 kHz motion tick, running only while something moves).
; BRK lands here too and finds nothing to do.
irq:    pha
        txa
        pha
        tya
        pha
        lda ACIA_STATUS         ; clears the 6551's IRQ bit
        and #ST_RDRF
        beq @bumper
        lda ACIA_DATA
        jsr rx_put
@bumper:
        lda VIA_IFR
        and #IRQ_CA1
        beq @tick
        lda VIA_ORA             ; clears the CA1 flag
        cmp #$FF
        beq @tick
        lda IOBYTE              ; a closed bumper sets master bit 7
        ora #$80
        sta IOBYTE
        jsr apply_io
@tick:  lda TICKING
        beq @done
        lda VIA_IFR
        and #IRQ_T2
        beq @done
        jsr tick
@done:  pla
        tay
        pla
        tax
        pla
        rti

; Starts the tick if something needs it.
tick_start:
        lda TICKING
        bne @running
        jsr anything_moves
        beq @running
        php
        sei
        lda #<TICK_LOAD
        sta VIA_T2CL
        lda #>TICK_LOAD
        sta VIA_T2CH
        lda #$80 | IRQ_T2
        sta VIA_IER
        lda #1
        sta TICKING
        plp
@running:
        rts

; Z clear if a drive has work (a specific move or continuous mode) or a
; scan runs.
anything_moves:
        lda CSPEED
        ora CSPEED+1
        ora REMLO
        ora REMLO+1
        ora REMHI
        ora REMHI+1
        ora SCANST
        rts

; One tick: the drives and the active scanner step when their time comes.
tick:
        ; Re-arm timer 2 so that the next time-out comes exactly one period
        ; after this one, however late the handler got here. Past zero the
        ; counter keeps counting down: its low byte is $100 - d, d cycles
        ; after the zero. The write below comes 16 cycles after the read,
        ; and a count M written at cycle w reaches zero at w + 1 + M, so
        ; M = PERIOD - 17 - d = A + TICK_REARM. (Reading T2C-L also clears
        ; the flag.)
        lda VIA_T2CL
        clc
        adc #<TICK_REARM
        sta VIA_T2CL
        lda #>TICK_REARM
        adc #0
        sta VIA_T2CH
        lda #0
        sta ISTEP
        sta ICHANGE
        ldx #0
        jsr tick_drive
        ldx #1
        jsr tick_drive
        jsr tick_scan
        lda PBSHADOW            ; directions first, then the step edges
        sta VIA_ORB
        lda ISTEP
        beq @nostep
        ora PBSHADOW
        sta VIA_ORB
        lda PBSHADOW
        sta VIA_ORB
@nostep:
        lda ICHANGE
        beq @same
        jsr apply_io            ; a move or a scan ended
@same:  jsr anything_moves
        bne @keep
        sta TICKING             ; A is 0: stop ticking
        lda #IRQ_T2
        sta VIA_IER
@keep:  rts

; Drive X (0 left, 1 right): a specific move first, else continuous mode;
; nothing while the Master I/O byte inhibits it. The accumulator adds the
; speed every tick and the motor steps each time it passes STEP_LIMIT.
tick_drive:
        lda REMLO,x
        ora REMHI,x
        beq @continuous
        lda #1
        sta IMODE
        lda SSPEED,x
        jmp @speed
@continuous:
        lda #0
        sta IMODE
        lda CSPEED,x
        beq @idle
@speed: sta ITMP
        lda INHIBIT
        and drive_inhibit,x
        bne @idle
        lda ACC,x
        clc
        adc ITMP
        bcs @step
        cmp #STEP_LIMIT
        bcs @step
        sta ACC,x
@idle:  rts
@step:  sec
        sbc #STEP_LIMIT
        sta ACC,x
        lda IMODE
        beq @cdir
        lda SDIR,x
        jmp @dir
@cdir:  lda CDIR,x
@dir:   sta IDIR
        lda PBSHADOW
        and drive_dir_clear,x
        ldy IDIR
        beq @backward
        ora drive_dir,x
@backward:
        sta PBSHADOW
        lda ISTEP
        ora drive_step,x
        sta ISTEP
        lda IMODE
        beq @count
        lda REMLO,x             ; a specific move: one step fewer
        bne @low
        dec REMHI,x
@low:   dec REMLO,x
        lda REMLO,x
        ora REMHI,x
        bne @more
        inc ICHANGE             ; the move is over
@more:  lda SCOUNT,x
        beq @idle
@count: lda IDIR                ; the /1M count, saturating at +-9999
        beq @minus
        lda CNTLO,x
        cmp #<COUNT_MAX
        bne @plus
        lda CNTHI,x
        cmp #>COUNT_MAX
        beq @idle
@plus:  inc CNTLO,x
        bne @idle
        inc CNTHI,x
        rts
@minus: lda CNTLO,x
        cmp #<NEG_COUNT_MAX
        bne @less
        lda CNTHI,x
        cmp #>NEG_COUNT_MAX
        beq @idle
@less:  lda CNTLO,x
        bne @lowm
        dec CNTHI,x
@lowm:  dec CNTLO,x
        rts

NEG_COUNT_MAX = $10000 - COUNT_MAX

drive_inhibit:   .byte $20, $40
drive_dir:       .byte PB_LEFT_DIR, PB_RIGHT_DIR
drive_dir_clear: .byte $FF - PB_LEFT_DIR, $FF - PB_RIGHT_DIR
drive_step:      .byte PB_LEFT_STEP, PB_RIGHT_STEP

; The active scanner: phase 1 steps from the centre to -n, phase 2 sweeps to
; +n taking a reading at each of the 2n+1 positions, phase 3 returns to the
; centre. One step every SCAN_TICKS ticks, paused while inhibited.
tick_scan:
        lda SCANST
        beq @idle
        lda INHIBIT
        and SCANBIT
        bne @idle
        dec SCANDIV
        bne @idle
        lda #SCAN_TICKS
        sta SCANDIV
        lda SCANST
        cmp #2
        beq @sweep
        jsr scan_step_back
        dec SCANPOS
        lda SCANST
        cmp #3
        beq @return
        lda SCANPOS             ; phase 1: at -n yet?
        clc
        adc SCANN
        bne @idle
        lda #2
        sta SCANST
        jmp scan_read
@return:
        lda SCANPOS
        bne @idle
        sta SCANST              ; back at the centre: done
        inc ICHANGE
@idle:  rts
@sweep: lda PBSHADOW
        ora #PB_SCAN_DIR
        jsr scan_pulse
        inc SCANPOS
        jsr scan_read
        lda SCANPOS
        cmp SCANN
        bne @idle
        lda #3
        sta SCANST
        rts

scan_step_back:
        lda PBSHADOW
        and #$FF - PB_SCAN_DIR
        ; fall through

; A = port B with the scan direction set: pulse the active scanner's step.
scan_pulse:
        sta PBSHADOW
        sta VIA_ORB
        lda SCANBIT             ; $08 -> PB_H_STEP $10, $10 -> PB_V_STEP $20
        asl
        ora PBSHADOW
        sta VIA_ORB
        lda PBSHADOW
        sta VIA_ORB
        rts

; Stores the detector's reading at the scanner's position.
scan_read:
        ldx SCANIDX
        lda SCANNER
        sta SCANBUF,x
        inc SCANIDX
        rts

; IOAPPLY: obeys the Master I/O byte. INHIBIT = the devices switched off;
; BUSY = what is in progress (whether inhibited or not); the DRIVE latch
; and the speaker follow what is in progress and allowed. Interrupts are
; off inside, so the handler and the main line never interleave here.
apply_io:
        php
        sei
        pha
        txa
        pha
        jsr io_inhibit
        sta INHIBIT
        lda #0                  ; the busy byte
        ldx TONE
        beq @eyes
        ora #$01
@eyes:  ldx EYES
        beq @lamps
        ora #$02
@lamps: ldx LAMPS
        beq @scan
        ora #$04
@scan:  ldx SCANST
        beq @left
        ora SCANBIT
@left:  ldx CSPEED
        bne @lon
        ldx REMLO
        bne @lon
        ldx REMHI
        beq @right
@lon:   ora #$20
@right: ldx CSPEED+1
        bne @ron
        ldx REMLO+1
        bne @ron
        ldx REMHI+1
        beq @any
@ron:   ora #$40
@any:   cmp #0
        beq @idle
        ora #$80
@idle:  sta BUSY
        and #$7F                ; in progress and allowed
        sta ATMP
        lda INHIBIT
        eor #$FF
        and ATMP
        sta ATMP
        lda #0                  ; the DRIVE latch
        sta ATMP2
        lda ATMP
        and #$02
        beq @nolight
        lda EYES
        and #$03                ; bit 0 right eye, bit 1 left eye
        sta ATMP2
@nolight:
        lda ATMP
        and #$04                ; lamps: the same bit
        ora ATMP2
        sta ATMP2
        lda ATMP                ; drives: busy bits 5, 6 -> DRIVE bits 3, 4
        lsr
        lsr
        and #DRV_LEFT | DRV_RIGHT
        ora ATMP2
        sta ATMP2
        lda ATMP                ; scanners: busy bits 3, 4 -> DRIVE bits 5, 6
        asl
        asl
        and #DRV_HSCAN | DRV_VSCAN
        ora ATMP2
        sta ATMP2
        lda ATMP                ; speaker: busy bit 0 -> DRIVE bit 7
        lsr
        lda ATMP2
        bcc @quiet
        ora #DRV_SPEAKER
@quiet: sta DRIVE
        and #DRV_SPEAKER        ; timer 1 drives PB7 only while it sounds
        beq @acr
        lda #$C0
@acr:   sta VIA_ACR
        pla
        tax
        pla
        plp
        rts
