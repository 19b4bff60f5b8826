"""The ideal field: what the interlocking reads until the trackside-circuit models take over.

Occupancy comes from ``occupy`` / ``vacate`` (the teaching base's switch K that fakes a shunt), switch machines reach
their position after the machine's throw time, lamps light, screen doors follow the truth table of DOMAIN.md section 5
(they open only with the open command AND the platform track authorised), and the 64D neighbours are virtual stations
that accept our requests and restore the line once our train has left.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from interlocking.io import Outputs, RelayBoard
from interlocking.rules import RuleSet
from stations.station import Station


@dataclass
class Machine:
    position: str | None = "normal"  # None while moving
    target: str | None = None
    remaining: float = 0.0


@dataclass
class Neighbour:
    """A virtual neighbour station at the far end of a 64D block line."""

    auto: bool = True
    outbox: list[tuple[float, str]] = field(default_factory=list)  # (send at, pulse)
    our_train_out: bool = False  # our train is on the line towards it
    seen_departure_occupied: bool = False


class IdealField:
    def __init__(self, station: Station, rules: RuleSet) -> None:
        self.station = station
        self.rules = rules
        self.occupied: set[str] = set()
        self.machines = {t: Machine() for t in station.turnouts}
        self.throw_s = {t.id: rules.throw_time_s[t.machine.value] for t in station.model.turnouts}
        self.doors_open: dict[str, bool] = {f"{p.id}:{d.side.value}": False
                                            for p in station.model.platforms for d in p.screen_doors}
        self.bypass: dict[str, bool] = dict.fromkeys(self.doors_open, False)
        self.neighbours = {lk.id: Neighbour() for lk in station.model.links if lk.kind.value == "64d"}
        self.link_section = {lk.id: (lk.sections[0] if lk.sections else "") for lk in station.model.links}
        self._dirty_tracks: set[str] = set(station.sections)
        self._dirty_turnouts: set[str] = set(station.turnouts)
        self._dirty_doors: set[str] = set(self.doors_open)
        self._lamps_published = False
        self.t = 0.0
        # equipment states the fault models of the circuits layer will drive; kept minimal here
        self.indication_lost: set[str] = set()  # turnouts whose indication circuit is broken
        self.jammed: set[str] = set()  # machines that run but never reach the end position
        self.dark: set[tuple[str, str]] = set()  # (signal, lamp) with both filaments broken
        self.flasher_failed: set[str] = set()
        self.doors_stuck: set[str] = set()  # doors that do not move whatever the command

    def set_indication_lost(self, turnout: str, lost: bool) -> None:
        (self.indication_lost.add if lost else self.indication_lost.discard)(turnout)
        self._dirty_turnouts.add(turnout)

    def set_lamp_dark(self, signal: str, lamp: str, dark: bool) -> None:
        (self.dark.add if dark else self.dark.discard)((signal, lamp))
        self._lamps_published = False

    def set_flasher_failed(self, signal: str, failed: bool) -> None:
        (self.flasher_failed.add if failed else self.flasher_failed.discard)(signal)
        self._lamps_published = False

    def set_doors(self, key: str, *, open_: bool | None = None, bypass: bool | None = None) -> None:
        if open_ is not None:
            self.doors_open[key] = open_
        if bypass is not None:
            self.bypass[key] = bypass
        self._dirty_doors.add(key)

    # ---- instructor / script actions -------------------------------------------------------------------------
    def occupy(self, section: str) -> None:
        self.occupied.add(section)
        self._dirty_tracks.add(section)

    def vacate(self, section: str) -> None:
        self.occupied.discard(section)
        self._dirty_tracks.add(section)

    def neighbour_sends(self, link: str, pulse: str) -> None:
        self.neighbours[link].outbox.append((self.t, pulse))

    # ---- one field step -------------------------------------------------------------------------------------
    def step(self, dt: float, out: Outputs) -> None:
        self.t += dt
        for t_id, target in out.turnouts.items():
            m = self.machines[t_id]
            if m.target != target and m.position != target:
                m.target = target
                m.remaining = self.throw_s[t_id]
                m.position = None
                self._dirty_turnouts.add(t_id)
        for t_id, m in self.machines.items():
            if m.target is not None and t_id not in self.jammed:
                m.remaining -= dt
                if m.remaining <= 1e-9:
                    m.position, m.target = m.target, None
                    self._dirty_turnouts.add(t_id)
        for key, cmd in out.doors.items():
            if key in self.doors_stuck:
                continue
            want_open = cmd.kmj and cmd.zckj and not cmd.gmj
            if cmd.gmj:
                want_open = False
            if self.doors_open.get(key) != want_open and (want_open or cmd.gmj):
                self.doors_open[key] = want_open
                self._dirty_doors.add(key)
        for link, pulses in out.line_out.items():
            nb = self.neighbours.get(link)
            if nb is None:
                continue
            for p in pulses:
                if p == "request" and nb.auto:
                    nb.outbox.append((self.t + self.rules.block_pulse_s, "accept"))
                elif p == "depart":
                    nb.our_train_out = True
                    nb.seen_departure_occupied = True
        out.line_out.clear()
        for link, nb in self.neighbours.items():
            if nb.our_train_out and nb.auto and self.link_section[link] not in self.occupied:
                nb.our_train_out = False
                nb.outbox.append((self.t + self.rules.block_pulse_s, "restore"))

    def publish(self, board: RelayBoard) -> None:
        for s in self._dirty_tracks:
            board.set_track(s, s not in self.occupied)
        self._dirty_tracks.clear()
        for t_id in self._dirty_turnouts:
            pos = None if t_id in self.indication_lost else self.machines[t_id].position
            board.set_turnout(t_id, pos == "normal", pos == "reverse")
        self._dirty_turnouts.clear()
        for key in self._dirty_doors:
            board.set_doors(key, not self.doors_open[key], self.bypass[key])
        self._dirty_doors.clear()
        if not self._lamps_published:
            for sig in self.station.model.signals:
                for lamp in sig.lamps:
                    board.set_lamp(sig.id, lamp.value, (sig.id, lamp.value) not in self.dark)
                board.set_flasher(sig.id, sig.id not in self.flasher_failed)
            self._lamps_published = True
        for link, nb in self.neighbours.items():
            due = [p for at, p in nb.outbox if at <= self.t]
            if due:
                nb.outbox = [(at, p) for at, p in nb.outbox if at > self.t]
                for p in due:
                    board.pulse(link, p)
