; `.faraddr`: 24-bit little-endian values, constants and addresses.
        .code
start:  .faraddr $123456, start, there + 2
        .faraddr $FFFFFF
there:  rts
