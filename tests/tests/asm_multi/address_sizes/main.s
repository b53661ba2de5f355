; Address sizes on imports and exports: `ptr: zp` makes `lda ptr` a
; zero-page access, as `.importzp` would; `entry: abs` exports a label.
        .import ptr: zp, far_thing: abs
        .export entry: abs
entry:  lda ptr
        sta ptr+1
        jmp far_thing
