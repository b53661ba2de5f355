/* A Scorpion-style command decoder: a switch on the letter, a struct of
 * readings, hex digits out. */
struct reading {
    unsigned char channel;
    unsigned int value;
};

static struct reading last;
char answer[8];

static char hex(unsigned char nibble) {
    return nibble < 10 ? '0' + nibble : 'A' + nibble - 10;
}

unsigned char handle(char letter, unsigned char arg) {
    switch (letter) {
    case 'A':
        last.channel = arg & 7;
        last.value = (unsigned int)arg * 3;
        answer[0] = 'A';
        answer[1] = hex(last.value >> 4 & 15);
        answer[2] = hex(last.value & 15);
        answer[3] = 0;
        return 1;
    case 'Q':
        answer[0] = 'Q';
        answer[1] = 0;
        return 1;
    default:
        return 0;
    }
}
