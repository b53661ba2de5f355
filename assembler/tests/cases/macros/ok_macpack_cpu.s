; `.macpack cpu` and `.cpu`: code that asks which instructions it may use.
        .macpack cpu
        .byte   .cpu, CPU_6502, CPU_ISET_6502X, <CPU_4510, >CPU_4510
.if (.cpu .bitand CPU_ISET_65SC02)
        stz     $10
.else
        lda     #0
        sta     $10
.endif
        .setcpu "6502X"
        .byte   .cpu
.if (.cpu .bitand CPU_ISET_6502X)
        lax     $10
.endif
