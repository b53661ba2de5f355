; Routines for the linker's tables: each is exported and listed with its
; table type and priority (7 unless given, as ca65's).
        .constructor init_screen
        .constructor init_serial, 10
        .destructor  shutdown
        .interruptor on_irq, 5
        .condes      on_tick, 4, 32
        .code
init_screen: rts
init_serial: rts
shutdown:    rts
on_irq:      rts
on_tick:     rts
