; An .enum member defined by a later one, as ca65 allows; the members
; after it count on from it, and names in values are the enum's first.
OUTER = 100
.enum colors
        red = green - 1
        green = 5
        blue
        far = OUTER + blue
        farther
.endenum
        lda #colors::red
        lda #colors::blue
        lda #colors::farther
