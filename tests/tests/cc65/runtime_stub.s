; The C runtime's names our C programs call, each a bare RTS, and its
; zero-page cells: enough to link the compiler's output on its own and
; compare the bytes (tests/tests/asm_differential.rs). Not a runtime.
        .exportzp sp, sreg, regsave, regbank
        .exportzp tmp1, tmp2, tmp3, tmp4, ptr1, ptr2, ptr3, ptr4
        .export boolult, decaxy, decsp1, incaxy, incsp1, incsp2, incsp3
        .export ldauidx, mulax3, pusha, pushax, shrax4, tosultax

        .zeropage
sp:      .res 2
sreg:    .res 2
regsave: .res 4
regbank: .res 6
tmp1:    .res 1
tmp2:    .res 1
tmp3:    .res 1
tmp4:    .res 1
ptr1:    .res 2
ptr2:    .res 2
ptr3:    .res 2
ptr4:    .res 2

        .code
boolult:
decaxy:
decsp1:
incaxy:
incsp1:
incsp2:
incsp3:
ldauidx:
mulax3:
pusha:
pushax:
shrax4:
tosultax:
        rts
