; Macros: parameters, braces, .local, .exitmacro, recursion, .paramcount,
; .ifblank/.ifnblank, .repeat with a counter, nested repeats, .define.
.define TEN 10
.define PLUS(p, q) ((p) + (q))
.macro load value
        lda #value
.endmacro
.macro copy src, dst
        lda src
        sta dst
.endmacro
.macro delay n
        .local loop
        ldx #n
loop:   dex
        bne loop
.endmacro
.macro bytes p1, p2, p3
.ifblank p1
        .exitmacro
.endif
        .byte p1
.ifnblank p2
        .byte p2
.endif
.if .paramcount = 3
        .byte p3
.endif
.endmacro
.macro countdown n
.if n > 0
        .byte n
        countdown n - 1
.endif
.endmacro
        .code
        load 5
        load TEN
        load PLUS(1, 2)
        copy $10, $20
        copy {#$FF}, $1234
        delay 20
        delay 30
        bytes
        bytes 1
        bytes 1, 2
        bytes 1, 2, 3
        bytes {1, 2}
        countdown 4
.repeat 3, i
        .byte i
.repeat 2, j
        .byte i * 10 + j
.endrepeat
.endrepeat
.repeat 4
        nop
.endrepeat
SEVEN = 7
.ifdef SEVEN
        .byte 1
.else
        .byte 2
.endif
.ifndef undefined_thing
        .byte 3
.endif
.if .defined(SEVEN) && TEN > 5
        .byte 4
.elseif TEN = 5
        .byte 5
.else
        .byte 6
.endif
.undefine TEN
TEN = 11
        .byte TEN
