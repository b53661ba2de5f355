LEVEL = 2
.if LEVEL > 2
        .byte 1
.elseif LEVEL = 2
        .byte 2
.else
        .byte 3
.endif
.ifdef LEVEL
        .byte 4
.endif
.ifndef LEVEL
        .byte 5
.else
        .byte 6
.endif
.if 0
.if 1                           ; nested in a false branch: skipped
        .byte 7
.endif
        this is not even valid
.else
        .byte 8
.endif
.ifconst LEVEL
        .byte 9
.endif
.ifblank
        .byte 10
.endif
.ifnblank x
        .byte 11
.endif
.ifp02
        .byte 12
.endif
