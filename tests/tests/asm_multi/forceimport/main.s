; `.forceimport`: the start-up module is linked although nothing here
; names it (cc65's `__STARTUP__`).
        .forceimport __STARTUP__
        .code
        lda     #1
        rts
