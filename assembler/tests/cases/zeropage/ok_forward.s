; Zero page is chosen for symbols defined later in the file and for
; .importzp symbols; ca65 would assemble the first three as absolute.
        .importzp ext_zp
        .import ext_abs
        .code
        lda later_zp            ; defined below as a constant < $100
        sta later_zp,x
        lda zp_var              ; a label in ZEROPAGE defined below
        lda ext_zp              ; .importzp: zero page, R_MOS_ADDR8
        lda ext_abs             ; .import: absolute, R_MOS_ADDR16
        lda later_abs           ; a constant >= $100: absolute
        lda later_abs,y         ; no zero-page,Y form for lda: absolute
        ldx later_zp,y          ; ldx has zero-page,Y
        lda z:later_abs & $FF   ; z: forces zero page
        lda a:later_zp          ; a: forces absolute
        lda code_label          ; a CODE label: absolute
code_label:
        rts
later_zp = $80
later_abs = $1234
        .segment "ZEROPAGE"
zp_var: .res 1
