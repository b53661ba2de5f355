; ca65 accepts these; the Scorpion's CPU is an NMOS 6502, so each is a
; clear error, not an unknown directive.
        .p816
        .pc02
        .PSC02
        .p4510
        .setcpu "65816"
        nop
