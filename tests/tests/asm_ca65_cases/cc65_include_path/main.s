; cc65's own include files, found without `-I` (ca65's built-in path).
; cc65-include: yes
; bytes: A5 22 20 D2 FF
        .include "apple2.inc"
        .include "cbm_kernal.inc"
        lda WNDTOP
        jsr CHROUT
