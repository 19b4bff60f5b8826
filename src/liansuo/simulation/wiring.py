"""The wires between the trackside field and the interlocking: commands out, relays in.

Only what changed crosses: the interlocking's changed aspects become lamp commands, the field's changed relays are
copied onto the interlocking's relay board.
"""

from __future__ import annotations

from liansuo.circuits.field import Field, FieldCommands
from liansuo.interlocking.io import Outputs, RelayBoard
from liansuo.rules import RuleSet
from liansuo.simulation.fieldlink import Elements
from liansuo.stations.station import Station


class Wiring:
    def __init__(self, station: Station, rules: RuleSet, field: Field) -> None:
        self.station = station
        self.rules = rules
        self.field = field
        self.commands = FieldCommands()
        self.signal_lamps = station.derived(_signal_lamps)  # read only: shared by every wiring of the station
        self._lit = False  # until every signal is lit at power-on, and again once a restarted interlocking takes over
        self.remote = Elements()  # under field control: the elements read from the field link, not from here

    def power_on(self, board: RelayBoard, out: Outputs) -> None:
        """The station powers on: the field, as built, lights every signal at the aspect ``out`` commands (lamps
        take no time to light), and ``board`` reads every relay (``publish(board, everything=True)``).

        A field is built the same for every simulation of a station (:func:`~circuits.field.field_plan`), and the
        interlocking starts with the same aspects, so what the board reads then is the same for all of them: the
        first wiring of a station reads it, and the others copy it (verify builds thousands of simulations). With
        other aspects at power-on the board reads the field again."""
        self.field.light(self.commands_from(out))
        first = self.station.derived(_PoweredOn, self.rules)
        if first.board is not None and first.aspects == out.signals:
            self.field.take_changes()
            board.load(first.board)
            return
        self.publish(board, everything=True)
        if first.board is None:
            first.aspects, first.board = dict(out.signals), board.copy()

    def relight(self) -> None:
        """Send every signal's lamps again with the next commands (a new interlocking has taken over)."""
        self._lit = False

    def commands_from(self, out: Outputs) -> FieldCommands:
        cmd = self.commands
        cmd.drives = out.turnouts
        changed = out.changed_signals if self._lit else set(out.signals)
        self._lit = True
        for sig in changed:
            aspect = out.signals.get(sig, "")
            cmd.lamps[sig] = set(self.rules.lamps.get(aspect, [])) & self.signal_lamps[sig]
            if aspect in self.rules.aspects.flashing:
                cmd.flashing.add(sig)
            else:
                cmd.flashing.discard(sig)
            cmd.changed_signals.add(sig)
        cmd.doors = {k: (d.zckj, d.kmj, d.gmj) for k, d in out.doors.items()}
        cmd.cab_codes = out.cab_codes
        cmd.axle_resets |= out.axle_resets
        out.axle_resets.clear()
        return cmd

    def at_rest(self, out: Outputs) -> bool:
        """The commands last sent are what ``commands_from(out)`` would send now (the interlocking changed no output
        since; its drives and door relays are read in place)."""
        return self._lit and not out.changed_signals and not out.axle_resets

    def publish(self, board: RelayBoard, everything: bool = False) -> None:
        """Copy the field's changed relays (``everything``: all its relays) onto ``board``, except those of the
        elements under field control (``remote``)."""
        f = self.field
        ch = f.take_changes()
        far = self.remote
        tracks = self.station.sections if everything else ch.tracks
        for s in tracks:
            if s not in far.tracks:
                board.set_track(s, f.track_up(s))
        for t in (self.station.turnouts if everything else ch.turnouts):
            if t in far.turnouts:
                continue
            dbj, fbj = f.indication(t)
            board.set_turnout(t, dbj, fbj)
        for sig in (self.station.signals if everything else ch.signals):
            if sig in far.signals:
                continue
            for lamp in self.signal_lamps[sig]:
                board.set_lamp(sig, lamp, f.lamp_proven(sig, lamp))
            if sig in f.flashers:
                board.set_flasher(sig, f.flasher_ok(sig))
            board.set_filament_alarm(sig, f.filament_alarm(sig))
        for key in (f.doors if everything else ch.doors):
            if key in far.doors:
                continue
            pdkj, pdqcj = f.doors_relays(key)
            board.set_doors(key, pdkj, pdqcj)


class _PoweredOn:
    """What the first simulation of a station read at power-on (:meth:`Wiring.power_on`): the aspects, and the
    relay board that read the field. Set once; never changed after."""

    def __init__(self, station: Station, rules: RuleSet) -> None:
        self.aspects: dict[str, str] = {}
        self.board: RelayBoard | None = None


def _signal_lamps(station: Station) -> dict[str, set[str]]:
    """Every signal's lamps."""
    return {s.id: {lamp.value for lamp in s.lamps} for s in station.model.signals}
