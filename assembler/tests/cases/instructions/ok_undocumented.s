; The undocumented NMOS opcodes after `.setcpu "6502X"`; several
; opcodes share a mnemonic and mode, and the canonical one is chosen.
        .setcpu "6502X"
        .org $1000
        jam                     ; $02
        slo ($12,x)             ; $03
        nop $12                 ; $04
        slo $12                 ; $07
        anc #$12                ; $0B
        nop $3412               ; $0C
        slo $3412               ; $0F
        slo ($12),y             ; $13
        nop $12,x               ; $14
        slo $12,x               ; $17
        slo $3412,y             ; $1B
        nop $3412,x             ; $1C
        slo $3412,x             ; $1F
        rla ($12,x)             ; $23
        rla $12                 ; $27
        rla $3412               ; $2F
        rla ($12),y             ; $33
        rla $12,x               ; $37
        rla $3412,y             ; $3B
        rla $3412,x             ; $3F
        sre ($12,x)             ; $43
        sre $12                 ; $47
        alr #$12                ; $4B
        sre $3412               ; $4F
        sre ($12),y             ; $53
        sre $12,x               ; $57
        sre $3412,y             ; $5B
        sre $3412,x             ; $5F
        rra ($12,x)             ; $63
        rra $12                 ; $67
        arr #$12                ; $6B
        rra $3412               ; $6F
        rra ($12),y             ; $73
        rra $12,x               ; $77
        rra $3412,y             ; $7B
        rra $3412,x             ; $7F
        nop #$12                ; $80
        sax ($12,x)             ; $83
        sax $12                 ; $87
        ane #$12                ; $8B
        sax $3412               ; $8F
        sha ($12),y             ; $93
        sax $12,y               ; $97
        tas $3412,y             ; $9B
        shy $3412,x             ; $9C
        shx $3412,y             ; $9E
        sha $3412,y             ; $9F
        lax ($12,x)             ; $A3
        lax $12                 ; $A7
        lax #$12                ; $AB (ca65 spelling; also lxa)
        lax $3412               ; $AF
        lax ($12),y             ; $B3
        lax $12,y               ; $B7
        las $3412,y             ; $BB
        lax $3412,y             ; $BF
        dcp ($12,x)             ; $C3
        dcp $12                 ; $C7
        axs #$12                ; $CB (ca65 spelling; also sbx)
        dcp $3412               ; $CF
        dcp ($12),y             ; $D3
        dcp $12,x               ; $D7
        dcp $3412,y             ; $DB
        dcp $3412,x             ; $DF
        isc ($12,x)             ; $E3
        isc $12                 ; $E7
        isc $3412               ; $EF
        isc ($12),y             ; $F3
        isc $12,x               ; $F7
        isc $3412,y             ; $FB
        isc $3412,x             ; $FF
