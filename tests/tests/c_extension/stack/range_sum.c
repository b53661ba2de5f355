/* A Scorpion extension's arithmetic in C with parameters and locals on
 * cc65's C stack: the 16-bit sum of a memory range. It needs the part of
 * the C runtime in runtime.s. */
unsigned int range_sum(const unsigned char *start, unsigned char length) {
    unsigned int sum = 0;
    unsigned char i;
    for (i = 0; i != length; ++i) {
        sum += start[i];
    }
    return sum;
}
