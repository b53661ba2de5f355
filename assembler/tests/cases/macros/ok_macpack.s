; ca65's macro packages: `longbranch` (a branch back when near, else the
; opposite branch over a JMP; forward targets always the long way) and
; `generic` (add/sub with the carry set up, comparison branches).
        .macpack longbranch
        .macpack generic
back:   nop
        jeq back
        jne back
        jcc fwd
        jcs fwd
        jmi back
        jpl fwd
        jvc back
        jvs fwd
        add #1
        sub $10
        add ($10),y
        add $10,x
        bge back
        blt fwd
        bgt back
        ble fwd
        bnz back
        bze fwd
fwd:    rts
        .res 120, $EA
        jeq fwd                 ; 123 bytes back: still a branch
        jeq back                ; too far back: the long form
