"""A station nobody uses any more is freed. verify, soak and the fuzzers build thousands of simulations in one
process; anything cached per station must let go of it, or each one keeps about a megabyte for good (issue 17: the
console fuzzer's run grew without end until the rail geometry cache stopped holding its stations)."""

from __future__ import annotations

import gc
import weakref

from liansuo.simulation.sim import Simulation
from liansuo.stations.loader import load


def test_a_simulated_station_is_freed_once_its_simulation_is_dropped() -> None:
    refs = []
    for _ in range(3):
        station = load("jiaopei")
        sim = Simulation(station)
        assert sim.command("route X XI")
        assert sim.command("run 5")
        refs.append(weakref.ref(station))
        del sim, station
    gc.collect()
    assert [r() for r in refs] == [None, None, None]
