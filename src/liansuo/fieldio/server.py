"""``liansuo field-sim``: a station's simulated outdoor equipment served as a Modbus TCP device (docs/field-mode.md).

The device has the four tables of the point map. Each time the interlocking writes a new count to the heartbeat
register, the field simulator takes the coils and code registers as the commands, steps its yard one cycle
(:class:`~.yard.FieldYard`), and echoes the count; the discrete inputs are the yard's relays as they stand when
read. pymodbus serves the protocol; the device's behaviour is its action hook (:meth:`FieldServer.action`).

The watchdog: when no new heartbeat comes for ``watchdog_s``, every output is taken as de-energised (lamps dark,
no turnout drive, no code, no door command), as an I/O module's communication watchdog does. The first heartbeat
after that is not acted on: the echo register answers 0, which the interlocking takes as a lost link (its signals
close, and reopen only when the signaller reopens them); the heartbeats after it are acted on again.
"""

from __future__ import annotations

import asyncio
import logging
import time
from collections.abc import Callable

from liansuo.fieldio import frames
from liansuo.fieldio.points import PointMap
from liansuo.fieldio.yard import FieldYard

try:
    from pymodbus.server import ModbusTcpServer
    from pymodbus.simulator import DataType, SimData, SimDevice
    logging.getLogger("pymodbus").setLevel(logging.CRITICAL)  # what fails is reported here, in a signaller's terms
except ImportError:  # the field extra is not installed
    ModbusTcpServer = None  # type: ignore[assignment,misc]

_WRITE_COILS, _WRITE_REGISTERS = (5, 15), (6, 16)
_READ_INPUTS, _READ_INPUT_REGISTERS = 2, 4


class FieldServer:
    """The yard behind a Modbus device; ``log`` gets every line worth telling the field simulator's operator."""

    def __init__(self, yard: FieldYard, points: PointMap, *, watchdog_s: float = 1.0,
                 log: Callable[[str], None] = print) -> None:
        self.yard, self.pm, self.watchdog_s, self.log = yard, points, watchdog_s, log
        self.coils = [False] * points.coil_count
        self.registers: dict[int, int] = {}
        self.beat = 0  # the heartbeat last acted on (the echo); 0 after the watchdog tripped
        self.heard = time.monotonic()
        self.energised = False  # a heartbeat has come
        self.tripped = False  # the watchdog de-energised the outputs; the next heartbeat is answered with echo 0
        self.cycles = 0
        self._told: object = None  # the last of the yard's events logged

    # ---- the device --------------------------------------------------------------------------------------------------
    def device(self) -> SimDevice:
        f = self.pm.file
        registers = max([f.heartbeat, *(p.at for p in f.codes)]) + 1
        return SimDevice(f.unit, simdata=(
            [SimData(0, count=max(1, self.pm.coil_count), values=False, datatype=DataType.BITS)],
            [SimData(0, count=max(1, self.pm.input_count), values=False, datatype=DataType.BITS)],
            [SimData(0, count=registers, values=0, datatype=DataType.REGISTERS)],
            [SimData(0, count=f.echo + 1, values=0, datatype=DataType.REGISTERS)]), action=self.action)

    async def action(self, fc: int, start: int, address: int, count: int, registers: list[int],
                     set_values: list[int] | list[bool] | None) -> None:
        """Every request: a write is taken as a command (the heartbeat steps the yard), a read of the inputs or of
        the echo is answered from the yard as it stands."""
        if set_values is not None:
            if fc in _WRITE_COILS:
                for i, v in enumerate(set_values):
                    if address + i < len(self.coils):
                        self.coils[address + i] = bool(v)
            elif fc in _WRITE_REGISTERS:
                for i, v in enumerate(set_values):
                    self.registers[address + i] = int(v)
                hb = self.pm.file.heartbeat
                if address <= hb < address + len(set_values):
                    self.heartbeat(self.registers[hb])
            return
        if fc == _READ_INPUTS:
            bits = frames.inputs(self.pm, self.yard.field)
            for w in range(len(registers)):
                word = bits[(start + w) * 16:(start + w + 1) * 16]
                registers[w] = sum(1 << j for j, up in enumerate(word) if up)
        elif fc == _READ_INPUT_REGISTERS:
            echo = self.pm.file.echo
            if start <= echo < start + len(registers):
                registers[echo - start] = self.beat

    def heartbeat(self, beat: int) -> None:
        """The interlocking's count: a new one is one cycle with the commands now in the coils."""
        if beat == self.beat or beat == 0:
            return
        self.heard = time.monotonic()
        if self.tripped:  # tell the interlocking its outputs were dropped: echo 0, the link is lost to it
            self.tripped = False
            self.beat = 0
            self.log(f"{self.yard.t:9.2f} link     heartbeat {beat} after the watchdog: answered with echo 0 (a "
                     "lost link to the interlocking)")
            return
        if not self.energised:
            self.energised = True
            self.log(f"{self.yard.t:9.2f} link     heartbeat {beat}: outputs energised from the interlocking")
        self.yard.step_with(frames.commands(self.pm, self.coils, self.registers, self.yard.bus))
        self.beat = beat
        self.cycles += 1
        self._tell()

    def watch(self) -> None:
        """De-energise every output when the heartbeat has stopped for ``watchdog_s``."""
        if not self.energised or self.tripped or time.monotonic() - self.heard < self.watchdog_s:
            return
        self.tripped, self.energised = True, False
        self.coils = [False] * len(self.coils)
        self.registers = {k: 0 for k in self.registers}
        dark = frames.commands(self.pm, self.coils, self.registers, self.yard.bus)
        self.yard.bus = dark
        self.yard.field.step(0.0, dark)
        self.log(f"{self.yard.t:9.2f} alarm    no heartbeat from the interlocking for {self.watchdog_s:g} s: every "
                 "output de-energised (lamps dark, no turnout drive, no code)")

    def command(self, line: str) -> str:
        """An instructor's line of the command language, answered."""
        result = self.yard.command(line)
        self._tell()
        return f"{'ok' if result.ok else 'refused'}: {result.message}" if result.message or not result.ok else "ok"

    def _tell(self) -> None:
        """The yard's new events (faults, trains) to the log."""
        new = []
        for e in reversed(self.yard.events):
            if e is self._told:
                break
            new.append(e)
        for e in reversed(new):
            self.log(f"{e.t:9.2f} {e.kind:8} {e.text}")
        if new:
            self._told = new[0]


async def serve(server: FieldServer, host: str, port: int, *, ready: Callable[[], None] | None = None,
                lines: asyncio.Queue[str | None] | None = None) -> None:
    """Serve until cancelled; ``lines`` brings the instructor's commands (None ends the input, not the serving).
    ``OSError`` when the address cannot be listened on."""
    modbus = ModbusTcpServer(server.device(), address=(host, port))
    try:
        await modbus.serve_forever(background=True)
    except RuntimeError:
        raise OSError(f"cannot listen on {host}:{port}: the port is taken, or the address is not this "
                      "machine's") from None
    tick = min(0.05, server.watchdog_s / 4)
    try:
        if ready is not None:
            ready()
        while True:
            server.watch()
            if lines is None:
                await asyncio.sleep(tick)
                continue
            try:
                line = await asyncio.wait_for(lines.get(), timeout=tick)
            except TimeoutError:
                continue
            if line is None:
                lines = None
            elif line.strip():
                server.log(server.command(line))
    finally:
        await modbus.shutdown()
