; checksum.s: a second extension, chained behind the first.
;
; /9Kaaaannnn answers Khhhh: the 16-bit sum of the nnnn (hex) bytes from
; aaaa (hex). A host can check a whole uploaded area with one short
; question instead of reading every byte back with /7R.
;
; It hooks HOOK_UNKNOWN like rangefinder.s. Loaded after it, its chain slot
; receives rangefinder's handler (the loader reads HOOK_UNKNOWN's target
; before re-pointing it), so the chain runs: checksum -> rangefinder ->
; the ROM's BAD_COMMAND. Both extensions answer; anything else is dropped
; as before.
;
; Two extensions must not overlap: checksum.toml places this one at the top
; of user RAM ($0C00-$0F3F, USER_RAM_END) and the top of the user zero page,
; leaving $0400-$0BFF to the first.
;
;   scorpion build examples/checksum/checksum.s -o checksum.elf --target examples/checksum/checksum.toml

        .include "scorpion.inc"

        .zeropage
pointer:        .res 2
count:          .res 2
sum:            .res 2

        .code

        SCORPION_UNKNOWN_HANDLER
checksum:
        cpx #9
        bne not_mine
        cmp #'K'
        bne not_mine

        ldy #1                  ; the fields start after the letter
        jsr GETHEX
        bcs malformed
        sta pointer+1
        jsr GETHEX
        bcs malformed
        sta pointer
        jsr GETHEX
        bcs malformed
        sta count+1
        jsr GETHEX
        bcs malformed
        sta count

        lda #0
        sta sum
        sta sum+1
        tay                     ; Y stays 0: the pointer moves instead
@next:  lda count
        ora count+1
        beq @answer
        lda (pointer),y
        clc
        adc sum
        sta sum
        bcc @carried
        inc sum+1
@carried:
        inc pointer
        bne @counted
        inc pointer+1
@counted:
        lda count
        bne @low
        dec count+1
@low:   dec count
        jmp @next

@answer:
        lda #'K'
        jsr PUTCH
        lda sum+1
        jsr PUTHEX
        lda sum
        jsr PUTHEX
        jsr PUTEOL
        jmp CMD_DONE

; Not hex: leave it to the rest of the chain, as the ROM would.
malformed:
        lda CMDBUF
        ldx CMDLEN
not_mine:
        SCORPION_CHAIN_UNKNOWN
