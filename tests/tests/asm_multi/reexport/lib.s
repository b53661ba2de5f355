; A routine another module gives other names.
        .export return0
        .code
return0:
        lda     #0
        rts
