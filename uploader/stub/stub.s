; stub.s: the debug stub (docs/PROTOCOL.md, section 5; docs/DEBUGGING.md,
; "Debug on the robot"). Linked by the uploader at attach time where the
; image leaves room, written and verified with the ROM's commands, then
; hooked into HOOK_UNKNOWN ahead of what was there (PREV).
;
; A breakpoint at A is `JSR entry` over A's first three bytes; the
; instructions it displaced (a branch as its opposite over a `JMP` to its
; target) run from a trampoline (`tramps`, written by
; the host) that ends `JMP` back. At a stop the stub keeps A X Y P S and
; the return address, sends a stop frame and serves the host's frames
; through GETCH/PUTCH until one says where to go on: the handler or loop
; pass it stopped does not return meanwhile, so the control loop stops,
; while interrupts (the receive ring) stay on.
;
; Frames to the host:   $F0  len  payload  sum      (binary)
; Frames from the host: $F1  LL   payload  SS       (hex digits)
; A frame's length and payload and its sum add up to zero (mod 256).
;
; While running, `/1@` copies the three staged bytes (`stage`: address,
; then the bytes) to their address in one go and answers `@`: a patch
; and its removal are written whole, after the stage read back right.

        .import GETCH, PUTCH, PUTEOL, CMD_DONE, PREV
        .importzp SZP
        .export entry, handler, regs, saved_zp, stage, buf, tramps, code_end

SOF_OUT = $F0                   ; starts a frame to the host
SOF_IN  = $F1                   ; starts a frame from the host
BUFLEN  = 40                    ; the longest payload from the host
PTR     = SZP                   ; two bytes: kept at a stop, given back

        .segment "CODE"

; ---- a breakpoint's JSR lands here
entry:  php
        cld                     ; the program's D would make the sums BCD (RTI gives it back)
        sta r_a
        stx r_x
        sty r_y
        pla
        sta r_p
        pla                     ; the return address: the breakpoint + 2
        sta r_pcl
        pla
        sta r_pch
        tsx                     ; S as it was before the JSR
        stx r_s
        lda PTR
        sta saved_zp
        lda PTR+1
        sta saved_zp+1
        cli                     ; the line's interrupt must run
stop:   ldx #7
st1:    lda regs,x
        sta out,x
        dex
        bpl st1
        lda #8
        ldx #0
        jsr send
        tsx
        stx serve_s
next:   jsr getframe
        bcs nak
        lda buf
        cmp #'R'
        beq read
        cmp #'W'
        beq write
        cmp #'C'
        beq cont
nak:    lda #'N'
        sta out
        lda #1
        ldx #0
        jsr send
        jmp next

; R lo hi n: n bytes from lo hi, answered M lo hi bytes
read:   lda len
        cmp #4
        bne nak
        beq reply

; W lo hi n bytes: written, then answered as a read of them
write:  lda buf+3
        clc
        adc #4
        cmp len
        bne nak
        jsr point
        ldy #0
w1:     cpy buf+3
        beq reply
        lda buf+4,y
        sta (PTR),y
        iny
        bne w1
reply:  jsr point
        lda #'M'
        sta out
        lda buf+1
        sta out+1
        lda buf+2
        sta out+2
        lda #3
        ldx buf+3
        jsr send
        jmp next

point:  lda buf+1
        sta PTR
        lda buf+2
        sta PTR+1
        rts

; C lo hi: go on at lo hi with the registers kept (the host may have
; changed them in `regs`)
cont:   lda len
        cmp #3
        bne nak
        lda saved_zp
        sta PTR
        lda saved_zp+1
        sta PTR+1
        ldx r_s
        txs
        lda buf+2
        pha
        lda buf+1
        pha
        lda r_p
        pha
        lda r_a
        ldx r_x
        ldy r_y
        rti                     ; P and the PC at once

; a frame from the host into buf (len bytes): carry set if it is bad
getframe:
        jsr getch
        cmp #SOF_IN
        bne getframe
        jsr gethex
        bcs gfbad
        sta len
        sta sum
        cmp #BUFLEN+1
        bcs gfbad
        tax
        beq gfbad
        ldy #0
gf1:    jsr gethex
        bcs gfbad
        sta buf,y
        clc
        adc sum
        sta sum
        iny
        cpy len
        bne gf1
        jsr gethex
        bcs gfbad
        clc
        adc sum
        bne gfbad
        clc
        rts
gfbad:  sec
        rts

; the next byte; a slash (a command sent to a stopped robot) sends the
; stop frame again, so the host learns where the robot is
getch:  jsr GETCH
        cmp #'/'
        bne gc1
        ldx serve_s
        txs
        jmp stop
gc1:    rts

; two hex digits (upper case) into A: carry set if not hex
gethex: jsr nib
        bcs gh9
        asl a
        asl a
        asl a
        asl a
        sta tmp
        jsr nib
        bcs gh9
        ora tmp
        clc
gh9:    rts

nib:    jsr getch
        sec
        sbc #'0'
        cmp #10
        bcc n9                  ; 0-9, carry clear
        sbc #7                  ; carry set: 'A' comes to 10
        cmp #10
        bcc nbad
        cmp #16                 ; carry clear for 10-15
        rts
nbad:   sec
n9:     rts

; a frame to the host: A bytes of `out`, then X bytes from (PTR)
send:   sta olen
        stx dlen
        lda #SOF_OUT
        jsr PUTCH
        lda olen
        clc
        adc dlen
        sta sum
        jsr PUTCH
        ldx #0
s1:     cpx olen
        beq s2
        lda out,x
        jsr put
        inx
        bne s1
s2:     ldy #0
s3:     cpy dlen
        beq s4
        lda (PTR),y
        jsr put
        iny
        bne s3
s4:     lda #0
        sec
        sbc sum
        jmp PUTCH

put:    jsr PUTCH
        clc
        adc sum
        sta sum
        rts

; ---- HOOK_UNKNOWN while the debugger is attached: /1@ patches
handler:
        cmp #'@'
        bne chain
        cpx #1
        bne chain
        lda PTR                 ; another extension's, perhaps: kept
        pha
        lda PTR+1
        pha
        lda stage
        sta PTR
        lda stage+1
        sta PTR+1
        ldy #2
h1:     lda stage+2,y
        sta (PTR),y
        dey
        bpl h1
        pla
        sta PTR+1
        pla
        sta PTR
        lda #'@'
        jsr PUTCH
        jsr PUTEOL
        jmp CMD_DONE
chain:  jmp PREV
code_end:

; ---- data: the host reads and writes it
regs:   .byte 'S'               ; the stop frame's payload
r_pcl:  .res 1
r_pch:  .res 1
r_a:    .res 1
r_x:    .res 1
r_y:    .res 1
r_p:    .res 1
r_s:    .res 1
saved_zp: .res 2
stage:  .res 5                  ; address lo hi, three bytes
serve_s: .res 1
len:    .res 1
sum:    .res 1
tmp:    .res 1
olen:   .res 1
dlen:   .res 1
out:    .res 8
buf:    .res BUFLEN
tramps: .res 128                ; eight trampolines of sixteen bytes
