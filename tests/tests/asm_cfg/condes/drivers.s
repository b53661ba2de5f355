; Another module's routines for the same tables, at other priorities.
        .constructor init_serial, 10
        .constructor init_screen
        .destructor  close_serial, 5
        .destructor  close_screen, 20
        .interruptor serial_irq
        .condes      tick, 4
        .segment "ONCE"
init_serial:  rts
init_screen:  rts
        .code
close_serial: rts
close_screen: rts
serial_irq:   rts
tick:         rts
