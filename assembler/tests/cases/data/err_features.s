; Mistakes the features allow: a `.sprintf` field too wide to be a
; string, and a C comment never closed (named where it opens).
        .byte .sprintf("%2000d", 1)
        .feature c_comments
        .byte 1 /* never
        .byte 2
