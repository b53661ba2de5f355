; `.strat(string, index)`: a string's character as a number, as msbasic's
; token tables use it.
        .byte .strat("HELLO", 0), .strat("HELLO", 4)
        .byte .strat("ABC", 1) | $80
COUNT = 2
        lda #.strat("xyz", COUNT)
        .charmap $41, $C1
        .byte .strat("A", 0)
