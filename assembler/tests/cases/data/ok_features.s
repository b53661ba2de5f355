; Every .feature that changes how lines read, at once, as ca65 2.19 reads
; them (and .linecont, which later ca65s spell .feature line_continuations).
        .feature at_in_identifiers, dollar_in_identifiers, underline_in_numbers
        .feature c_comments, string_escapes, dollar_is_pc, bracket_as_indirect
        .feature loose_string_term, missing_char_term, pc_assignment, addrsize
        .feature leading_dot_in_identifiers, labels_without_colons, ubiquitous_idents
        .linecont +
* = $1000
name@x = 1
name$y = 2
        .byte name@x, name$y, %1010_0101, $12_34 & $FF, 1_000 & $FF
        .byte /* inline */ 3 /* a comment
        that goes on */
        .byte "a\tb\n\x41\\\"", 'loose'
        .word $, * ; dollar is the PC
        jmp [vector]
        lda [$10],y
        lda [$10,x]
.dotted = 5
        .byte .dotted
start   lda #1
        .byte 1, \
              2, 3
.macro lda arg
        .byte arg
.endmacro
        lda 7
        .byte .addrsize(start), .addrsize(name@x)
vector: .word start
