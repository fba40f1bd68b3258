"""The Modbus face of the APOSS axis bus programs (tests/canopen/st/
canopen_aposs.st, canopen_enc.st), as pymodbus reaches it: a command word
and its sequence number (%MW0, %MW1: the program acts when the sequence
changes), the error number (%MW2) and status bits (%MW3), and double words
%MD0.. (holding registers 2048 + 2 n, high word first)."""
from pymodbus.client import ModbusTcpClient


class AxisMb:
    MOTOR, BUSY, INPOS, ERROR = 1, 2, 4, 8      # bits of %MW3

    def __init__(self, port):
        self.mb = ModbusTcpClient("127.0.0.1", port=port)
        self.seq = 0

    def connect(self):
        return self.mb.connect()

    def mw(self, a, n=1):
        rr = self.mb.read_holding_registers(1024 + a, n, slave=1)
        return None if rr.isError() else rr.registers

    def mds(self, a, n):
        """n double words from %MD a on, in one request: one cycle's values"""
        rr = self.mb.read_holding_registers(2048 + 2 * a, 2 * n, slave=1)
        if rr.isError():
            return None
        r = rr.registers
        v = [r[2 * k] << 16 | r[2 * k + 1] for k in range(n)]
        return [x - (1 << 32) if x & 0x80000000 else x for x in v]

    def md(self, a):
        r = self.mds(a, 1)
        return r[0] if r else None

    def put_md(self, a, v):
        v &= 0xFFFFFFFF
        self.mb.write_registers(2048 + 2 * a, [v >> 16, v & 0xFFFF], slave=1)

    def command(self, c, pos=None):
        """command c (the program's code), with the target or distance in %MD1"""
        if pos is not None:
            self.put_md(1, pos)
        self.seq += 1
        self.mb.write_registers(1024, [c, self.seq], slave=1)

    def bits(self):
        r = self.mw(3)
        return r[0] if r else 0

    def errnum(self):
        r = self.mw(2)
        return r[0] if r else None
