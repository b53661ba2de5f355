/* A table summed in a loop: locals on the C stack, a global array. */
unsigned char table[4] = {1, 2, 3, 4};

unsigned char sum(unsigned char n) {
    unsigned char i, s = 0;
    for (i = 0; i < n; ++i) {
        s += table[i];
    }
    return s;
}
