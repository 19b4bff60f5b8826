"""``liansuo bench``: how fast the table is derived and the interlocking cycles, on a generated hub and on jiaopei.

The benchmark is the one place that reads the wall clock (``time.perf_counter``); the simulation itself never does.
Figures are reported, never asserted: targets are listed with whether this machine met them. See docs/benchmark.md.

For each station:

* ``load_s``: YAML -> validated :class:`~stations.station.Station`; ``table_build_s``: :func:`build_table` on it;
* ``cycle_us_idle``: mean wall time of one :meth:`Simulation.step` (field step + interlocking cycle) with nothing
  happening;
* ``circuit_us_busy``: of the busy cycle, the time in the trackside field: its step (machines, lamps, flashers,
  doors) and the track-circuit re-evaluations the moving occupancy causes.
* ``cycle_us_busy``: the same with up to 20 non-conflicting train routes set, opened and traversed over and over: a
  driver occupies each route's approach and sections in order and vacates them behind (``field.occupy/vacate``, the
  teaching base's switch K), and sets the route again once it has released;
* ``realtime_factor``: simulated seconds per wall second over the busy run, driver and route commands included.

And on the hub, trains (:mod:`.trains`): ``realtime_factor_trains``, 10 signal-obeying trains running
through the hub on the kinematic engine, and ``realtime_factor_trains_sumo``, the same on the SUMO engine, with their
ratio (SUMO "not installed" where the extra is missing).

And once, station-independent: ``zpw_configs_per_s``, ZPW-2000A section configurations (carrier x ballast x
capacitor fault x shunt position) evaluated per second by the vectorised sweep of ``circuits.zpw2000a``.
"""
