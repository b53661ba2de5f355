"""Runs py65's NMOS 6502 on the cases the differential test sends.

Used by emulator/tests/cpu/py65.rs: one process per test run. Reads every
case from stdin before writing anything, then writes one line per step.

Input lines:
  stream A X Y S P PC      start a stream with these registers (hex)
  mem HEX                  the stream's 64 KiB of memory
  i ADDR HEX               write these bytes at ADDR (not a CPU write), step
  irq | nmi                raise the interrupt (py65 ignores an IRQ with I set)
  end                      end of the stream: print its memory
  decimal                  exhaustive decimal ADC and SBC (see below)

Output lines: after each step "PC A X Y S P W" with W the bytes the CPU
wrote as ADDR=VAL,... (last value per address, "-" if none); after "end"
"mem HEX"; after "decimal" "decimal HEX" (see run_decimal).
"""

import sys

from py65.devices.mpu6502 import MPU


class Memory(list):
    """64 KiB that logs the addresses the CPU writes."""

    def __init__(self, data):
        super().__init__(data)
        self.written = {}

    def __setitem__(self, address, value):
        super().__setitem__(address, value)
        self.written[address] = value


def run_decimal(out):
    """For ADC then SBC, for every carry-in, A and operand: A and P after
    ADC #/SBC # in decimal mode, two bytes per case, in that order."""
    mpu = MPU()
    result = bytearray()
    for opcode in (0x69, 0xE9):
        mpu.memory[0x0200] = opcode
        for carry in (0, 1):
            for a in range(256):
                for operand in range(256):
                    mpu.memory[0x0201] = operand
                    mpu.pc = 0x0200
                    mpu.a = a
                    mpu.p = 0x30 | MPU.DECIMAL | carry
                    mpu.step()
                    result.append(mpu.a)
                    result.append(mpu.p)
    out.append("decimal " + result.hex())


def main():
    lines = sys.stdin.read().split("\n")
    out = []
    mpu = None
    memory = None
    for line in lines:
        if not line:
            continue
        word, _, rest = line.partition(" ")
        if word == "stream":
            a, x, y, s, p, pc = (int(field, 16) for field in rest.split())
            mpu = MPU()
            mpu.a, mpu.x, mpu.y, mpu.sp = a, x, y, s
            mpu.p = p | 0x30
            mpu.pc = pc
        elif word == "mem":
            memory = Memory(bytes.fromhex(rest))
            mpu.memory = memory
        elif word in ("i", "irq", "nmi"):
            if word == "i":
                address, data = rest.split()
                address = int(address, 16)
                for offset, byte in enumerate(bytes.fromhex(data)):
                    list.__setitem__(memory, (address + offset) & 0xFFFF, byte)
                memory.written = {}
                mpu.step()
            elif word == "irq":
                memory.written = {}
                mpu.irq()
            else:
                memory.written = {}
                mpu.nmi()
            writes = ",".join(
                "%04X=%02X" % item for item in sorted(memory.written.items())
            )
            out.append(
                "%04X %02X %02X %02X %02X %02X %s"
                % (mpu.pc, mpu.a, mpu.x, mpu.y, mpu.sp, mpu.p, writes or "-")
            )
        elif word == "end":
            out.append("mem " + bytes(memory).hex())
        elif word == "decimal":
            run_decimal(out)
        else:
            raise SystemExit("py65_driver: unknown input line: " + line[:40])
    sys.stdout.write("\n".join(out) + "\n")


main()
