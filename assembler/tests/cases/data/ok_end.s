; `.end`: nothing after it is read, whatever it is.
        lda #1
        .end
        this is not assembled ###
