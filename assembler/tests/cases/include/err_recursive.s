; An include of itself is stopped at the nesting limit, not a crash.
        .include "err_recursive.s"
