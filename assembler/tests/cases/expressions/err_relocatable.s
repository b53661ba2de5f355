; Expressions no relocation can express: named in the error.
        .import ext1, ext2
        .code
start:  lda #start * 2
        .word ext1 - ext2
        .word ext1 + ext2
        .byte start & $FF
        .word -start
        lda #ext1 / 256
