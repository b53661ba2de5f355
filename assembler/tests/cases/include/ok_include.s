; `.include` finds files next to this one, and built-in files by name.
        .include "defs.inc"
        .include "builtin.inc"
        from_include
        builtin_macro
        .byte INCLUDED_VALUE, BUILTIN_VALUE
