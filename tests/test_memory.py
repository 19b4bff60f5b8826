"""A station nobody uses any more is freed. verify, soak and the fuzzers build thousands of simulations in one
process; anything cached per station must let go of it, or each one keeps about a megabyte for good (issue 17: the
console fuzzer's run grew without end until the rail geometry cache stopped holding its stations)."""

from __future__ import annotations

import gc
import weakref

from liansuo.proving.oracle import Watch
from liansuo.proving.verify.probe import Probe
from liansuo.proving.verify.units import Bench
from liansuo.rules import load_rules
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


def test_a_dropped_simulation_is_freed_at_once() -> None:
    """A simulation dropped after routes, occupancy and faults, and a verify probe's watched one, leave nothing for
    the garbage collector: verify drops thousands, and freeing them by collection took about a fifth of its route
    items. (With a train on the track the field and the train's wheelsets still refer to each other.)"""
    station = load("jiaopei")
    bench = Bench.build(station, load_rules())
    gc.collect()
    gc.disable()
    try:
        sim = Simulation(station, table=bench.table)
        for line in ("route X XI", "run 5", "occupy 3G", "fault no-indication 7", "cancel X", "run 20"):
            assert sim.command(line), line
        del sim
        assert gc.collect() == 0
        probe = Probe(bench.context())
        probe.do("route X XI")
        probe.run(5.0)
        assert probe.watch.cycles > 0
        del probe
        assert gc.collect() == 0
        sim = Simulation(station, table=bench.table)
        watch = Watch(sim)
        sim.run(1.0)
        assert watch.cycles == 5  # the first look, then 4 cycles
        inner = Watch(sim)  # a second watch wraps the first one's wrappers; detached, it gives them back
        sim.run(1.0)
        assert watch.cycles == 9 and inner.cycles == 5  # each: its first look, then 4 cycles
        inner.detach()
        sim.run(1.0)
        assert watch.cycles == 13 and inner.cycles == 5
        watch.detach()
        sim.run(1.0)
        assert watch.cycles == 13 and "step" not in vars(sim) and sim.t == 4.0
        del inner
        del sim, watch
        assert gc.collect() == 0
    finally:
        gc.enable()
