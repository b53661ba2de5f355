; One ELF section per segment; flags from the segment's kind.
        .zeropage
ptr:    .res 2
        .segment "ZEROPAGE"
count:  .res 1
        .segment "FASTVARS": zeropage
fast:   .res 1
        .bss
buffer: .res 64
        .data
table:  .word buffer, ptr
        .rodata
message: .asciiz "hi"
        .segment "MYSEG"
        .byte 1
        .code
        lda (ptr),y
        sta count
        lda fast
        lda buffer
        lda message
        rts
