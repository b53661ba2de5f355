; `.end` inside an open .if and an open .proc: both reported, as ca65 does.
        .proc foo
        .if 1
        lda #1
        .end
