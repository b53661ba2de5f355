; ca65's `.org` is global: absolute mode follows into the next segment,
; which goes on at the address the last one reached, until `.reloc`.
        .code
        .org    $1000
first:  .word   *
        .rodata
second: .word   *, first
        .code
third:  .word   *, second
        .reloc
        .rodata
fourth: .word   *
