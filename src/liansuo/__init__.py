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
import sys
from importlib import import_module
from importlib.machinery import (
    BYTECODE_SUFFIXES,
    EXTENSION_SUFFIXES,
    SOURCE_SUFFIXES,
    FileFinder,
    ModuleSpec,
    SourceFileLoader,
    SourcelessFileLoader,
)
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from liansuo.interlocking.io import Result
    from liansuo.interlocking.route import InterlockingTable, Route
    from liansuo.interlocking.table import build_table
    from liansuo.proving.verify import VerifyReport, verify_station
    from liansuo.simulation.sim import Simulation
    from liansuo.simulation.unknown import UnknownId
    from liansuo.stations.loader import load as load_station
    from liansuo.stations.loader import load_text as load_station_text
    from liansuo.stations.source import StationError
    from liansuo.stations.station import Station

__version__ = "0.1.0"

_WHERE = {
    "Simulation": ("liansuo.simulation.sim", "Simulation"),
    "Result": ("liansuo.interlocking.io", "Result"),
    "UnknownId": ("liansuo.simulation.unknown", "UnknownId"),
    "Station": ("liansuo.stations.station", "Station"),
    "StationError": ("liansuo.stations.source", "StationError"),
    "load_station": ("liansuo.stations.loader", "load"),
    "load_station_text": ("liansuo.stations.loader", "load_text"),
    "build_table": ("liansuo.interlocking.table", "build_table"),
    "InterlockingTable": ("liansuo.interlocking.route", "InterlockingTable"),
    "Route": ("liansuo.interlocking.route", "Route"),
    "verify_station": ("liansuo.proving.verify", "verify_station"),
    "VerifyReport": ("liansuo.proving.verify", "VerifyReport"),
}

__all__ = ["InterlockingTable", "Result", "Route", "Simulation", "Station", "StationError", "UnknownId",
           "VerifyReport", "__version__", "build_table", "load_station", "load_station_text", "native_modules",
           "use_pure", "verify_station"]


class _PureFinder:
    """Finds liansuo's modules among its Python sources only, passing over the compiled ones of a native build."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> ModuleSpec | None:
        if not fullname.startswith("liansuo.") or path is None:
            return None
        for where in path:
            spec = FileFinder(where, (SourceFileLoader, SOURCE_SUFFIXES),
                              (SourcelessFileLoader, BYTECODE_SUFFIXES)).find_spec(fullname, target)
            if spec is not None:
                return spec
        return None


def native_modules() -> list[str]:
    """The modules of liansuo loaded so far that run compiled (a native build without LIANSUO_PURE=1)."""
    return sorted(name for name, mod in list(sys.modules.items()) if name.startswith("liansuo.")
                  and (getattr(mod, "__file__", None) or "").endswith(tuple(EXTENSION_SUFFIXES)))


def use_pure() -> None:
    """Run the Python sources of liansuo's modules from now on, in this process and the processes it starts. Asked
    before any of them is imported compiled (the suite's tests/conftest.py), else it raises."""
    os.environ["LIANSUO_PURE"] = "1"
    if not any(isinstance(f, _PureFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, _PureFinder())
    loaded = native_modules()
    if loaded:
        raise RuntimeError(f"liansuo's compiled modules are loaded already ({', '.join(loaded)}): set LIANSUO_PURE=1 "
                           "in the environment to run the Python sources")


# A native build (setup.py, docs/native.md) compiles the hot path with mypyc. LIANSUO_PURE=1 runs the Python sources
# instead: what replaces a method at run time (``liansuo mutate``'s seeded defects, the suite's doubles) needs them.
if os.environ.get("LIANSUO_PURE", "") == "1":
    use_pure()


def __getattr__(name: str) -> Any:
    where = _WHERE.get(name)
    if where is None:
        raise AttributeError(f"module 'liansuo' has no attribute {name!r}")
    value = getattr(import_module(where[0]), where[1])
    globals()[name] = value
    return value
