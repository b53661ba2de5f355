; The names of the NMOS manuals for two undocumented opcodes, which ca65
; 2.19 spells `lax #` and `axs #`: both spellings are accepted here.
        .setcpu "6502X"
        lxa #$12                ; $AB
        lax #$12                ; $AB
        sbx #$12                ; $CB
        axs #$12                ; $CB
