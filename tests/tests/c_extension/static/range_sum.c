/* A Scorpion extension's arithmetic in C: the 16-bit sum of a memory
 * range, as the checksum example's /9K computes it in assembly. Static
 * locals (cc65 -Cl), so it needs no C runtime but ptr1. */
unsigned char *range_start;
unsigned char range_length;

unsigned int range_sum(void) {
    static unsigned int sum;
    static unsigned char i;
    sum = 0;
    for (i = 0; i != range_length; ++i) {
        sum += range_start[i];
    }
    return sum;
}
