; Every documented opcode of the NMOS 6502, in opcode order.
        .org $1000
        brk                     ; $00
        ora ($12,x)             ; $01
        ora $12                 ; $05
        asl $12                 ; $06
        php                     ; $08
        ora #$12                ; $09
        asl a                   ; $0A
        ora $3412               ; $0D
        asl $3412               ; $0E
        bpl *+4                 ; $10
        ora ($12),y             ; $11
        ora $12,x               ; $15
        asl $12,x               ; $16
        clc                     ; $18
        ora $3412,y             ; $19
        nop                     ; $1A
        ora $3412,x             ; $1D
        asl $3412,x             ; $1E
        jsr $3412               ; $20
        and ($12,x)             ; $21
        bit $12                 ; $24
        and $12                 ; $25
        rol $12                 ; $26
        plp                     ; $28
        and #$12                ; $29
        rol a                   ; $2A
        bit $3412               ; $2C
        and $3412               ; $2D
        rol $3412               ; $2E
        bmi *+4                 ; $30
        and ($12),y             ; $31
        and $12,x               ; $35
        rol $12,x               ; $36
        sec                     ; $38
        and $3412,y             ; $39
        and $3412,x             ; $3D
        rol $3412,x             ; $3E
        rti                     ; $40
        eor ($12,x)             ; $41
        eor $12                 ; $45
        lsr $12                 ; $46
        pha                     ; $48
        eor #$12                ; $49
        lsr a                   ; $4A
        jmp $3412               ; $4C
        eor $3412               ; $4D
        lsr $3412               ; $4E
        bvc *+4                 ; $50
        eor ($12),y             ; $51
        eor $12,x               ; $55
        lsr $12,x               ; $56
        cli                     ; $58
        eor $3412,y             ; $59
        eor $3412,x             ; $5D
        lsr $3412,x             ; $5E
        rts                     ; $60
        adc ($12,x)             ; $61
        adc $12                 ; $65
        ror $12                 ; $66
        pla                     ; $68
        adc #$12                ; $69
        ror a                   ; $6A
        jmp ($3412)             ; $6C
        adc $3412               ; $6D
        ror $3412               ; $6E
        bvs *+4                 ; $70
        adc ($12),y             ; $71
        adc $12,x               ; $75
        ror $12,x               ; $76
        sei                     ; $78
        adc $3412,y             ; $79
        adc $3412,x             ; $7D
        ror $3412,x             ; $7E
        sta ($12,x)             ; $81
        sty $12                 ; $84
        sta $12                 ; $85
        stx $12                 ; $86
        dey                     ; $88
        txa                     ; $8A
        sty $3412               ; $8C
        sta $3412               ; $8D
        stx $3412               ; $8E
        bcc *+4                 ; $90
        sta ($12),y             ; $91
        sty $12,x               ; $94
        sta $12,x               ; $95
        stx $12,y               ; $96
        tya                     ; $98
        sta $3412,y             ; $99
        txs                     ; $9A
        sta $3412,x             ; $9D
        ldy #$12                ; $A0
        lda ($12,x)             ; $A1
        ldx #$12                ; $A2
        ldy $12                 ; $A4
        lda $12                 ; $A5
        ldx $12                 ; $A6
        tay                     ; $A8
        lda #$12                ; $A9
        tax                     ; $AA
        ldy $3412               ; $AC
        lda $3412               ; $AD
        ldx $3412               ; $AE
        bcs *+4                 ; $B0
        lda ($12),y             ; $B1
        ldy $12,x               ; $B4
        lda $12,x               ; $B5
        ldx $12,y               ; $B6
        clv                     ; $B8
        lda $3412,y             ; $B9
        tsx                     ; $BA
        ldy $3412,x             ; $BC
        lda $3412,x             ; $BD
        ldx $3412,y             ; $BE
        cpy #$12                ; $C0
        cmp ($12,x)             ; $C1
        cpy $12                 ; $C4
        cmp $12                 ; $C5
        dec $12                 ; $C6
        iny                     ; $C8
        cmp #$12                ; $C9
        dex                     ; $CA
        cpy $3412               ; $CC
        cmp $3412               ; $CD
        dec $3412               ; $CE
        bne *+4                 ; $D0
        cmp ($12),y             ; $D1
        cmp $12,x               ; $D5
        dec $12,x               ; $D6
        cld                     ; $D8
        cmp $3412,y             ; $D9
        cmp $3412,x             ; $DD
        dec $3412,x             ; $DE
        cpx #$12                ; $E0
        sbc ($12,x)             ; $E1
        cpx $12                 ; $E4
        sbc $12                 ; $E5
        inc $12                 ; $E6
        inx                     ; $E8
        sbc #$12                ; $E9
        cpx $3412               ; $EC
        sbc $3412               ; $ED
        inc $3412               ; $EE
        beq *+4                 ; $F0
        sbc ($12),y             ; $F1
        sbc $12,x               ; $F5
        inc $12,x               ; $F6
        sed                     ; $F8
        sbc $3412,y             ; $F9
        sbc $3412,x             ; $FD
        inc $3412,x             ; $FE
