; sieve.s: count the primes below 8192 with the sieve of Eratosthenes.
;
; The demo program of `scorpion emu run` and the CPU benchmark's workload.
; It runs on the plain 64 KiB machine: load and start it at $0400. It sieves
; REPEAT times (so that there is something to time), then stops in a trap
; (`jmp *`) with the count in X (low byte) and Y (high byte): 1028 = $0404.
;
; Build (the test `programs::sieve_binary_is_what_its_source_builds` checks
; that sieve.bin is exactly this):
;   ca65 -o sieve.o sieve.s && ld65 -C sieve.cfg -o sieve.bin sieve.o

        .setcpu "6502"

FLAGS   = $2000                 ; one byte per number: 1 = still a candidate
SIZE    = $2000                 ; numbers 0 to 8191
REPEAT  = 20                    ; sieves per run
LIMIT   = 91                    ; 91 * 91 > 8191: larger primes mark nothing new

        .zeropage
ptr:    .res 2                  ; flag pointer
i:      .res 2                  ; the number under test
count:  .res 2                  ; primes found
pass:   .res 1                  ; sieves left

        .code
start:  ldx #$FF
        txs
        cld
        lda #REPEAT
        sta pass
again:  jsr sieve
        dec pass
        bne again
        ldx count
        ldy count+1
done:   jmp done                ; the trap: X/Y = the count

; Counts the primes below SIZE into count.
sieve:  lda #0                  ; mark every number a candidate
        sta ptr
        lda #>FLAGS
        sta ptr+1
        lda #1
        ldy #0
@fill:  sta (ptr),y
        iny
        bne @fill
        inc ptr+1
        ldx ptr+1
        cpx #>(FLAGS+SIZE)
        bne @fill

        lda #0
        sta count
        sta count+1
        sta i+1
        lda #2
        sta i
@scan:  lda i                   ; ptr = FLAGS + i
        sta ptr
        lda i+1
        clc
        adc #>FLAGS
        sta ptr+1
        ldy #0
        lda (ptr),y
        beq @next               ; crossed out
        inc count
        bne :+
        inc count+1
:       lda i+1
        bne @next
        lda i
        cmp #LIMIT
        bcs @next
        jsr mark
@next:  inc i
        bne :+
        inc i+1
:       lda i+1
        cmp #>SIZE
        bne @scan
        rts

; Crosses out 2i, 3i, ... below SIZE.
mark:   lda i                   ; ptr = FLAGS + 2i
        asl a
        sta ptr
        lda i+1
        rol a
        clc
        adc #>FLAGS
        sta ptr+1
        ldy #0
@loop:  lda ptr+1
        cmp #>(FLAGS+SIZE)
        bcs @done
        tya
        sta (ptr),y
        lda ptr                 ; ptr += i
        clc
        adc i
        sta ptr
        lda ptr+1
        adc i+1
        sta ptr+1
        jmp @loop
@done:  rts
