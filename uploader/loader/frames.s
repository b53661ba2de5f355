; frames.s: the uploader's RAM loader (see README.md), hooked through
; HOOK_UNKNOWN while an upload runs, removed when it ends.
;
; /1L is followed by a binary frame that the handler reads itself with
; the ROM's GETCH and CHKCH services (the bytes wait in the ROM's receive
; ring):
;
;       key  lo^key  hi^key  count^key  c0^key  c1^key  data^key...
;
; Every byte but the key is XORed with the key, which the uploader picks
; so that no byte of the frame is a slash: if the handler is not running
; (the /1L was damaged, a reset unhooked it), the ROM ignores the whole
; frame, since outside a command only a slash means anything.
;
; The header (address, count) carries a Fletcher-16 checksum: two sums
; mod 256, both starting at the key; c0 and c1 bring both to zero.
; Nothing is written unless the header checks, so a damaged header never
; writes anywhere; damaged or missing data lands only within the frame's
; own `count` bytes from its address, where the uploader's /7R
; verification of every byte finds it. A frame that lost a byte takes the
; next command's first byte as its last, and the ROM then ignores the rest
; of that command (it has no slash): the uploader asks again.
;
; Anything else falls through to the chain slot: the uploader points it
; at the rate switch (fast.s), whose /1F puts the line back on the base
; rate at the end, and which drops every other command as BAD_COMMAND
; would.

        .import GETCH, CHKCH, CMD_DONE, BAD_COMMAND

        .export __scorpion_hook_unknown, __scorpion_chain_unknown
        .segment "CODE"
__scorpion_hook_unknown:
        cmp #'L'
        beq frame
        .byte $4C               ; JMP to the chain slot's target
__scorpion_chain_unknown:
        .addr BAD_COMMAND

frame:  jsr GETCH
        sta key+1
        sta sum0+1
        sta sum1+1
        jsr getb
        stx dest+1
        jsr getb
        stx dest+2
        jsr getb
        stx count+1
        jsr getb
        jsr getb                ; A = sum1
        ora sum0+1
        bne done                ; a damaged header: nothing is written
        tay
data:   jsr CHKCH               ; the bytes are usually in the ring already
        bcs data
        eor key+1
dest:   sta $FFFF,y
        iny
count:  cpy #0
        bne data
done:   jmp CMD_DONE

; The next frame byte, decoded, into X and added to both sums; A = sum1.
getb:   jsr GETCH
key:    eor #0
        tax
        clc
sum0:   adc #0
        sta sum0+1
        clc
sum1:   adc #0
        sta sum1+1
        rts
