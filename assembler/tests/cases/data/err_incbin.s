        .incbin "data.bin", 2, 10
        .incbin "missing.bin"
        .incbin "data.bin", -1
