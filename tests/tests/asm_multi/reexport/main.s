; Uses the re-exported names.
        .import zero, after_zero, zero_page
        .code
        jsr     zero
        jmp     after_zero
        .word   zero, after_zero
        .byte   <zero_page
