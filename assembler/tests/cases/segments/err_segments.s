        .segment CODE
        .segment "bad name"
        .segment "CODE": zeropage
        .segment "X": sometimes
