"""The world around the interlocking: the clock, the field, the trains, the query API every front end reads
(:mod:`.view`) and the command language (:mod:`.language`) that drives it all.

Python API::

    from liansuo.simulation import Simulation
    sim = Simulation("jiaopei")          # a bundled name or a path to a station file
    result = sim.command("route X XI")   # Result(ok=True, message='route X-XI selected')
    sim.run(5)                           # advance simulated time by 5 s
    sim.aspect("X")                      # 'U'
"""

from liansuo.interlocking.io import Result
from liansuo.simulation.sim import Simulation

__all__ = ["Result", "Simulation"]
