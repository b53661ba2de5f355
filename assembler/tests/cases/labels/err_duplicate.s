start:  nop
start:  nop
value = 1
value = 2
        .import ext
ext:    rts
count .set 1
start .set 2
