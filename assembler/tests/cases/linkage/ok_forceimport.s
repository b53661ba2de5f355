; `.forceimport`: the object names the symbol although nothing here uses
; it, so a linker pulls in the module that defines it (cc65's
; `__STARTUP__`); a plain `.import` of an unused name leaves nothing.
        .forceimport __STARTUP__
        .import unused
        .code
        rts
