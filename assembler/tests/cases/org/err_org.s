        .org later
later = $1000
        .org $1000000
        .org $1000
        .import ext
        bne ext
