; Structs inside structs, as ca65's driver headers write them: a named
; nested block is a member and its members belong to the outer struct;
; `.org` moves the next member; `.faraddr` members take three bytes.
.struct HDR
        ID      .byte   3
        JUMPTAB .struct
            INSTALL .addr
            REMOVE  .addr
        .endstruct
        FLAGS   .byte
        .union
            WIDE    .word
            NARROW  .byte
        .endunion
        FAR     .faraddr
        .org    $40
        LAST    .byte
.endstruct
        .byte   HDR::JUMPTAB, HDR::INSTALL, HDR::REMOVE, HDR::FLAGS
        .byte   HDR::WIDE, HDR::NARROW, HDR::FAR, HDR::LAST, .sizeof(HDR)
        .byte   .sizeof(HDR::JUMPTAB), .sizeof(HDR::FLAGS), .sizeof(HDR::FAR)
