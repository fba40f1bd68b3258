"""Remote I/O modules for the modbus_io tests: real pymodbus servers (TCP,
and RTU on a pseudo-terminal) whose tables the test reads and writes
directly, and proxies that put faults between plcrt and a peer.

Peers: pymodbus servers in one asyncio loop of a thread of their own.
  peers = Peers(); dev = peers.tcp(port) ; peers.rtu(path, {1: ..., 2: ...})
  dev.set(fc, addr, values) / dev.get(fc, addr, n)     (fc 1 coils, 2 discrete
  inputs, 3 holding registers, 4 input registers); peers.stop(dev) closes it
  (its port refused), peers.tcp(port) starts it again.
FaultProxy(listen_port, peer_port): TCP, passes requests and answers
  through; mode "pass", "stall" (half an answer, then nothing), "garbage"
  (bytes no Modbus frame has), "exception" (exception 04 in place of every
  answer), "silent" (no answer at all).
SerialProxy(plc_side, peer_side): bytes between two pty pairs; with
  corrupt=True every answer gets a wrong CRC.
PtyPair(work, name): socat's two linked pseudo-terminals.
"""
import asyncio
import os
import socket
import subprocess
import threading
import time

from pymodbus.datastore import ModbusSequentialDataBlock, ModbusServerContext, ModbusSlaveContext
from pymodbus.server import ModbusSerialServer, ModbusTcpServer
try:
    from pymodbus.framer import ModbusRtuFramer
except ImportError:                        # older layouts
    from pymodbus.transaction import ModbusRtuFramer


class CountingBlock(ModbusSequentialDataBlock):
    """A table that counts the requests the server serves from it: reads
    (getValues) and writes (setValues, each noted with the reads counted
    by the device so far), so that a test bounds a delay in the device's
    own requests, whatever the host's speed."""

    def __init__(self, size, dev):
        super().__init__(0, [0] * size)
        self.dev = dev

    def getValues(self, address, count=1):
        self.dev.reads += 1
        return super().getValues(address, count)

    def setValues(self, address, values):
        if not isinstance(values, list):
            values = [values]
        super().setValues(address, values)
        self.dev.writes.append((self.dev.reads, address, list(values)))


class Dev:
    """One remote device's tables; set/get touch them directly (uncounted)."""

    def __init__(self, size=1024):
        self.reads = 0
        self.writes = []
        self.blocks = {fc: CountingBlock(size, self) for fc in (1, 2, 3, 4)}
        self.ctx = ModbusSlaveContext(co=self.blocks[1], di=self.blocks[2], hr=self.blocks[3], ir=self.blocks[4],
                                      zero_mode=True)

    def set(self, fc, addr, values):
        self.blocks[fc].values[addr:addr + len(values)] = list(values)

    def get(self, fc, addr, n):
        return list(self.blocks[fc].values[addr:addr + n])


class Peers:
    def __init__(self):
        self.loop = asyncio.new_event_loop()
        self.servers = {}
        self.t = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.t.start()

    def _run(self, coro, timeout=10):
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    def tcp(self, port, d=None):
        """A TCP server on 127.0.0.1:port answering every unit id with the
        tables of d (a new Dev if None); d."""
        d = d or Dev()
        sctx = ModbusServerContext(slaves=d.ctx, single=True)

        async def start():
            srv = ModbusTcpServer(sctx, address=("127.0.0.1", port))
            asyncio.ensure_future(srv.serve_forever())
            return srv
        srv = self._run(start())
        deadline = time.monotonic() + 10
        while time.monotonic() < deadline:           # listening?
            with socket.socket() as s:
                if s.connect_ex(("127.0.0.1", port)) == 0:
                    break
            time.sleep(0.02)
        self.servers[id(d)] = srv
        d.port = port
        return d

    def rtu(self, path, ids, baud=115200):
        """An RTU server on the pty path for the slave ids; {id: Dev}."""
        devs = {i: Dev() for i in ids}
        sctx = ModbusServerContext(slaves={i: d.ctx for i, d in devs.items()}, single=False)

        async def start():
            srv = ModbusSerialServer(sctx, framer=ModbusRtuFramer, port=path, baudrate=baud,
                                     bytesize=8, parity="N", stopbits=1)
            asyncio.ensure_future(srv.serve_forever())
            return srv
        self.servers[id(devs)] = self._run(start())
        time.sleep(0.3)
        return devs

    def stop(self, d):
        srv = self.servers.pop(id(d))
        self._run(srv.shutdown())

    def close(self):
        for srv in list(self.servers.values()):
            try:
                self._run(srv.shutdown(), 3)
            except Exception:
                pass
        self.loop.call_soon_threadsafe(self.loop.stop)


class FaultProxy:
    """127.0.0.1:port -> 127.0.0.1:peer_port, one connection at a time."""

    def __init__(self, port, peer_port):
        self.mode = "pass"
        self.peer_port = peer_port
        self.ls = socket.socket()
        self.ls.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.ls.bind(("127.0.0.1", port))
        self.ls.listen(4)
        self.conns = 0
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self):
        while True:
            try:
                c, _ = self.ls.accept()
            except OSError:
                return
            self.conns += 1
            threading.Thread(target=self._serve, args=(c,), daemon=True).start()

    @staticmethod
    def _recv_frame(s):
        head = b""
        while len(head) < 7:
            b = s.recv(7 - len(head))
            if not b:
                return None
            head += b
        n = int.from_bytes(head[4:6], "big") - 1
        body = b""
        while len(body) < n:
            b = s.recv(n - len(body))
            if not b:
                return None
            body += b
        return head + body

    def _serve(self, c):
        try:
            p = socket.create_connection(("127.0.0.1", self.peer_port), timeout=5)
        except OSError:
            c.close()
            return
        try:
            while True:
                q = self._recv_frame(c)
                if q is None:
                    break
                mode = self.mode
                if mode == "silent":
                    continue
                if mode == "exception":
                    c.sendall(q[:4] + (3).to_bytes(2, "big") + q[6:7] + bytes([q[7] | 0x80, 4]))
                    continue
                p.sendall(q)
                a = self._recv_frame(p)
                if a is None:
                    break
                if mode == "stall":
                    c.sendall(a[:len(a) // 2])
                    time.sleep(3600)
                elif mode == "garbage":
                    c.sendall(b"\xde\xad\xbe\xef" * 4)
                else:
                    c.sendall(a)
        except OSError:
            pass
        finally:
            c.close()
            p.close()


class PtyPair:
    def __init__(self, work, name):
        self.a = os.path.join(work, name + "-a")
        self.b = os.path.join(work, name + "-b")
        for x in (self.a, self.b):
            if os.path.lexists(x):
                os.unlink(x)
        self.p = subprocess.Popen(["socat", f"pty,raw,echo=0,link={self.a}", f"pty,raw,echo=0,link={self.b}"],
                                  stderr=subprocess.DEVNULL)
        deadline = time.monotonic() + 10
        while not (os.path.exists(self.a) and os.path.exists(self.b)) and time.monotonic() < deadline:
            time.sleep(0.02)

    def close(self):
        self.p.terminate()
        self.p.wait()


class SerialProxy:
    """Copies bytes between the pty plc_side (plcrt's line) and peer_side
    (the RTU server's); with corrupt set, the answers' last byte flipped."""

    def __init__(self, plc_side, peer_side):
        import termios
        import tty
        self.corrupt = False
        self.fa = os.open(plc_side, os.O_RDWR | os.O_NOCTTY)
        self.fb = os.open(peer_side, os.O_RDWR | os.O_NOCTTY)
        for f in (self.fa, self.fb):
            tty.setraw(f)
            attrs = termios.tcgetattr(f)
            termios.tcsetattr(f, termios.TCSANOW, attrs)
        threading.Thread(target=self._copy, args=(self.fa, self.fb, False), daemon=True).start()
        threading.Thread(target=self._copy, args=(self.fb, self.fa, True), daemon=True).start()

    def _copy(self, src, dst, answers):
        while True:
            try:
                b = os.read(src, 512)
            except OSError:
                return
            if not b:
                return
            if answers and self.corrupt:
                b = b[:-1] + bytes([b[-1] ^ 0x5A])
            os.write(dst, b)
