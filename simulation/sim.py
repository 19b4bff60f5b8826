"""A running station: the clock, the field, the interlocking, and the command language that drives them.

Time is injected: ``step()`` advances the field by one interlocking cycle and then runs the cycle at the new time.
Nothing here reads the wall clock; pacing to real time belongs to the console.
"""

from __future__ import annotations

from pathlib import Path

from interlocking.io import Result
from interlocking.operations import Interlocking
from interlocking.rules import RuleSet, load_rules
from interlocking.state import RouteStage
from interlocking.table import InterlockingTable, build_table
from stations.loader import load
from stations.station import Station

from .field import IdealField


class Simulation:
    def __init__(self, station: str | Path | Station, *, cycle_s: float = 0.25, rules: str | RuleSet = "china",
                 table: InterlockingTable | None = None) -> None:
        self.station = station if isinstance(station, Station) else load(station)
        self.rules = load_rules(rules) if isinstance(rules, str) else rules
        self.table = table or build_table(self.station)
        self.cycle_s = cycle_s
        self.interlocking: Interlocking = Interlocking(self.table, self.rules, cycle_s)
        self.field: IdealField = IdealField(self.station, self.rules)
        self.t = 0.0
        self.last_result: Result | None = None
        self.field.publish(self.interlocking.board)
        self.interlocking.cycle(self.t)

    # ---- time -------------------------------------------------------------------------------------------------
    def step(self) -> None:
        self.field.step(self.cycle_s, self.interlocking.out)
        self.t = round(self.t + self.cycle_s, 9)
        self.field.publish(self.interlocking.board)
        self.interlocking.cycle(self.t)

    def run(self, seconds: float) -> None:
        for _ in range(max(0, round(seconds / self.cycle_s))):
            self.step()

    # ---- commands ---------------------------------------------------------------------------------------------
    def command(self, line: str) -> Result:
        """Run one line of the command language; scripts' ``expect`` lines check the state."""
        from .commands import execute

        self.field.publish(self.interlocking.board)
        result = execute(self, line)
        # relays follow the field at once; only the interlocking's processing is cyclic
        self.field.publish(self.interlocking.board)
        if not line.strip().startswith("expect"):
            self.last_result = result
        return result

    # ---- queries ----------------------------------------------------------------------------------------------
    def aspect(self, signal: str) -> str:
        return self.interlocking.out.signals.get(signal, "")

    def route_state(self, route_id: str) -> str:
        rs = self.interlocking.routes.get(route_id)
        if rs is None:
            return "released"
        if rs.stage is RouteStage.open:
            return "open"
        return rs.stage.value

    def section_state(self, section: str) -> str:
        if not self.interlocking.board.clear(section):
            return "occupied"
        if section in self.interlocking.section_lock:
            return "locked"
        return "free"

    def turnout_state(self, turnout: str) -> tuple[str | None, bool]:
        ts = self.interlocking.turnouts[turnout]
        locked = bool(ts.locks) or ts.single_locked or ts.guide_locked
        return self.interlocking.board.indication(turnout), locked

    def alarm_texts(self) -> list[str]:
        return [a.text for a in self.interlocking.alarms.values()]

    def event_texts(self) -> list[str]:
        return [f"{e.t:9.2f} {e.kind:8} {e.text}" for e in self.interlocking.events]
