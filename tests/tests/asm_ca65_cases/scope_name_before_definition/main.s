; A name used in a scope before the scope defines it is the scope's own
; (ca65 binds `done` to the proc's, not to the global one above).
; bytes: EA 30 01 EA 60 4C 0A 08 A5 34 60 4C 00 08 12
value = $12
done:   nop
.proc p
        bmi done        ; the proc's `done`: 30 01
        nop
done:   rts
.endproc
.scope s
        jmp done        ; the scope's `done`
        lda value       ; the scope's `value`, zero page as the outer one
done:   rts
value = $34
.endscope
.proc q
        jmp done        ; no `done` in q: the global one
        .byte value     ; no `value` in q: the global one
.endproc
