        .incbin "data.bin"
        .incbin "data.bin", 1, 2
        .incbin "data.bin", 4
