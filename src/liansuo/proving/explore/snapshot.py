"""A watched simulation's state, taken and put back: the explorer's way to branch from one state many times.

What changes while a station runs (the interlocking, the field and its wiring, the virtual neighbours, the world's
clock and counters, the oracle's memory) is pickled in one go, so the objects that refer to each other still do
after a restore. What never changes once built (the station, the rules, the table, the indices the interlocking and
the oracle derive from them, the rail geometry) is named in the pickle, not written: every snapshot of a station
shares it (:class:`Shared`).
"""

from __future__ import annotations

import io
import pickle
from typing import Any

from liansuo.proving.oracle.watch import Watch
from liansuo.simulation.sim import Simulation
from liansuo.simulation.view import InterlockingView

_PARTS = ("interlocking", "field", "wiring", "neighbours", "t", "parked", "alarms", "sealed")


class Shared:
    """The objects every simulation of one station shares and never changes, by name (a pickle's persistent ids)."""

    def __init__(self, sim: Simulation, watch: Watch) -> None:
        named: dict[str, Any] = {
            "station": sim.station, "rules": sim.rules, "table": sim.table, "index": sim.interlocking.core.index,
            "autoblock": sim.interlocking.core.autoblock, "geometry": sim.field.geometry,
            "topology": sim.station.topology,
        }
        oracle = watch.oracle
        for name in ("tracer", "reader", "ceiling", "onto_track", "kind", "lamps", "rear", "doors", "role",
                     "section_of", "turnout_section", "turnout_sections", "turnout_tracks", "pair_of", "lines"):
            named[f"oracle.{name}"] = getattr(oracle, name)
        flank = oracle.flank
        for name in ("role", "fouled", "partners", "limit"):
            named[f"flank.{name}"] = getattr(flank, name)
        if watch.judge is not None:
            named["judge.tables"] = watch.judge.tables
        self.by_name = named
        self.by_id = {id(obj): name for name, obj in named.items()}


class _Pickler(pickle.Pickler):
    def __init__(self, buf: io.BytesIO, shared: Shared) -> None:
        super().__init__(buf, protocol=pickle.HIGHEST_PROTOCOL)
        self.shared = shared

    def persistent_id(self, obj: Any) -> str | None:
        return self.shared.by_id.get(id(obj))


class _Unpickler(pickle.Unpickler):
    def __init__(self, buf: io.BytesIO, shared: Shared) -> None:
        super().__init__(buf)
        self.shared = shared

    def persistent_load(self, pid: Any) -> Any:
        return self.shared.by_name[pid]


def take(sim: Simulation, watch: Watch, shared: Shared) -> bytes:
    """The state of ``sim`` and of the oracle watching it."""
    buf = io.BytesIO()
    oracle = watch.oracle
    judge = watch.judge.memory if watch.judge is not None else None
    _Pickler(buf, shared).dump(([getattr(sim, name) for name in _PARTS], oracle.flank._cache, _oracle_memory(oracle),
                                judge))
    return buf.getvalue()


def restore(sim: Simulation, watch: Watch, shared: Shared, data: bytes) -> None:
    """Put ``sim`` and its oracle back in the state ``data`` was taken in."""
    parts, flank_cache, memory, judge = _Unpickler(io.BytesIO(data), shared).load()
    for name, value in zip(_PARTS, parts, strict=True):
        setattr(sim, name, value)
    sim.view = InterlockingView(sim.interlocking)
    sim.fleet.field = sim.field
    oracle = watch.oracle
    oracle.flank._cache = flank_cache
    vars(oracle).update(memory)
    if watch.judge is not None:
        watch.judge.memory = judge
    view = watch.view
    view.field = sim.field
    view._wheelsets = None
    view._showing = (-1, ())
    watch._last = ()
    watch.violations, watch.hazards = [], []


_MEMORY = ("open", "shown", "in_use", "closed", "allowed", "pending", "active", "was_moving", "approached",
           "operated", "guide_locked", "fault_released", "turnout_sections_occupied", "guide_given", "now")


def _oracle_memory(oracle: Any) -> dict[str, Any]:
    return {name: getattr(oracle, name) for name in _MEMORY}
