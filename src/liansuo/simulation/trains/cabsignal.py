"""The cab signal (机车信号) of every train: the code it reads at its leading wheelset, and the ATP's reaction.

The cab reads the track circuit under its leading wheelset (DOMAIN.md, "Station coding"; Chen Bo 2023,
docs/references.md):

- ``none``: the wheelset is on no coded section, or on a coded section that carries no code now (no route over it):
  the driver goes by the lineside signals;
- ``code``: a coded section carrying the interlocking's low-frequency code (the field's ``cab_codes``). On a
  ZPW-2000A section the cab reads the section's carrier and the code current at the wheelset
  (:mod:`~liansuo.circuits.cabcurrent`: sent from the end the train runs towards, with the section's faults); on a
  coded 25 Hz section (superimposed coding) carrier and level are not modelled and the code is read;
- ``lost`` (掉码): the code current at the wheelset is below the carrier's minimum (``ZpwCircuit.cab_min_mA``);
- ``wrong-carrier`` (串码): the wheelset stands in a *long* dead zone (longer than the rule set's
  ``dead_zone_long_m``, :mod:`~liansuo.circuits.leakage`), where it joins one rail of the section to the other rail
  of the neighbour: both carriers are on the rails under the cab for long enough for it to decode the neighbour's,
  which differs from the one the section's train-control data announce. Chen Bo measured 255 mA and 294 mA of the
  two carriers in a 15.5 m dead zone, both above the receiving threshold.

The ATP brakes a train movement to a stand when its cab goes to ``lost`` or ``wrong-carrier``: an emergency stop
from the source ``atp`` (it outranks the driver in every mode), a train event and an alarm. The driver releases it
(``estop-release NAME atp``); the ATP brakes again at the next loss. Shunting movements are not supervised.

Work in proportion to change: the reading is worked out again only when the leading wheelset leaves the stretch of
track it was on (a track end or a long dead zone's edge), the code sent on its section changes or a fault is
injected or repaired; on a coded ZPW-2000A section the level is then read from the section's current profile each
step (a binary search).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise
from typing import Protocol

from liansuo.circuits.cabcurrent import CabCurrents
from liansuo.circuits.field import Field
from liansuo.circuits.leakage import LongDeadZone
from liansuo.circuits.trackcircuits import SectionCircuit
from liansuo.circuits.zpw.model import End, ZpwCircuit
from liansuo.simulation.trains.consist import Consist
from liansuo.simulation.trains.movement import Position, TrackGeometry
from liansuo.stations.schema import Direction
from liansuo.stations.station import Station
from liansuo.stations.topology import Move

CAB_STATES = ("none", "code", "lost", "wrong-carrier")
ATP = "atp"  # the emergency-stop source of the ATP's brake


@dataclass(frozen=True)
class CabReading:
    """What a cab signal shows: ``state`` (one of :data:`CAB_STATES`), the section under the leading wheelset, the
    low-frequency code and the carrier read, and the code current (mA) where the model gives one."""

    state: str = "none"
    section: str | None = None
    code: str | None = None
    carrier: str | None = None
    level_mA: float | None = None
    why: str = ""  # for lost and wrong-carrier: what happened, in words

    @property
    def failed(self) -> bool:
        """Code lost or a wrong carrier: what the ATP brakes on."""
        return self.state in ("lost", "wrong-carrier")


class CabSignal:
    """One train's cab signal: its reading and the stretch over which it can change only in level."""

    __slots__ = ("circuit", "code_sent", "end", "geo", "hi_s", "lo_s", "move", "reading", "stamp")

    def __init__(self) -> None:
        self.reading = CabReading()
        self.move: Move | None = None  # the front move the leading wheelset stood on when last worked out
        self.lo_s = 0.0  # ... and how far into it it may stand for the reading to hold
        self.hi_s = 0.0
        self.code_sent: str | None = None  # the code sent on its section then
        self.stamp = -1  # the field's fault stamp then
        self.circuit: SectionCircuit | None = None  # while the level follows the wheelset: the ZPW-2000A section
        self.end: End = "upper"
        self.geo: tuple[float, float, float] = (0.0, 0.0, 1.0)  # (track low, high, length) of the move


class Cabbed(Protocol):
    """What the cab reader needs of a train (:class:`~.fleet.Train`)."""

    cab: CabSignal
    pos: Position
    consist: Consist

    @property
    def direction(self) -> Direction: ...


class CabReader:
    """Reads every train's cab signal from the field."""

    def __init__(self, station: Station, fld: Field, track: TrackGeometry, zones: dict[str, list[LongDeadZone]],
                 wheel_ohm: float) -> None:
        self.station = station
        self.field = fld
        self.track = track
        self.zones = zones  # long dead zones by track
        self.wheel_ohm = wheel_ohm
        self.currents = CabCurrents()

    def update(self, tr: Cabbed) -> CabReading | None:
        """Read ``tr``'s cab now; returns the reading before when the state changed, else None."""
        cab = tr.cab
        pos = tr.pos
        move = pos.moves[-1]
        lead_s = pos.front_s - tr.consist.axle_offsets_m[0]
        fld = self.field
        if (cab.move == move and cab.lo_s <= lead_s < cab.hi_s and cab.stamp == fld.fault_stamp
                and fld.cab_codes.get(cab.reading.section or "") == cab.code_sent):
            if cab.circuit is None:
                return None
            lo, hi, length = cab.geo
            x = lo + (hi - lo) * lead_s / length if move[1] is Direction.down else hi - (hi - lo) * lead_s / length
            return self._set(tr, self._level(cab.reading, cab.circuit, x, cab.end))
        return self._set(tr, self._work_out(tr, cab, move, lead_s))

    @staticmethod
    def _set(tr: Cabbed, reading: CabReading) -> CabReading | None:
        before = tr.cab.reading
        tr.cab.reading = reading
        return before if before.state != reading.state else None

    def _work_out(self, tr: Cabbed, cab: CabSignal, move: Move, lead_s: float) -> CabReading:
        fld, station = self.field, self.station
        cab.move, cab.lo_s, cab.hi_s, cab.stamp, cab.circuit = move, 0.0, 0.0, fld.fault_stamp, None
        axles = self.track.axles(tr.pos, tr.consist.axle_offsets_m[:1])
        if not axles:  # the leading wheelset is on the open line beyond the boundary
            cab.code_sent = None
            if move[0] not in station.tracks and lead_s >= 0:
                cab.lo_s, cab.hi_s = 0.0, math.inf
            return CabReading()
        t, x = axles[0].track, axles[0].x
        sec = station.tracks[t].section
        zones = self.zones.get(t, ())
        if lead_s >= 0 and move[0] == t:  # on the front move: the reading holds up to the next zone edge or track end
            cab.geo = self.track.geo[t]
            cuts = sorted(s for z in zones for e in (z.start, z.end)
                          if (s := self.track.s_of_x(move, e)) is not None)
            bounds = [0.0, *cuts, cab.geo[2] + 1e-9]
            for a, b in pairwise(bounds):
                if a <= lead_s < b:
                    cab.lo_s, cab.hi_s = a, b
        code = cab.code_sent = fld.cab_codes.get(sec)
        if not station.sections[sec].coded or code is None:
            return CabReading("none", sec)
        circuit = fld.circuits[sec]
        if not isinstance(circuit.model, ZpwCircuit):
            return CabReading("code", sec, code)  # superimposed coding on a 25 Hz section: level not modelled
        zone = next((z for z in zones if z.start <= x < z.end), None)
        if zone is not None:
            other = zone.other(sec)
            neighbour = fld.circuits[other].model if other is not None else None
            if isinstance(neighbour, ZpwCircuit) and neighbour.carrier != circuit.model.carrier:
                return CabReading("wrong-carrier", sec, fld.cab_codes.get(str(other)), neighbour.carrier, None,
                                  f"read carrier {neighbour.carrier} of {other} in the {zone.length_m:.3g} m dead zone "
                                  f"of joint {zone.joint}, expected {circuit.model.carrier} of {sec}")
        cab.circuit = circuit
        cab.end = "upper" if tr.direction is Direction.down else "lower"
        return self._level(CabReading("code", sec, code, circuit.model.carrier), circuit, x, cab.end)

    def _level(self, reading: CabReading, circuit: SectionCircuit, x: float, end: End) -> CabReading:
        model = circuit.model
        assert isinstance(model, ZpwCircuit)
        level = self.currents.at(circuit, x - self.field.geometry.section_low[circuit.section], end, self.wheel_ohm)
        level = round(level, 1)
        if level == reading.level_mA:
            return reading
        need = model.cab_min_mA
        if level >= need:
            return CabReading("code", reading.section, reading.code, model.carrier, level)
        return CabReading("lost", reading.section, reading.code, model.carrier, level,
                          f"code lost on {reading.section}: {level:.0f} mA at the leading wheelset, "
                          f"under the {need:g} mA the cab needs on {model.carrier}")


__all__ = ["ATP", "CAB_STATES", "CabReader", "CabReading", "CabSignal"]
