; A package this assembler does not have, no name at all, and a package
; loaded twice (its macros defined again, as ca65 refuses too).
        .macpack cbm
        .macpack
        .macpack generic
        .macpack generic
