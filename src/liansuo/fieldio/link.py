"""The interlocking's Modbus TCP link to the field (a :class:`~simulation.fieldlink.FieldLink`), as a Modbus client.

One exchange per interlocking cycle: write every coil and code register, then the heartbeat register (the count of
cycles, 1 to 65535 and round again, never 0), then read the echo register until the field echoes that count, and
the discrete inputs it set after acting on the commands. Anything else is :class:`LinkLost`, naming what failed: no
connection, no reply within ``timeout_s``, an exception reply, fewer bits than asked, an echo that does not come
(stale inputs: the field no longer acts on what it is sent), or an echo of 0 after others (the field's watchdog
dropped its outputs).
"""

from __future__ import annotations

import logging
import time

from liansuo.circuits.field import FieldCommands
from liansuo.fieldio import frames
from liansuo.fieldio.points import MAX_BITS, MAX_COILS, MAX_REGISTERS, PointMap
from liansuo.simulation.fieldlink import Elements, LinkLost, Reading

try:
    from pymodbus.client import ModbusTcpClient
    from pymodbus.exceptions import ModbusException
    logging.getLogger("pymodbus").setLevel(logging.CRITICAL)  # what fails is reported here, in a signaller's terms
except ImportError:  # the field extra is not installed
    ModbusTcpClient = None  # type: ignore[assignment,misc]
    ModbusException = Exception  # type: ignore[assignment,misc]

EXTRA = "field mode needs the field extra: pip install 'liansuo[field]' (pymodbus)"


def available() -> bool:
    """pymodbus is installed (the field extra)."""
    return ModbusTcpClient is not None


class ModbusLink:
    """The field at ``host:port``, wired by ``points``."""

    def __init__(self, host: str, port: int, points: PointMap, *, timeout_s: float = 0.5) -> None:
        if ModbusTcpClient is None:
            raise RuntimeError(EXTRA)
        self.host, self.port, self.pm, self.timeout_s = host, port, points, timeout_s
        self.unit = points.file.unit
        self.client = ModbusTcpClient(host, port=port, timeout=timeout_s, retries=0, reconnect_delay=0)
        self.beat = 0
        self.echoed = False  # the field has echoed a heartbeat since the link was made

    @property
    def where(self) -> str:
        return f"modbus {self.host}:{self.port}"

    @property
    def elements(self) -> Elements:
        return self.pm.elements

    def points(self, elements: Elements) -> list[str]:
        return self.pm.input_names(elements)

    def exchange(self, commands: FieldCommands, *, live: bool = True) -> Reading:
        cmd = commands if live else None
        self._connect()
        try:
            bits = frames.coils(self.pm, cmd)
            for lo in range(0, len(bits), MAX_COILS):
                self._ok(self.client.write_coils(lo, bits[lo:lo + MAX_COILS], device_id=self.unit), "coils", lo)
            first, _ = self.pm.register_span
            regs = frames.code_registers(self.pm, cmd)
            for lo in range(0, len(regs), MAX_REGISTERS):
                self._ok(self.client.write_registers(first + lo, regs[lo:lo + MAX_REGISTERS], device_id=self.unit),
                         "code registers", first + lo)
            self.beat = self.beat % 65535 + 1
            hb = self.pm.file.heartbeat
            self._ok(self.client.write_register(hb, self.beat, device_id=self.unit), "heartbeat register", hb)
            self._await_echo()
            return frames.reading(self.pm, self._inputs())
        except (ModbusException, OSError) as exc:
            self.client.close()
            raise LinkLost(f"{self.where}: {_plain(exc)}") from None

    def read(self) -> Reading:
        self._connect()
        try:
            return frames.reading(self.pm, self._inputs())
        except (ModbusException, OSError) as exc:
            self.client.close()
            raise LinkLost(f"{self.where}: {_plain(exc)}") from None

    def close(self) -> None:
        self.client.close()

    # ---- the steps -------------------------------------------------------------------------------------------------
    def _connect(self) -> None:
        if not self.client.connected and not self.client.connect():
            raise LinkLost(f"no connection to {self.host}:{self.port}")

    def _ok(self, response: object, what: str, at: int) -> None:
        if getattr(response, "isError", lambda: True)():
            self.client.close()
            raise LinkLost(f"{self.where} refused the write of the {what} at {at}: {response}")

    def _await_echo(self) -> None:
        """The field echoes the heartbeat once it has acted on the commands; within ``timeout_s``, or the inputs
        are stale."""
        at = self.pm.file.echo
        deadline = time.monotonic() + self.timeout_s
        while True:
            rr = self.client.read_input_registers(at, count=1, device_id=self.unit)
            if rr.isError() or len(rr.registers) < 1:
                raise LinkLost(f"{self.where}: a malformed reply to the read of the echo register {at}: {rr}")
            echo = rr.registers[0]
            if echo == self.beat:
                self.echoed = True
                return
            if echo == 0 and self.echoed:
                self.echoed = False
                raise LinkLost(f"{self.where}: the field's watchdog de-energised its outputs (no heartbeat came in "
                               "its time)")
            if time.monotonic() >= deadline:
                raise LinkLost(f"{self.where}: stale inputs: the field echoes heartbeat {echo}, not "
                               f"{self.beat}, after {self.timeout_s:g} s")
            time.sleep(0.001)

    def _inputs(self) -> list[bool]:
        n = self.pm.input_count
        bits: list[bool] = []
        for lo in range(0, n, MAX_BITS):
            count = min(MAX_BITS, n - lo)
            rr = self.client.read_discrete_inputs(lo, count=count, device_id=self.unit)
            if rr.isError() or len(rr.bits) < count:
                raise LinkLost(f"{self.where}: a malformed reply to the read of discrete inputs {lo}-{lo + count - 1}"
                               f": {rr}")
            bits += rr.bits[:count]
        return bits


def _plain(exc: BaseException) -> str:
    """pymodbus's exception text without its class-name prefix."""
    text = str(exc).strip() or type(exc).__name__
    return text.replace("Modbus Error: ", "")
