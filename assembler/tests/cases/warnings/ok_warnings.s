; Likely mistakes the NMOS 6502 punishes: warnings, the object is written.
        jmp ($12FF)             ; the page-wrap bug
        jmp ($1300)
        .import vector
        jmp (vector)            ; not known here: a deferred check for the linker
start:  bne *+3                 ; lands on the next instruction's operand
        lda #$01
        bne *+2                 ; the next instruction: fine
        nop
        beq start + 1           ; inside an instruction
        .warning "a user warning"
        .feature labels_without_colons
        .debuginfo on
        .assert 1 = 2, warning, "a failed warning assertion"
        .assert * > $FFFF, warning, "an address check: deferred to the linker"
        .out "this line goes to stdout"
        .assert vector <> 0, error, "checked by the linker"
