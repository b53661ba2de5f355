; ca65's choice (the default): an operand whose symbol is defined further
; down is absolute unless what is known at the line says zero page; a
; warning where the final value fits zero page.
        .globalzp declared
early = $10
        .code
        lda later_zp            ; absolute, warned
        sta later_zp,x          ; absolute, warned
        lda zp_var              ; a ZEROPAGE label defined below: absolute, warned
        lda <later_abs          ; a byte operator: zero page
        lda declared            ; `.globalzp` above: zero page
        lda later_abs           ; absolute, no warning
        sty later_zp,x          ; sty has no absolute,x: zero page
        lda z:later_zp          ; z: forces zero page
        lda early               ; defined above: zero page
code_label:
        rts

later_zp = $80
later_abs = $1234
declared = $42
        .segment "ZEROPAGE"
zp_var: .res 1
