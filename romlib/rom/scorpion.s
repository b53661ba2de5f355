; The Scorpion reference ROM.
;
; Implements the command protocol and extension ABI of docs/PROTOCOL.md on the
; board of emulator/src/board/map.rs. Built with our own assembler and
; linker (target scorpion-rom): see romlib/README.md for how the image,
; romlib's symbol constants and scorpion.inc are regenerated and checked.
;
; One assembly unit: the parts below are included in order.
;   loop.s       power-up, /1R, the control loop, the parser, dispatch
;   commands.s   the instructions (no answer)
;   questions.s  the questions (answer)
;   services.s   serial I/O and parsing services (the jump table's targets)
;   motion.s     the interrupt handler: receive, bumpers, the motion tick
;
; Every name of docs/PROTOCOL.md section 4 is exported; the jump table at $FF00
; keeps the services at fixed addresses across ROM revisions.

        .include "hardware.inc"
        .include "ram.inc"

        ; RAM the ROM owns, and what extensions may use
        .export HOOK_UNKNOWN, HOOK_LOOP, CMDBUF, CMDLEN
        .export IOBYTE, OBEYMASK, BUSY, LASTMOVE
        .exportzp USER_ZP_START, USER_ZP_END
        .export USER_RAM_START, USER_RAM_END
        ; the receive ring: how much a host may send ahead of an answer, and
        ; for a handler that reads its own data faster than CHKCH does
        .export RXBUF, RXBUF_SIZE
        .export EXTTAB, EXTTAB_ENTRIES, EXTTAB_ENTRY_LEN
        .exportzp RXHEAD, RXTAIL
        ; the jump table
        .export PUTCH, PUTHEX, PUTDEC4, PUTEOL, GETHEX, GETDEC
        .export IOINHIBIT, IOAPPLY, GETCH, CHKCH
        .export CMD_DONE, BAD_COMMAND, ROM_LOOP, ROM_RESET, INJECT, PENDING

        .segment "CODE"
        .include "loop.s"
        .include "commands.s"
        .include "questions.s"
        .include "services.s"
        .include "motion.s"

; ---- the service jump table: fixed addresses, never reordered ---------
; Add entries at the end only; extensions assembled against one ROM keep
; working with the next.
        .segment "JUMPTABLE"
PUTCH:          jmp putch           ; $FF00 send A (A, X, Y kept)
PUTHEX:         jmp puthex          ; $FF03 send A as two hex digits (A, X, Y kept)
PUTDEC4:        jmp putdec4         ; $FF06 send X (low) / Y (high) as four decimal digits
PUTEOL:         jmp puteol          ; $FF09 end the answer (carriage return)
GETHEX:         jmp gethex          ; $FF0C two hex digits at CMDBUF+Y into A, Y += 2; C set if not hex
GETDEC:         jmp getdec          ; $FF0F A decimal digits at CMDBUF+Y into A (low) / X (high), Y += A; C set if not digits
IOINHIBIT:      jmp io_inhibit      ; $FF12 A = the devices the Master I/O byte switches off now (bit = 1)
IOAPPLY:        jmp apply_io        ; $FF15 obey IOBYTE/OBEYMASK now (outputs, busy byte)
GETCH:          jmp getch           ; $FF18 wait for the next received byte, into A
CHKCH:          jmp chkch           ; $FF1B C clear and A = next received byte, or C set if none
CMD_DONE:       jmp cmd_done        ; $FF1E a command is finished: back to the control loop
BAD_COMMAND:    jmp bad_command     ; $FF21 HOOK_UNKNOWN's first target: drop the command
ROM_LOOP:       jmp rom_loop        ; $FF24 HOOK_LOOP's first target: one pass of the ROM's loop
ROM_RESET:      jmp soft_reset      ; $FF27 what /1R does
INJECT:         jmp inject          ; $FF2A queue A for the command parser, parsed between commands (A, X, Y kept; C set if the queue is full)
PENDING:        jmp pending         ; $FF2D A = received bytes not yet parsed, Z set if none (X, Y kept)

        .segment "VECTORS"
        .addr nmi, reset, irq
