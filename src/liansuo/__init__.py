"""liansuo (联锁): a trackside signalling and computer-based interlocking simulator for Chinese railway stations.

The public API::

    import liansuo

    station = liansuo.load_station("jiaopei")   # a bundled name or a path to a station file
    table = liansuo.build_table(station)        # the interlocking table (联锁表)
    sim = liansuo.Simulation(station)           # the station with its field and interlocking
    sim.command("route X XI")                   # Result(ok=True, message='route X-XI selected'), true when ok
    sim.run(5)                                  # simulated seconds
    sim.aspect("X")                             # 'U'; an id the station lacks raises liansuo.UnknownId (a KeyError)
    report = liansuo.verify_station(station)    # the automatic interlocking test (联锁试验)

The packages below are the layers (docs/architecture.md): ``rules`` (the national rule sets, docs/rules.md),
``stations`` (the station model), ``circuits`` (trackside equipment), ``interlocking`` (the CBI), ``simulation`` (the
world around it, with its query API ``sim.view``), ``proving`` (what proves it), ``bench`` (how fast it runs), ``tui``
(the operator console) and ``cli`` (the command line). The names here are loaded on first use, so importing one layer
does not import the others.
"""

from __future__ import annotations

import os
from importlib import import_module
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from liansuo.interlocking.io import Result
    from liansuo.interlocking.table.build import build_table
    from liansuo.interlocking.table.route import InterlockingTable, Route
    from liansuo.kit.native import native_modules, use_pure
    from liansuo.kit.source import StationError
    from liansuo.proving.verify import VerifyReport, verify_station
    from liansuo.simulation.sim import Simulation
    from liansuo.simulation.unknown import UnknownId
    from liansuo.stations.loader import load as load_station
    from liansuo.stations.loader import load_text as load_station_text
    from liansuo.stations.station import Station


_WHERE = {
    "Simulation": ("liansuo.simulation.sim", "Simulation"),
    "Result": ("liansuo.interlocking.io", "Result"),
    "UnknownId": ("liansuo.simulation.unknown", "UnknownId"),
    "Station": ("liansuo.stations.station", "Station"),
    "StationError": ("liansuo.kit.source", "StationError"),
    "load_station": ("liansuo.stations.loader", "load"),
    "load_station_text": ("liansuo.stations.loader", "load_text"),
    "build_table": ("liansuo.interlocking.table.build", "build_table"),
    "InterlockingTable": ("liansuo.interlocking.table.route", "InterlockingTable"),
    "Route": ("liansuo.interlocking.table.route", "Route"),
    "verify_station": ("liansuo.proving.verify", "verify_station"),
    "VerifyReport": ("liansuo.proving.verify", "VerifyReport"),
    "native_modules": ("liansuo.kit.native", "native_modules"),
    "use_pure": ("liansuo.kit.native", "use_pure"),
}

__all__ = ["InterlockingTable", "Result", "Route", "Simulation", "Station", "StationError", "UnknownId",
           "VerifyReport", "__version__", "build_table", "load_station", "load_station_text", "native_modules",
           "use_pure", "verify_station"]


# A native build (kit/native.py, docs/native.md) compiles the hot path with mypyc; LIANSUO_PURE=1 runs the Python
# sources instead: what replaces a method at run time (liansuo mutate's seeded defects, the suite's doubles) needs them.
if os.environ.get("LIANSUO_PURE", "") == "1":
    import_module("liansuo.kit.native").use_pure()


def __getattr__(name: str) -> Any:
    if name == "__version__":  # one source: the package metadata, written from pyproject.toml
        from liansuo.kit.jsonreport import version
        return version()
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module 'liansuo' has no attribute {name!r}")
    value = getattr(import_module(where[0]), where[1])
    globals()[name] = value
    return value
