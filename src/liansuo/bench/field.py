"""Field mode's figure: interlocking cycles per second in field control, each one a Modbus TCP exchange with
``liansuo field-sim`` in a second process on this machine (docs/field-mode.md), beside the same station's cycles in
simulated control in the same run."""

from __future__ import annotations

import socket
import subprocess
import sys
import time
from typing import Any

STATION = "jiaopei"


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def measure_field(cycles: int) -> dict[str, Any]:
    """``field_cycles_per_s``: cycles of ``STATION`` with route X-XI open, in field control against field-sim over
    localhost (the exchange: coils, code and heartbeat registers written, the echo and the inputs read), and the same
    cycles in simulated control; ``realtime_factor_field`` at a 0.25 s cycle."""
    from liansuo.fieldio.link import EXTRA, ModbusLink, available

    if not available():
        return {"station": STATION, "skipped": EXTRA}
    from liansuo.fieldio import points
    from liansuo.simulation.sim import Simulation

    port = _free_port()
    server = subprocess.Popen([sys.executable, "-m", "liansuo", "field-sim", STATION, "--modbus", f"127.0.0.1:{port}"],
                              stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    try:
        ready = server.stdout.readline() if server.stdout else ""
        if not ready.startswith("field-sim"):
            return {"station": STATION, "skipped": f"field-sim did not start: {ready.strip() or 'no output'}"}
        field = Simulation(STATION)
        field.attach_field(ModbusLink("127.0.0.1", port, points.from_station(field.station, field.rules)))
        simulated = Simulation(STATION)
        figures: dict[str, float] = {}
        for name, sim in (("field", field), ("simulated", simulated)):
            if name == "field" and not sim.command("changeover field"):
                return {"station": STATION, "skipped": "the change-over to field control was refused"}
            sim.command("route X XI")
            sim.run(5)
            t0 = time.perf_counter()
            for _ in range(cycles):
                sim.step()
            figures[name] = cycles / (time.perf_counter() - t0)
        field.close()
    finally:
        server.terminate()
        server.wait(10)
    return {
        "station": STATION, "cycles": cycles, "transport": "modbus tcp, 127.0.0.1",
        "field_cycles_per_s": round(figures["field"], 1),
        "field_cycle_ms": round(1000 / figures["field"], 3),
        "realtime_factor_field": round(figures["field"] * 0.25, 1),
        "simulated_cycles_per_s": round(figures["simulated"], 1),
        "ratio_simulated_to_field": round(figures["simulated"] / figures["field"], 1),
    }
