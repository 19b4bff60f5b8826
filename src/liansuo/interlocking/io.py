"""The interlocking's only window on the world: relay states in, commands out (docs/architecture.md, principle 1).

``RelayBoard`` holds the input relays the field reports (track relays GJ, turnout indication relays DBJ/FBJ, lamp
proving relays DJ, the flasher check, platform-door relays PDKJ/PDQCJ, 64D line pulses) and remembers which changed
since the last cycle, so a cycle does work in proportion to change. Anything the board has never been told is read
fail-safe: a section is occupied, a turnout has no indication, a lamp is dark, doors are not proven closed.
``Outputs`` is what the interlocking drives: turnout commands, signal aspects, door relays, cab codes, line pulses.
"""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass(frozen=True)
class Result:
    """The answer to an operator command: accepted, or refused with the reason in a signaller's terms."""

    ok: bool
    message: str = ""

    def __bool__(self) -> bool:
        """``ok``: ``if sim.command("route X XI"):`` reads as it says."""
        return self.ok

    @staticmethod
    def accept(message: str = "") -> Result:
        return Result(True, message)

    @staticmethod
    def refuse(message: str) -> Result:
        return Result(False, message)


@dataclass
class RelayBoard:
    track: dict[str, bool] = field(default_factory=dict)  # section -> GJ up (clear)
    dbj: dict[str, bool] = field(default_factory=dict)  # turnout -> normal indication
    fbj: dict[str, bool] = field(default_factory=dict)  # turnout -> reverse indication
    lamps: dict[str, dict[str, bool]] = field(default_factory=dict)  # signal -> lamp -> DJ proven
    flasher: dict[str, bool] = field(default_factory=dict)  # signal -> SNJ/SNJJ healthy
    filament_alarm: dict[str, bool] = field(default_factory=dict)  # signal -> a main filament broken
    pdkj: dict[str, bool] = field(default_factory=dict)  # platform:side -> doors closed and locked
    pdqcj: dict[str, bool] = field(default_factory=dict)  # platform:side -> interlock bypass
    line_in: dict[str, set[str]] = field(default_factory=dict)  # link -> pulses received this cycle
    changed_tracks: set[str] = field(default_factory=set)
    changed_turnouts: set[str] = field(default_factory=set)
    changed_signals: set[str] = field(default_factory=set)
    changed_doors: set[str] = field(default_factory=set)

    # ---- written by the field ----------------------------------------------------------------------------------
    def set_track(self, section: str, clear: bool) -> None:
        if self.track.get(section) is not clear:
            self.track[section] = clear
            self.changed_tracks.add(section)

    def set_turnout(self, turnout: str, normal: bool, reverse: bool) -> None:
        if self.dbj.get(turnout) is not normal or self.fbj.get(turnout) is not reverse:
            self.dbj[turnout] = normal
            self.fbj[turnout] = reverse
            self.changed_turnouts.add(turnout)

    def set_lamp(self, signal: str, lamp: str, proven: bool) -> None:
        lamps = self.lamps.setdefault(signal, {})
        if lamps.get(lamp) is not proven:
            lamps[lamp] = proven
            self.changed_signals.add(signal)

    def set_flasher(self, signal: str, healthy: bool) -> None:
        if self.flasher.get(signal) is not healthy:
            self.flasher[signal] = healthy
            self.changed_signals.add(signal)

    def set_filament_alarm(self, signal: str, alarm: bool) -> None:
        if self.filament_alarm.get(signal, False) is not alarm:
            self.filament_alarm[signal] = alarm
            self.changed_signals.add(signal)

    def set_doors(self, key: str, closed_locked: bool, bypass: bool) -> None:
        if self.pdkj.get(key) is not closed_locked or self.pdqcj.get(key) is not bypass:
            self.pdkj[key] = closed_locked
            self.pdqcj[key] = bypass
            self.changed_doors.add(key)

    def pulse(self, link: str, message: str) -> None:
        self.line_in.setdefault(link, set()).add(message)

    def copy(self) -> RelayBoard:
        """A board of its own with the same relays and the same changes waiting to be taken."""
        other = RelayBoard()
        other.load(self)
        return other

    def load(self, other: RelayBoard) -> None:
        """Take ``other``'s relays and waiting changes, copied (``other`` is left as it is)."""
        self.track, self.dbj, self.fbj = dict(other.track), dict(other.dbj), dict(other.fbj)
        self.lamps = {sig: dict(lamps) for sig, lamps in other.lamps.items()}
        self.flasher, self.filament_alarm = dict(other.flasher), dict(other.filament_alarm)
        self.pdkj, self.pdqcj = dict(other.pdkj), dict(other.pdqcj)
        self.line_in = {link: set(msgs) for link, msgs in other.line_in.items()}
        self.changed_tracks, self.changed_turnouts = set(other.changed_tracks), set(other.changed_turnouts)
        self.changed_signals, self.changed_doors = set(other.changed_signals), set(other.changed_doors)

    # ---- read by the interlocking (fail-safe defaults) ------------------------------------------------------
    def clear(self, section: str) -> bool:
        return self.track.get(section, False)

    def indication(self, turnout: str) -> str | None:
        n, r = self.dbj.get(turnout, False), self.fbj.get(turnout, False)
        if n and not r:
            return "normal"
        if r and not n:
            return "reverse"
        return None

    def lamp_ok(self, signal: str, lamp: str) -> bool:
        return self.lamps.get(signal, {}).get(lamp, False)

    def flasher_ok(self, signal: str) -> bool:
        return self.flasher.get(signal, False)

    def doors_safe(self, key: str) -> bool:
        return self.pdkj.get(key, False) or self.pdqcj.get(key, False)

    def pending(self) -> bool:
        """A relay changed, or a line pulse came, since the interlocking last took the changes."""
        return bool(self.changed_tracks or self.changed_turnouts or self.changed_signals or self.changed_doors
                    or self.line_in)

    def take_changes(self) -> tuple[set[str], set[str], set[str], set[str], dict[str, set[str]]]:
        out = (self.changed_tracks, self.changed_turnouts, self.changed_signals, self.changed_doors, self.line_in)
        self.changed_tracks, self.changed_turnouts, self.changed_signals = set(), set(), set()
        self.changed_doors, self.line_in = set(), {}
        return out


@dataclass
class DoorCommand:
    """Relays the interlocking drives for one platform side (Yu Qinlong 2023, docs/references.md)."""

    zckj: bool = False  # platform track occupied / authorised
    kmj: bool = False  # open command
    gmj: bool = True  # close command


@dataclass
class Outputs:
    turnouts: dict[str, str] = field(default_factory=dict)  # turnout -> position being driven to
    signals: dict[str, str] = field(default_factory=dict)  # signal -> commanded aspect
    doors: dict[str, DoorCommand] = field(default_factory=dict)  # platform:side -> relays
    cab_codes: dict[str, str | None] = field(default_factory=dict)  # coded section -> low-frequency code
    line_out: dict[str, set[str]] = field(default_factory=dict)  # link -> pulses sent this cycle
    line_direction: dict[str, str] = field(default_factory=dict)  # automatic line -> 'outbound' when changed (改方)
    axle_resets: set[str] = field(default_factory=set)  # axle-counter sections to reset (计轴复零), sent once
    changed_signals: set[str] = field(default_factory=set)
    changed_turnouts: set[str] = field(default_factory=set)

    def set_aspect(self, signal: str, aspect: str) -> None:
        if self.signals.get(signal) != aspect:
            self.signals[signal] = aspect
            self.changed_signals.add(signal)

    def drive(self, turnout: str, position: str | None) -> None:
        if position is None:
            if self.turnouts.pop(turnout, None) is not None:
                self.changed_turnouts.add(turnout)
        elif self.turnouts.get(turnout) != position:
            self.turnouts[turnout] = position
            self.changed_turnouts.add(turnout)


MAX_EVENTS = 20_000  # the events an interlocking keeps (and a console of the classroom shows): the last ones


@dataclass(frozen=True)
class Event:
    t: float
    kind: str
    text: str


@dataclass(frozen=True)
class Alarm:
    """An active alarm: its kind (closed, lamp, red, filament, flasher, move, squeeze, spad), the signal or turnout
    it concerns, when it was raised and what it says; ``detail`` tells apart alarms of one kind on one element."""

    kind: str
    element: str
    t: float
    text: str
    detail: str = ""

    @staticmethod
    def key_of(kind: str, element: str, detail: str = "") -> str:
        return f"{kind}:{element}" + (f":{detail}" if detail else "")

    @property
    def key(self) -> str:
        """What names it (and what the console acknowledges it by)."""
        return self.key_of(self.kind, self.element, self.detail)


@dataclass
class Changes:
    """What changed on the relay board since the last cycle."""

    tracks: set[str]
    turnouts: set[str]
    signals: set[str]
    doors: set[str]
    pulses: dict[str, set[str]]
    commanded: bool  # aspects set by operator commands since the last cycle
