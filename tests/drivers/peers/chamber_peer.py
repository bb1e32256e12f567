#!/usr/bin/python3
"""A Watlow-F4-like chamber played by pymodbus 3.0 (a Modbus peer we did not write).

usage: chamber_peer.py PORT   -- serves holding registers on 127.0.0.1:PORT, unit 1, 0-based
(zero_mode) at the generic_plc map addresses: air 23.4 C, product 21.0 C, status constant,
setpoint 23.5 C, ramp 1.5 C/min, limits -45.0 / 85.0 C, run 1, no alarms.
"""
import sys

from pymodbus.datastore import ModbusSequentialDataBlock, ModbusServerContext, ModbusSlaveContext
from pymodbus.server import StartTcpServer


def tenths(value_c):
    return int(round(value_c * 10)) & 0xFFFF


def main():
    port = int(sys.argv[1])
    regs = [0] * 2100
    regs[100] = tenths(23.4)
    regs[104] = tenths(21.0)
    regs[110] = 0
    regs[200] = 1
    regs[300] = tenths(23.5)
    regs[310] = tenths(1.5)
    regs[602] = tenths(-45.0)
    regs[603] = tenths(85.0)
    regs[2000] = 1
    block = ModbusSequentialDataBlock(0, regs)
    store = ModbusSlaveContext(hr=block, ir=block, zero_mode=True)
    context = ModbusServerContext(slaves=store, single=True)
    StartTcpServer(context=context, address=("127.0.0.1", port))


if __name__ == "__main__":
    main()
