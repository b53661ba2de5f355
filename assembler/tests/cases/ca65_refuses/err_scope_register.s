; A scope named after a register. ca65 then also refuses the `.endproc`
; (its `.proc` never opened); we open the scope all the same, so the one
; error is the name.
        .proc a                 ; ca65: Unexpected trailing garbage characters
        nop
        .endproc                ; ca65 only: No open .PROC (its .proc never opened)
