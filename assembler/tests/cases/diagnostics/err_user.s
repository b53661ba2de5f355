        .error "stop here"
        .warning "careful"
        .out "hello from .out"
        .assert 1 = 2, error, "one is not two"
        .assert * < 2, warning, "a warning assertion"
        .assert 0, lderror
        .fatal "fatal: nothing after this"
        .byte 256
