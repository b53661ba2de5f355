a1 = b1 + 1
b1 = a1 + 1
        .byte a1
self = self
        lda self
