; `.align` padding in code and data segments, with and without a fill
; value, at positions known when read and settled only by layout; `.res`
; without a value. ld65 puts the memory area's `fillval` where no value is
; given (the differential test links this with fillval $00 and $FF), the
; given value elsewhere, and aligns within the segment (segment starts are
; not moved: ld65 only warns that RODATA is misaligned).
zp0 = $10
        .code
start:  lda #1
        .align 4, $EA           ; known position: NOP padding
        nop
        jmp later               ; settled at once (absolute)
        lda later2              ; forward: zero page or absolute, settled by layout
        .align 8, $EA           ; position unknown when read
        lda zp0
        .align 16               ; no value: the area's fill
        .byte $AA
        .align 2, $FF
later:  rts
        .align 32, $60
        .res 3                  ; reserved, no value: the area's fill
        .res 2, $42
        .align 4
        .byte $BB
later2: .byte $CB

        .rodata
tab:    .byte 1, 2, 3
        .align 4, $CC
        .word start, later
        .align 8
        .byte $DD
        .align 16, $EE
        .byte <later, >tab
        .align 2
        .byte $DF

        .data
        .byte $D1
        .align 4, $99
        .byte $D2
        .align 8
        .byte $D3
