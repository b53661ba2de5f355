; .struct, .union, nested anonymous members, .tag, .enum.
.struct Point
        xpos    .word
        ypos    .word
.endstruct
.struct Sprite
        pos     .tag Point
        tile    .byte
        flags   .byte 2
        .union
                speed   .byte
                delay   .word
        .endunion
        last    .byte
.endstruct
.enum Dir
        north
        east
        south = 8
        west
.endenum
.enum
        ANON_A = 3
        ANON_B
.endenum
        .code
        lda #.sizeof(Point)
        lda #.sizeof(Sprite)
        lda #Sprite::pos
        lda #Sprite::tile
        lda #Sprite::flags
        lda #Sprite::speed
        lda #Sprite::delay
        lda #Sprite::last
        lda #Dir::north
        lda #Dir::west
        lda #ANON_B
        lda sprites + Sprite::tile
sprites: .tag Sprite
        .tag Point
        .byte $FF
