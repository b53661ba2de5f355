start:  nop
        .res 200
        bne start
        beq far_ahead
        .res 130
far_ahead:
        rts
