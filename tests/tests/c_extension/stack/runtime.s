; The part of cc65's C runtime that a small extension compiled by cc65
; calls, written here for the Scorpion: the C stack pointer `sp` in zero
; page (the extension sets it), pushes and pops, and the helpers cc65's
; code generator uses for locals, at every optimisation level. Callers
; find their results as cc65's runtime leaves them: A and X as each
; routine's contract says, Y clobbered.
        .exportzp sp, ptr1
        .export pusha, pushax, push0, decsp1, incsp6, addysp
        .export ldaxysp, addeqysp, ldauidx, tosaddax, tosneax

        .zeropage
sp:     .res 2                  ; the C stack, growing down
ptr1:   .res 2                  ; the compiler's pointer cell

        .code
; Push A (one byte). A and X kept.
pusha:  ldy sp
        bne :+
        dec sp+1
:       dec sp
        ldy #0
        sta (sp),y
        rts

; Push 0 as a word.
push0:  lda #0
        tax
; Push A (low) and X (high) as a word. A and X kept.
pushax: pha
        lda sp
        sec
        sbc #2
        sta sp
        bcs :+
        dec sp+1
:       ldy #1
        txa
        sta (sp),y
        pla
        dey
        sta (sp),y
        rts

; One byte more on the stack (a local). A and X kept.
decsp1: ldy sp
        bne :+
        dec sp+1
:       dec sp
        rts

; Drop six bytes (a callee's arguments and locals); Y more from addysp.
; A and X (the result) kept.
incsp6: ldy #6
addysp: pha
        tya
        clc
        adc sp
        sta sp
        bcc :+
        inc sp+1
:       pla
        rts

; The word at (sp),Y-1 (low) and (sp),Y (high) into A and X.
ldaxysp:
        lda (sp),y
        tax
        dey
        lda (sp),y
        rts

; The word at (sp),Y += A/X; the new value in A and X.
addeqysp:
        clc
        adc (sp),y
        sta (sp),y
        pha
        iny
        txa
        adc (sp),y
        sta (sp),y
        tax
        pla
        rts

; The byte at (A/X)+Y into A, X = 0.
ldauidx:
        sta ptr1
        stx ptr1+1
        ldx #0
        lda (ptr1),y
        rts

; A/X += the word popped from the stack.
tosaddax:
        ldy #0
        clc
        adc (sp),y
        pha
        iny
        txa
        adc (sp),y
        tax
        pla
        ldy #2
        jmp addysp

; A/X = (the word popped) != A/X, as 0 or 1, flags set from A.
tosneax:
        ldy #0
        cmp (sp),y
        bne @differ
        txa
        iny
        cmp (sp),y
        bne @differ
        lda #0
        beq @done
@differ:
        lda #1
@done:  ldy #2
        jsr addysp
        ldx #0
        tay                     ; flags from the result
        rts
