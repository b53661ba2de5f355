.define WIDTH 40
.define HEIGHT 25
.define AREA WIDTH * HEIGHT
.define MAX(p, q) ((p) > (q)) * (p) + ((p) <= (q)) * (q)
        .word AREA
        .byte MAX(3, 9), MAX(12, 4)
.undefine WIDTH
WIDTH = 1
        .byte WIDTH
