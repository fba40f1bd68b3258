#!/usr/bin/env python3
"""Two remote I/O modules for the remote I/O example, played by pymodbus:

panel (Modbus TCP, 127.0.0.1:5020): 8 push buttons (discrete inputs 0-7),
  pressed one after the other, one a second; 8 lamps (coils 0-7).
tank (Modbus RTU, slave 2, 38400 8N1 on the pseudo-terminal TTY): a level
  sensor (input register 2, per mille), a flow counter (input registers
  0-1, 32-bit, low word first), a pump (holding register 0: 1 = on); the
  flow counter as the PLC saw it comes back in holding registers 10-11.

Prints one line a second. usage: modules.py TTY [PANEL_PORT]"""
import asyncio
import sys

from pymodbus.datastore import ModbusSequentialDataBlock, ModbusServerContext, ModbusSlaveContext
from pymodbus.server import ModbusSerialServer, ModbusTcpServer
try:
    from pymodbus.framer import ModbusRtuFramer
except ImportError:
    from pymodbus.transaction import ModbusRtuFramer


def tables():
    return ModbusSlaveContext(di=ModbusSequentialDataBlock(0, [0] * 100), co=ModbusSequentialDataBlock(0, [0] * 100),
                              hr=ModbusSequentialDataBlock(0, [0] * 100), ir=ModbusSequentialDataBlock(0, [0] * 100),
                              zero_mode=True)


async def main(tty, port):
    panel, tank = tables(), tables()
    tcp = ModbusTcpServer(ModbusServerContext(slaves=panel, single=True), address=("127.0.0.1", port))
    rtu = ModbusSerialServer(ModbusServerContext(slaves={2: tank}, single=False), framer=ModbusRtuFramer,
                             port=tty, baudrate=38400, bytesize=8, parity="N", stopbits=1)
    asyncio.ensure_future(tcp.serve_forever())
    asyncio.ensure_future(rtu.serve_forever())
    level, flow, t = 500.0, 0, 0
    print(f"modules: panel on 127.0.0.1:{port}, tank (slave 2) on", tty, flush=True)
    while True:
        await asyncio.sleep(0.1)
        t += 1
        panel.setValues(2, 0, [int(i == (t // 10) % 8) for i in range(8)])
        pump = tank.getValues(3, 0, 1)[0] == 1
        level = min(1000.0, level + 8) if pump else max(0.0, level - 3)
        flow = (flow + (7 if pump else 0)) & 0xFFFFFFFF
        tank.setValues(4, 0, [flow & 0xFFFF, flow >> 16, int(level)])
        if t % 10 == 0:
            seen = tank.getValues(3, 10, 2)
            print("modules: buttons", "".join(str(b) for b in panel.getValues(2, 0, 8)),
                  "lamps", "".join(str(int(b)) for b in panel.getValues(1, 0, 8)),
                  f"| level {int(level)} pump {'ON ' if pump else 'off'} flow {flow} (PLC saw {seen[1] << 16 | seen[0]})",
                  flush=True)


if __name__ == "__main__":
    asyncio.run(main(sys.argv[1], int(sys.argv[2]) if len(sys.argv) > 2 else 5020))
