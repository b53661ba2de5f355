; An .align after an instruction whose size is not known yet: the padding
; is recomputed by every layout pass. Under `.org` it pads the offset in
; the segment (and aligns the segment), as ca65's does, not the address.
        lda later               ; absolute once `later` is known: 3 bytes
        .align 4
aligned:
        nop
        .org $10
        lda small               ; stays zero page: 2 bytes
        .align 8, $EA
eight:  nop
later = $1234
small = $42
