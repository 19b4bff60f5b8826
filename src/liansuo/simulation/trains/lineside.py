"""What a train's automation sees of the world and may ask of it: the station and its table, the trains and the
wheelsets parked by hand, the interlocking's query API, and the command language (the same commands a signaller
gives). The :class:`~simulation.sim.Simulation` is one; automatic shunting and the ATO need no more of it."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

from liansuo.circuits.railgeometry import Axle
from liansuo.interlocking.io import Result
from liansuo.interlocking.table.build import InterlockingTable
from liansuo.rules import RuleSet
from liansuo.simulation.trains.fleet import Fleet
from liansuo.simulation.view import InterlockingView
from liansuo.stations.station import Station


class Lineside(Protocol):
    @property
    def station(self) -> Station: ...
    @property
    def table(self) -> InterlockingTable: ...
    @property
    def rules(self) -> RuleSet: ...
    @property
    def fleet(self) -> Fleet: ...
    @property
    def parked(self) -> Mapping[str, list[Axle]]: ...
    @property
    def view(self) -> InterlockingView: ...
    @property
    def t(self) -> float: ...
    def command(self, line: str) -> Result: ...
    def doors(self, platform: str, action: str) -> Result:
        """Open or close a platform's screen doors through the interlocking."""
    def log(self, kind: str, text: str) -> None: ...
