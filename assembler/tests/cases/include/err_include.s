; Errors in an included file and in a macro from it carry the backtrace.
        .include "bad.inc"
        inc_macro 999
        .include
        .include "nothere.inc"
