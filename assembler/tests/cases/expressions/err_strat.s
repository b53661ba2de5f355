; An index past the string's end, and a missing index.
        .byte .strat("AB", 2)
        .byte .strat("AB")
