; fast.s: the first stage of the uploader's RAM loader (see README.md).
;
; Fifteen bytes, written with the ROM's own /9W and verified at the
; robot's base rate, then hooked through HOOK_UNKNOWN. /1F toggles the
; 6551 between the base rate and 19200 baud, its fastest internal rate,
; so that the second stage (frames.s), seven times larger, goes in at
; twice the speed; any other unknown command is dropped, as BAD_COMMAND
; drops it (a command that line noise made up must not move the rate).
; The uploader replaces it with the second stage at once; an upload that
; died while it was hooked is undone by the next one's /1F.

        .import CMD_DONE
        .import RATE_TOGGLE     ; linked in: base control value XOR 19200's

ACIA_CTRL    = $C013    ; the 6551's control register (emulator/src/board/map.rs)

        .export __scorpion_hook_unknown
        .segment "CODE"
__scorpion_hook_unknown:
        cmp #'F'
        bne done
        lda ACIA_CTRL
        eor #RATE_TOGGLE
        sta ACIA_CTRL           ; the 6551 is idle: the uploader waited for every answer
done:   jmp CMD_DONE
