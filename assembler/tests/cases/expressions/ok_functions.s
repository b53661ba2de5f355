; Pseudo-functions.
.struct rec
        first   .byte
        second  .word
.endstruct
value = $123456
        .byte .lobyte(value), .hibyte(value), .bankbyte(value)
        .word .loword(value), .hiword(value)
        .byte .defined(value), .defined(nothing)
        .byte .const(value), .const(label)
        .byte .strlen("four"), .blank(), .blank(x)
        .byte .sizeof(rec), rec::second
label:  .byte .referenced(label), .referenced(value)
