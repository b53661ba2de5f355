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
        lda #.sizeof(Sprite)
        lda #Sprite::tile
        lda #Sprite::delay
        lda #Sprite::last
        lda #Dir::west
        ldx sprites + Sprite::flags
sprites: .tag Sprite
        .byte $EE
