; Parameters, braces, .local, .exitmacro, recursion, .paramcount.
.macro copy src, dst
        lda src
        sta dst
.endmacro
.macro delay count
        .local loop
        ldx #count
loop:   dex
        bne loop
.endmacro
.macro bytes first, second, third
.ifblank first
        .exitmacro
.endif
        .byte first
.ifnblank second
        .byte second
.endif
.if .paramcount = 3
        .byte third
.endif
.endmacro
.macro countdown n
.if n > 0
        .byte n
        countdown n - 1
.endif
.endmacro
        copy $10, $20
        copy {#$FF}, $1234
        delay 5
        delay 6
        bytes
        bytes 1
        bytes 1, 2
        bytes 1, 2, 3
        countdown 3
