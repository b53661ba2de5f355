; The module `main.s` forces into the link.
        .export __STARTUP__ : absolute = 1
        .code
        jmp     $0800
