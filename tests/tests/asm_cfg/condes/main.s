; Walks the tables the linker built: their addresses and counts.
        .import __CONSTRUCTOR_TABLE__, __CONSTRUCTOR_COUNT__
        .import __DESTRUCTOR_TABLE__, __DESTRUCTOR_COUNT__
        .import __INTERRUPTOR_TABLE__, __INTERRUPTOR_COUNT__
        .import __TICK_TABLE__, __HIMEM__
        .export __CALLIRQ__
        .constructor init_main, 30
        .code
start:  ldx     #<__CONSTRUCTOR_COUNT__
        lda     __CONSTRUCTOR_TABLE__
        ldy     #<__DESTRUCTOR_COUNT__
        lda     __DESTRUCTOR_TABLE__
        lda     __INTERRUPTOR_TABLE__, x
        ldx     #<__INTERRUPTOR_COUNT__
        lda     __TICK_TABLE__
        .word   __HIMEM__
__CALLIRQ__:
init_main:
        rts
