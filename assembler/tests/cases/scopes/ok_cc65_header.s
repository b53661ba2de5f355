; The lines the C compiler starts its output with, and its `.proc name:
; near`: accepted (the listing-only ones with a warning).
        .fopt   compiler,"a C compiler"
        .setcpu "6502"
        .smart  on
        .autoimport on
        .case   on
        .debuginfo off
        .macpack longbranch
        .export _twice
.proc   _twice: near
        asl     a
        jcc     done
        lda     #$FF
done:   rts
.endproc
