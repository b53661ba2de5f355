; loader.s: the uploader's RAM loader (see README.md), hooked through
; HOOK_UNKNOWN while an upload runs, removed when it ends. Two parts,
; linked as one piece:
;
; rate    (15 bytes, first): /1F toggles the 6551 between the base rate
;         and the fast one (RATE_TOGGLE is the XOR of their baud codes,
;         so the framing bits stay as the robot has them). Every other
;         command is dropped, as the ROM's BAD_COMMAND drops it: a command
;         that line noise made up must not move the rate. The uploader
;         writes this part alone at the base rate, verifies it, hooks it
;         and sends /1F, so the rest goes in at the fast rate.
; frames  (the rest): /1L and a binary frame, written straight to memory;
;         anything else falls into `rate`, so /1F still brings the line
;         back at the end.
;
; A frame, after /1L:
;
;       key  hi^key  lo^key  count^key  c0^key  c1^key  data^key...
;
; Every byte but the key is XORed with the key, which the uploader picks
; so that no byte of the frame is a slash: if the loader is not running
; (the /1L was damaged, a reset unhooked it), the ROM ignores the whole
; frame, since outside a command only a slash means anything.
;
; The header (address, count) carries a Fletcher-16 checksum: two sums
; mod 256, both starting at the key; c0 and c1 bring both to zero.
; Nothing is written unless the header checks, so a damaged header never
; writes anywhere. The data comes last byte first and is written down
; from address + count - 1 to address, so damaged or missing data lands
; only within the frame's own range, where the uploader's /7R
; verification of every byte finds it. A frame that lost a byte takes the
; next command's first byte as its last, and the ROM then ignores the rest
; of that command (it has no slash): the uploader asks again.
;
; sums    (last): /9Kaaaassnn answers Kaaaa, then for each of nn pieces
;         of ss bytes (00: 256), one after the other from aaaa, eight
;         digits: two sums of the piece, both mod 65536 and starting at
;         zero, the first (four digits) the sum of the bytes, the second
;         (four digits) the sum of the running first sums. So the
;         uploader can tell which ranges of an image a robot holds
;         already without reading every byte, and that the robot's ROM
;         is the one an image was linked against; many pieces in one
;         question, since each answer is a wait for the robot (PUTCH
;         waits for the 6551 at each character); nn = 00 answers no
;         sums. Over a piece of up to 256 bytes the first sum is exact,
;         and any change of one or two bytes changes one of them: two
;         bytes that change by +d and -d, k apart, change the second by
;         d times k, less than 65536
;         (hostile30 F1: with both sums mod 256, bit 7 of two bytes two
;         apart, or a $40 moved four bytes, passed unseen). Anything
;         else falls into `frames`. It goes in through `frames`,
;         verified, and only then is hooked: every part falls only into
;         parts verified before it.
;
; Assembled twice (build.rs): with RING = 1 the data bytes are taken
; straight from the ROM's receive ring (RXBUF, RXHEAD, RXTAIL: a 256-byte
; ring whose indexes wrap by themselves), 25 cycles a byte against about
; 60 through CHKCH. The ROM cannot answer while a frame is taken in, so
; that is time the return wire idles. The ring's tail stays in X and is
; given back when the frame is in: the frame's bytes come before any
; that follow it, so the ring holds at most the frame meanwhile (up to
; 128 bytes: it never fills). The uploader links the RING = 1 build when
; the ROM profile exports the ring.
;
; State lives in eight bytes of user zero page that the image does not
; load (LZP, chosen by the uploader): no operand is rewritten, so every
; byte of the loader reads back as it was verified.

        .import GETCH, CMD_DONE, ACIA_CTRL, RATE_TOGGLE
        .import GETHEX, PUTCH, PUTHEX, PUTEOL
        .importzp LZP
.if RING
        .import RXBUF
        .importzp RXHEAD, RXTAIL
.else
        .import CHKCH
.endif

KEY     = LZP                   ; the frame's key
SUM0    = LZP + 1               ; the Fletcher sums of the header
SUM1    = LZP + 2
HEAD    = LZP + 3               ; the header, last byte first: c1 c0 count lo hi
SUMS    = LZP                   ; sums: the answer's four bytes, last first
FIRSTHI = LZP + 3               ; the first sum, high byte
FIRSTLO = LZP + 2               ;   low byte (in X while the bytes are added)
SECOND  = LZP                   ; the second sum, low byte, then high
COUNT   = HEAD + 2
DEST    = HEAD + 3              ; lo, hi: the frame's first address
ARGS    = HEAD + 1              ; sums: its fields, last first: nn, ss, DEST
PIECES  = HEAD + 1              ; sums: pieces still to sum
SIZE    = HEAD + 2              ; sums: bytes a piece (0: 256)

        .export __scorpion_hook_unknown, rate, frames, sums
        .segment "CODE"

rate:   cmp #'F'
        bne drop
        lda ACIA_CTRL           ; the 6551 is idle: the uploader waited for every answer
        eor #RATE_TOGGLE
        sta ACIA_CTRL
drop:   jmp CMD_DONE

frames: cmp #'L'
        bne rate
        jsr GETCH               ; the key
        sta KEY
        sta SUM0
        sta SUM1
        ldx #4
head:   jsr GETCH
        eor KEY
        sta HEAD,x
        clc
        adc SUM0
        sta SUM0
        clc
        adc SUM1
        sta SUM1
        dex
        bpl head
        ora SUM0                ; A = SUM1
        bne drop                ; a damaged header: nothing is written
        ldy COUNT
.if RING
        ldx RXTAIL              ; the ring's tail in X until the frame is in
data:   cpx RXHEAD
        beq data                ; not here yet
        lda RXBUF,x
        inx
        eor KEY
        dey
        sta (DEST),y
        bne data
        stx RXTAIL
.else
data:   jsr CHKCH               ; the bytes are usually in the ring already
        bcs data
        eor KEY
        dey
        sta (DEST),y
        bne data
.endif
        beq drop

; /9Kaaaassnn: the address is answered first. Each piece's bytes are
; added at 35 cycles a byte (41 where the first sum's low byte carries,
; one more where (DEST),y crosses a page), from Y = 256 - ss, DEST that
; much lower, so the loop ends as Y wraps; DEST + 256 is then the next
; piece's first byte.
__scorpion_hook_unknown:
sums:   cmp #'K'
        bne frames
        cpx #9
        bne frames
        ldy #1
        ldx #3                  ; address high, low, ss, nn
args:   jsr GETHEX              ; X kept
        bcs sdrop
        sta ARGS,x
        dex
        bpl args
        lda #'K'
        jsr PUTCH
        lda DEST + 1
        jsr PUTHEX
        lda DEST
        jsr PUTHEX
        lda PIECES              ; none: a count noise made up, say (00
        beq eol                 ; would otherwise be 256)
piece:  lda #0
        sec
        sbc SIZE
        tay                     ; Y = 256 - ss (0 for 256)
        sty KEY
        lda DEST
        sec
        sbc KEY
        sta DEST
        bcs zero
        dec DEST + 1
zero:   ldx #0                  ; X = the first sum's low byte
        stx FIRSTHI
        stx SECOND
        stx SECOND + 1
        clc                     ; clear at the top of each byte
add:    txa
        adc (DEST),y
        tax
        bcc second
        inc FIRSTHI
        clc
second: adc SECOND              ; A = the first sum's low byte
        sta SECOND
        lda FIRSTHI
        adc SECOND + 1
        sta SECOND + 1
        clc
        iny
        bne add
        inc DEST + 1            ; the next piece's first byte
        stx FIRSTLO
        ldx #3
digits: lda SUMS,x              ; first sum high, low; second sum high, low
        jsr PUTHEX              ; X kept
        dex
        bpl digits
        dec PIECES
        bne piece
eol:    jsr PUTEOL
sdrop:  jmp CMD_DONE
