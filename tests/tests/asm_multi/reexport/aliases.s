; Names defined as an imported symbol and exported again, as cc65's
; runtime writes them (`.import return0` / `_exit = return0`): the
; linker computes them (.scorpion.values).
        .import return0
        .export zero, after_zero, zero_page
zero = return0
after_zero := return0 + 2
zero_page = >return0
