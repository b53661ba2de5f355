; adc.s: /2An reads channel n (0-7) of the ADC card at $9000 and answers
; Ahh, the reading in hex, or A-- when no card answers.
;
; The card (examples/adc/adc.rhai is its model for the virtual Scorpion):
;
;   $9000  CONTROL  write: bits 0-2 the channel, bit 7 start (100 us)
;   $9001  STATUS   bit 7: 1 while converting; bit 6: a result waits
;   $9002  DATA     the result; reading it clears STATUS bit 6
;
; The reference ROM's interrupt handler does not know the card, so this
; extension leaves the card's interrupt off and polls STATUS.
;
;   scorpion build examples/adc/adc.s -o adc.elf --target scorpion-ext
;   scorpion sim --image adc.elf --card examples/adc/adc.rhai

        .include "scorpion.inc"

CONVERTER       = $9000
ADC_CONTROL     = CONVERTER
ADC_STATUS      = CONVERTER + 1
ADC_DATA        = CONVERTER + 2

        .code

; HOOK_UNKNOWN lands here with A = the command letter, X = its count.
        SCORPION_UNKNOWN_HANDLER
read_channel:
        cpx #2
        bne not_mine
        cmp #'A'
        bne not_mine
        lda CMDBUF+1            ; the channel digit
        sec
        sbc #'0'
        cmp #8
        bcc @channel
        lda #'A'                ; not 0-7: not ours either, A as it came
        bne not_mine
@channel:
        ora #$80                ; start, no interrupt
        sta ADC_CONTROL
        ldx #0                  ; 256 looks, about 2.8 ms: 28 conversions
@wait:  bit ADC_STATUS          ; bit 6 into V: a result waits
        bvs @result
        dex
        bne @wait
        beq no_card             ; nothing came: a robot without the card
@result:
        bmi no_card             ; converting and done at once: no card there
        lda #'A'
        jsr PUTCH
        lda ADC_DATA
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE

; Without the card STATUS reads whatever is at $9001: plain RAM on the
; virtual Scorpion, the floating bus ($90) or pull-ups ($FF) on a real one.
; That is never a result, or both bits at once. Answer A-- rather than wait
; for ever with the robot's control loop stopped.
no_card:
        lda #'A'
        jsr PUTCH
        lda #'-'
        jsr PUTCH
        jsr PUTCH
        jsr PUTEOL
        jmp CMD_DONE

; Not ours: on to whatever HOOK_UNKNOWN pointed at before us, with A and X
; as they came.
not_mine:
        SCORPION_CHAIN_UNKNOWN
