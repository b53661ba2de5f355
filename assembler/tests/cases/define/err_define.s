.define LOOP LOOP + 1
        .byte LOOP
.define
