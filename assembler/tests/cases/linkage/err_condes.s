; Table entries out of ca65's ranges: named with the range.
        .constructor init, 0
        .constructor init, 33
        .condes      init, 7
        .condes      init
        .constructor
init:   rts
