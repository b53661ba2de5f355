; `.feature org_per_seg`: `.org` and `.reloc` affect the current segment
; only; the other segments stay relocatable.
        .feature org_per_seg
        .code
        .org    $1000
first:  .word   *
        .rodata
second: .word   *, first
        .code
third:  .word   *, second
