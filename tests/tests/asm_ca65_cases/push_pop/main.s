; `.pushseg`/`.popseg` and `.pushcpu`/`.popcpu`.
; bytes: 02 A7 12 03 01
        .pushseg
        .rodata
        .byte 1
        .popseg
        .byte 2
        .pushcpu
        .setcpu "6502X"
        lax $12
        .popcpu
        .byte 3
