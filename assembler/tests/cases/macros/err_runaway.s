; A macro that calls itself forever: stopped, not a hang or a crash.
.macro forever
        forever
.endmacro
        forever
