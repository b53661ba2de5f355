; .proc and .scope, :: paths, references bound to outer symbols at the end.
        .export api
outer_value = 7
.proc api
        lda #outer_value        ; found in the global scope
        jsr helper
        jmp done
.proc helper
        lda #1
local:  rts
.endproc
done:   rts
.endproc
        jsr api::helper::local
        jsr api::done
        jmp ::api
.scope tables
bytes:  .byte 1, 2, 3
count = * - bytes
.endscope
        ldx #tables::count
        lda tables::bytes,x
        .byte .sizeof(api), .sizeof(tables)
.scope
hidden: rts
.endscope
