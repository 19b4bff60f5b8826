"""The station-independent figure: ZPW-2000A section configurations evaluated per second by the vectorised sweep of
``circuits.zpw2000a``, and the live simulation's single evaluations."""

from __future__ import annotations

import gc
import time
from typing import Any

from liansuo.circuits.zpw.model import ZpwCircuit, standard_positions
from liansuo.circuits.zpw.sweep import sweep

ZPW_TARGET_CONFIGS_PER_S = 100_000.0
ZPW_BALLASTS = (1.0, 1.5, 2.0, 3.0, 5.0, 10.0)  # ohm*km


def measure_zpw(repeats: int = 10, length_m: float = 1400.0) -> dict[str, Any]:
    """``zpw_configs_per_s``: one sweep of a ``length_m`` section with standard capacitors over every carrier (8),
    ``ZPW_BALLASTS``, no fault plus every single capacitor fault (open, -50 %, short) and a 0.15 ohm shunt every
    10 m; a configuration is one (carrier, ballast, fault case, shunt position): receiver voltage and cab current."""
    sweep([length_m], ballasts=ZPW_BALLASTS)  # warm-up
    gc.collect()
    t0 = time.perf_counter()
    for _ in range(repeats):
        result = sweep([length_m], ballasts=ZPW_BALLASTS)[0]
    elapsed = time.perf_counter() - t0
    configs = result.configurations
    # the live simulation's call: one section, one shunt (a moving wheelset) or a 64-axle train
    circuit = ZpwCircuit(length_m, "2600-1", standard_positions(length_m))
    calls = 200 * repeats
    t1 = time.perf_counter()
    for k in range(calls):
        circuit.evaluate([(k * 7.0 % length_m, 0.15)])
    t2 = time.perf_counter()
    for k in range(calls // 10):
        circuit.evaluate([(k % 500 + 2.5 * axle, 0.15) for axle in range(64)])
    t3 = time.perf_counter()
    return {
        "evaluate_us_one_shunt": round((t2 - t1) / calls * 1e6, 1),
        "evaluate_us_train64": round((t3 - t2) / (calls // 10) * 1e6, 1),
        "length_m": length_m, "carriers": len(result.carriers), "ballasts": len(result.ballasts_ohm_km),
        "fault_cases": len(result.faults), "shunt_positions": len(result.positions_m),
        "configurations": configs, "sweeps": repeats, "sweep_s": round(elapsed / repeats, 5),
        "zpw_configs_per_s": round(configs * repeats / elapsed, 1),
    }
