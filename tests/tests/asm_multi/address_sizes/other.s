; The other file: the zero-page pointer and the far routine.
        .exportzp ptr
        .export far_thing
        .import entry
        .zeropage
ptr:    .res 2
        .code
far_thing:
        jmp entry
