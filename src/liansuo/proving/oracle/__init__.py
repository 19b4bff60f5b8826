"""The independent safety oracle (docs/safety.md).

It reads the station topology and the field as it is (lamps lit, switch rails, relays, wheelsets, doors, block
lines), traces the movement authority of every open signal and every movement under way, and judges them against
the safety properties. It imports nothing of the interlocking but its rule data: not the table, not the route
engine, not the aspect rules (``tests/test_oracle.py`` holds it to that).
"""

from liansuo.proving.oracle.authority import Authority, Tracer
from liansuo.proving.oracle.check import Oracle
from liansuo.proving.oracle.records import Finding
from liansuo.proving.oracle.watch import SimulationView, Violation, Watch

__all__ = ["Authority", "Finding", "Oracle", "SimulationView", "Tracer", "Violation", "Watch"]
