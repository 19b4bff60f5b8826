"""Field control (现场控制): the interlocking reads its relays from, and sends its commands to, trackside equipment
outside this process, through the change-over relay QHJ (docs/field-mode.md).

A station always powers on in simulated control (模拟控制). The sealed change-over button QHA (``changeover field``,
``changeover simulated``) picks QHJ up or lets it drop; it is accepted only at rest (:meth:`FieldControl.refuses`).
Under field control every element the link carries (its point map) is read from the link and driven through it;
every other element stays simulated.

A link is anything that carries :class:`~circuits.field.FieldCommands` out and brings a :class:`Reading` back in one
exchange per interlocking cycle: :mod:`liansuo.fieldio` has the Modbus TCP one. Whatever goes wrong with it (no
connection, a timeout, stale or malformed data) is a :class:`LinkLost`, and the link's inputs are then read fail-safe
in that same cycle: sections occupied, turnouts without indication, lamps dark, doors not proven closed. The
interlocking closes what that closes and, as for any fault, reopens nothing by itself when the link comes back.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

from liansuo.circuits.field import FieldCommands
from liansuo.interlocking.io import RelayBoard


@dataclass(frozen=True)
class Elements:
    """The elements a link carries, by kind."""

    tracks: frozenset[str] = frozenset()
    turnouts: frozenset[str] = frozenset()
    signals: frozenset[str] = frozenset()
    doors: frozenset[str] = frozenset()  # platform:side

    def describe(self) -> str:
        """'12 sections, 7 turnouts, 9 signals' (kinds it has none of left out)."""
        parts = [(len(self.tracks), "section"), (len(self.turnouts), "turnout"), (len(self.signals), "signal"),
                 (len(self.doors), "platform door side")]
        return ", ".join(f"{n} {what}{'s' if n != 1 else ''}" for n, what in parts if n) or "nothing"


@dataclass
class Reading:
    """The relays read from the field in one exchange. An element the link carries but the reading lacks is read
    fail-safe."""

    tracks: dict[str, bool] = field(default_factory=dict)  # section -> GJ up
    turnouts: dict[str, tuple[bool, bool]] = field(default_factory=dict)  # turnout -> (DBJ, FBJ)
    lamps: dict[str, dict[str, bool]] = field(default_factory=dict)  # signal -> lamp -> DJ
    flashers: dict[str, bool] = field(default_factory=dict)  # signal -> SNJ (flash check) healthy
    filaments: dict[str, bool] = field(default_factory=dict)  # signal -> DSBJ (filament alarm) up
    doors: dict[str, tuple[bool, bool]] = field(default_factory=dict)  # platform:side -> (PDKJ, PDQCJ)


class LinkLost(Exception):
    """An exchange with the field failed; the message says what and where, in a maintainer's terms ("no reply from
    127.0.0.1:5020 within 0.25 s")."""


class FieldLink(Protocol):
    """Trackside equipment outside this process, reached once per interlocking cycle."""

    @property
    def where(self) -> str:
        """Where the field is, as the console shows it ('modbus 127.0.0.1:5020')."""
        ...

    @property
    def elements(self) -> Elements:
        """The elements it carries."""
        ...

    def points(self, elements: Elements) -> list[str]:
        """The input points of ``elements``, by name ('1DG GJ', 'X DJ U'), for an alarm."""
        ...

    def exchange(self, commands: FieldCommands, *, live: bool = True) -> Reading:
        """One cycle: send ``commands`` (with ``live`` false: every output de-energised) with the next heartbeat,
        and read back the inputs the field set after acting on them; raise :class:`LinkLost` when that fails."""
        ...

    def read(self) -> Reading:
        """The inputs as they stand, sending nothing (the field does not step); :class:`LinkLost` on failure."""
        ...

    def close(self) -> None:
        ...


RETRY_CYCLES = 3  # a lost link is tried again every fourth cycle (about a second), so a console stays responsive


class FieldControl:
    """The change-over relay QHJ and the link behind it: ``up`` is field control."""

    def __init__(self, link: FieldLink, signal_lamps: dict[str, set[str]], flashers: set[str]) -> None:
        self.link = link
        self.elements = link.elements
        self.signal_lamps = signal_lamps
        self.flashers = flashers
        self.up = False
        self.lost = ""  # why the link is lost; '' while it answers
        self._quiet = 0  # while lost: cycles to go before the next try (a dead address may take a timeout to tell)

    @property
    def mode(self) -> str:
        """What the console shows: '模拟控制 simulated', '现场控制 field (modbus ...)', or that the link is lost."""
        if not self.up:
            return "模拟控制 simulated control"
        state = f"LINK LOST: {self.lost}" if self.lost else self.link.where
        return f"现场控制 field control ({state})"

    def exchange(self, commands: FieldCommands, board: RelayBoard) -> tuple[str, str] | None:
        """One cycle's exchange; the relays onto ``board``. Returns an event to log, (kind, text), when the link is
        lost or comes back."""
        if self.lost and self._quiet > 0:
            self._quiet -= 1
            self.fail_safe(board)
            return None
        try:
            reading = self.link.exchange(commands, live=not self.lost)
        except LinkLost as exc:
            return self._lost(exc, board)
        return self._read(reading, board)

    def refresh(self, board: RelayBoard) -> tuple[str, str] | None:
        """Read the inputs again without a cycle (a change-over, a restarted interlocking), onto ``board``."""
        try:
            reading = self.link.read()
        except LinkLost as exc:
            return self._lost(exc, board)
        return self._read(reading, board)

    def _lost(self, exc: LinkLost, board: RelayBoard) -> tuple[str, str] | None:
        self.fail_safe(board)
        self._quiet = RETRY_CYCLES
        if self.lost:
            return None
        self.lost = str(exc)
        points = self.link.points(self.elements)
        shown = ", ".join(points[:8]) + (f" and {len(points) - 8} more" if len(points) > 8 else "")
        return ("alarm", f"field link lost: {exc}; every input it carries is read fail-safe (occupied, no "
                         f"indication, lamp dark): {shown}; outputs de-energised")

    def _read(self, reading: Reading, board: RelayBoard) -> tuple[str, str] | None:
        self.apply(reading, board)
        if self.lost:
            self.lost = ""
            return ("control", f"field link restored ({self.link.where}); signals closed meanwhile stay closed "
                               "until reopened")
        return None

    def apply(self, r: Reading, board: RelayBoard) -> None:
        e = self.elements
        for s in e.tracks:
            board.set_track(s, r.tracks.get(s, False))
        for t in e.turnouts:
            board.set_turnout(t, *r.turnouts.get(t, (False, False)))
        for sig in e.signals:
            lamps = r.lamps.get(sig, {})
            for lamp in self.signal_lamps[sig]:
                board.set_lamp(sig, lamp, lamps.get(lamp, False))
            if sig in self.flashers:
                board.set_flasher(sig, r.flashers.get(sig, False))
            board.set_filament_alarm(sig, r.filaments.get(sig, False))
        for key in e.doors:
            board.set_doors(key, *r.doors.get(key, (False, False)))

    def fail_safe(self, board: RelayBoard) -> None:
        """Every input the link carries as the interlocking must read an input it cannot trust."""
        self.apply(Reading(), board)
