"""The trackside field: every piece of equipment whose relays the interlocking reads.

``Field.step(dt, commands)`` moves time on: switch machines turn, doors open and close, the USU flasher flashes,
lamps light as commanded, and track circuits follow the wheelsets standing on them (``set_axles``: loose wheelsets
and trains, :mod:`.shunts`) and the teaching panel's switch K (``occupy`` / ``vacate``). Relay states are read
through the ``track_up`` (``tracks_down`` for many sections at once), ``indication``, ``lamp_proven``, ``flasher_ok``
and ``doors`` methods; ``take_changes`` says what changed since it was last called, so the one reading them copies
only that. Faults are injected with ``inject`` and removed with ``repair`` (``circuits.faults`` parses them).
Traction current leaking through a long dead zone (``set_leakage``) makes a section's relay flicker down in a
pattern driven by the field's time (:mod:`.leakage`).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field

from liansuo.circuits.doors import PlatformDoors
from liansuo.circuits.faults import Fault
from liansuo.circuits.flasher import ElectronicFlasher, RelayFlasher
from liansuo.circuits.lamps import SignalLamps
from liansuo.circuits.leakage import Flicker
from liansuo.circuits.machines import SwitchMachine
from liansuo.circuits.railgeometry import Axle, geometry_of
from liansuo.circuits.shunts import OnTrack, SectionShunts, Shunt, WheelsetGroup, changed_sections
from liansuo.circuits.trackcircuits import CircuitSpec, SectionCircuit, circuit_spec
from liansuo.rules import RuleSet, load_rules
from liansuo.stations.station import Station


@dataclass
class FieldCommands:
    """What the interlocking drives, in the field's own terms."""

    drives: dict[str, str] = field(default_factory=dict)  # turnout -> position being driven to
    lamps: dict[str, set[str]] = field(default_factory=dict)  # signal -> lamps to light
    flashing: set[str] = field(default_factory=set)  # signals whose flasher is energised (USU)
    changed_signals: set[str] = field(default_factory=set)  # signals whose lamps or flashing changed
    doors: dict[str, tuple[bool, bool, bool]] = field(default_factory=dict)  # key -> (ZCKJ, KMJ, GMJ)
    cab_codes: dict[str, str | None] = field(default_factory=dict)
    axle_resets: set[str] = field(default_factory=set)  # axle-counter sections to reset (计轴复零), taken once


@dataclass
class FieldChanges:
    tracks: set[str] = field(default_factory=set)
    turnouts: set[str] = field(default_factory=set)
    signals: set[str] = field(default_factory=set)
    doors: set[str] = field(default_factory=set)


@dataclass(frozen=True)
class FieldPlan:
    """What a station's field is made of, worked out once per station and rule set (:func:`field_plan`): every
    simulation builds its own equipment from it, since every piece of equipment changes as it runs. Only values are
    here (names, and each section's :class:`~.trackcircuits.CircuitSpec`), never a live piece."""

    circuits: Mapping[str, CircuitSpec]  # by section, in the station's order
    machines: tuple[tuple[str, str], ...]  # (turnout, switch machine type)
    lamps: Mapping[str, tuple[str, ...]]  # signal -> its lamps
    flashers: tuple[tuple[str, str], ...]  # (signal showing USU, the flasher the file gives it)
    doors: tuple[str, ...]  # platform:side of every set of screen doors


def field_plan(station: Station, rules: RuleSet) -> FieldPlan:
    """The station's :class:`FieldPlan` under ``rules``, the same object for every field (``Station.derived``)."""
    return station.derived(_plan, rules)


def _plan(station: Station, rules: RuleSet) -> FieldPlan:
    lengths = geometry_of(station).section_length
    longest_25hz = rules.design.phase25hz_max_length_m
    return FieldPlan(
        {s: circuit_spec(station, s, lengths[s], longest_25hz) for s in station.sections},
        tuple((t.id, t.machine.value) for t in station.model.turnouts),
        {s.id: tuple(lamp.value for lamp in s.lamps) for s in station.model.signals},
        tuple((s.id, s.flasher) for s in station.model.signals if s.usu),
        tuple(f"{p.id}:{d.side.value}" for p in station.model.platforms for d in p.screen_doors))


class Field:
    def __init__(self, station: Station, *, flasher: str = "auto", rules: RuleSet | None = None) -> None:
        """``rules``: the rule set whose equipment figures and flashing lamp the field has (default: the default)."""
        self.station = station
        rules = rules or load_rules()
        self.flasher_lamp = rules.aspects.flasher_lamp
        self.geometry = geometry_of(station)
        plan = field_plan(station, rules)
        # every piece of equipment is this field's own, as its first evaluation left it
        self.circuits: dict[str, SectionCircuit] = {s: SectionCircuit.settled(spec)
                                                    for s, spec in plan.circuits.items()}
        equipment = rules.equipment
        self.machines = {t: SwitchMachine(t, kind, equipment=equipment) for t, kind in plan.machines}
        self.lamps = {s: SignalLamps(names) for s, names in plan.lamps.items()}
        self.flashers: dict[str, RelayFlasher | ElectronicFlasher] = {}
        for sig, own in plan.flashers:
            kind = own if flasher == "auto" else flasher
            self.flashers[sig] = RelayFlasher() if kind == "relay" else ElectronicFlasher()
        self.doors = {key: PlatformDoors(key, spec=equipment.doors) for key in plan.doors}
        self.faults: dict[tuple[str, str], Fault] = {}
        self.axles: list[Axle] = []
        self.on_track = OnTrack()  # every wheelset on the track, as the field was last told (``set_axles``)
        self._shunts = {s: SectionShunts(self.on_track, s) for s in station.sections}
        self._settled: set[str] = set()  # sections whose circuits are down by a standard shunt (``shunted_down``)
        # the shunts each other section was last evaluated with: none yet (``SectionCircuit.settled``)
        self._listed: dict[str, list[Shunt]] = {sec: [] for sec in self.circuits}
        self.cab_codes: dict[str, str | None] = {}
        self.t = 0.0  # the field's simulated time: the sum of its steps
        self.fault_stamp = 0  # counts the faults injected and repaired: what reads the circuits can tell a change
        self.flicker = Flicker()  # traction leakage through long dead zones (``set_leakage``)
        self._driven: set[str] = set()  # machines with a drive command outstanding
        self._moving: set[str] = set()
        self.stamp = 0  # counts the batches of changes taken: what reads the field can tell when nothing changed
        self.lamp_stamp = 0  # counts the lamp commands applied: what reads the lamps can tell when none changed
        self._changes = FieldChanges(set(station.sections), set(station.turnouts), set(station.signals),
                                     set(self.doors))

    # ---- occupancy ------------------------------------------------------------------------------------------
    def occupy(self, section: str) -> None:
        self.circuits[section].k_switch = True
        self._reevaluate(section)

    def vacate(self, section: str) -> None:
        self.circuits[section].k_switch = False
        self._reevaluate(section)

    def set_axles(self, axles: Iterable[Axle], groups: Mapping[str, WheelsetGroup] | None = None) -> None:
        """Where every wheelset stands now: loose ``axles``, and ``groups`` of wheelsets moving together (trains, by
        name). Sections whose shunts changed are re-evaluated, except that a circuit down by a standard shunt is
        not re-evaluated while its groups' wheelsets only move on it (it stays down by design). A loose wheelset
        whose position is not a finite number raises ``ValueError`` and changes nothing."""
        axles = list(axles)
        for a in axles:
            if not math.isfinite(a.x):
                raise ValueError(f"a wheelset on track {a.track} must stand at a finite number of metres, got {a.x!r}")
        self.axles = axles
        loose = self.geometry.shunts_of(self.axles)
        groups = dict(groups or {})
        touched = changed_sections(self.on_track, loose, groups, self._settled)
        self.on_track.loose, self.on_track.groups = loose, groups
        for sec in touched:
            self._reevaluate(sec, if_changed=True)

    def set_leakage(self, sections: Iterable[str]) -> None:
        """The sections that take traction current leaking through a long dead zone from now on (:mod:`.leakage`);
        their relays flicker down while it lasts (axle-counter sections are not touched)."""
        wanted = {s for s in sections if self.circuits[s].counter is None}
        if not wanted and not self.flicker.since:
            return  # no leakage before nor now (the common case: most stations have no long dead zone)
        for sec in self.flicker.leak(wanted, self.t):
            self._flick(sec)

    def _flick(self, section: str) -> None:
        """Hold the section's relay down, or let it go, as the leakage pattern says now."""
        c = self.circuits[section]
        down = self.flicker.down(section, self.t)
        if c.leak_drop != down:
            c.leak_drop = down
            self._reevaluate(section)

    def held_down(self) -> dict[str, str]:
        """Sections whose track relay is held down for good (past their model's range), with the reason."""
        return {s: c.held_down for s, c in self.circuits.items() if c.held_down}

    def shunts_on(self, section: str) -> list[Shunt]:
        """Every shunt on ``section`` now: (distance from its low end, ohm)."""
        return self.on_track.listed(section)

    def _reevaluate(self, section: str, *, if_changed: bool = False) -> None:
        """Update the section's circuit with its shunts now; ``if_changed``: only if they differ from the ones it
        was last evaluated with in full (a circuit down by a standard shunt is updated again, which leaves it
        down unless its shunts are gone)."""
        c = self.circuits[section]
        shunts = self._shunts[section]
        last = self._listed.get(section)
        if if_changed and last is not None and (shunts.listed() == last if last
                                                else not self.on_track.occupies(section)):
            return  # the same shunts as when last evaluated (none: without listing a train's)
        before = c.up
        c.update(shunts)
        if c.shunted_down:
            self._settled.add(section)
            self._listed.pop(section, None)
        else:
            self._settled.discard(section)
            self._listed[section] = shunts.listed()
        if c.up != before:
            self._changes.tracks.add(section)

    # ---- time ----------------------------------------------------------------------------------------------
    def step(self, dt: float, commands: FieldCommands) -> None:
        cmd = commands
        driven = set(cmd.drives) | self._driven
        for t_id in driven:
            m = self.machines[t_id]
            target = cmd.drives.get(t_id)
            if target != m.target or (target is not None and not m.running):
                was = (m.dbj, m.fbj)
                m.drive(target)
                if m.running:
                    self._moving.add(t_id)
                if (m.dbj, m.fbj) != was:
                    self._changes.turnouts.add(t_id)
        self._driven = {t for t in driven if t in cmd.drives}
        for t_id in list(self._moving):
            m = self.machines[t_id]
            was = (m.dbj, m.fbj)
            m.step(dt)
            if not m.running:
                self._moving.discard(t_id)
            if (m.dbj, m.fbj) != was:
                self._changes.turnouts.add(t_id)
        self.light(cmd)
        for sig, fl in self.flashers.items():
            if fl.energised:
                healthy = fl.healthy
                fl.step(dt)
                if fl.healthy != healthy:
                    self._changes.signals.add(sig)
        for key, d in self.doors.items():
            before = (d.pdkj, d.pdqcj)
            if key in cmd.doors:
                d.command(*cmd.doors[key])
            d.step(dt)
            if (d.pdkj, d.pdqcj) != before:
                self._changes.doors.add(key)
        self.cab_codes = cmd.cab_codes
        for sec in cmd.axle_resets:
            counter = self.circuits[sec].counter
            if counter is not None:
                counter.reset(self.circuits[sec].inside)
                self._reevaluate(sec)
        cmd.axle_resets.clear()
        self.t += dt
        for sec in self.flicker.since:
            self._flick(sec)

    def light(self, commands: FieldCommands) -> None:
        """Light the lamps and energise the flashers of the signals whose commands changed, at once (lamps take no
        time to light)."""
        cmd = commands
        for sig in cmd.changed_signals:
            self._relight(sig, cmd.lamps.get(sig, set()))
            fl = self.flashers.get(sig)
            if fl is not None and fl.energised != (sig in cmd.flashing):
                fl.energise(sig in cmd.flashing)
                self._changes.signals.add(sig)
        cmd.changed_signals.clear()

    def rest_steps(self, dt: float, commands: FieldCommands, limit: int) -> int:
        """How many of the next steps (at most ``limit``) would do nothing but run on the switch machines already
        running towards their positions: no relay changes (none is waiting to be taken either), no lamp, flasher,
        door, axle counter or leakage to work on, no drive command to act on, and no move ends. 0 when the next
        step does more than that."""
        ch = self._changes
        if ch.tracks or ch.turnouts or ch.signals or ch.doors or commands.changed_signals or commands.axle_resets \
                or self.flicker.since or any(fl.energised for fl in self.flashers.values()):
            return 0
        doors = commands.doors
        for key, d in self.doors.items():
            if d.moving or (key in doors and not d.still_under(*doors[key])):
                return 0
        drives = commands.drives
        if self._driven != drives.keys():
            return 0
        for t_id, target in drives.items():
            m = self.machines[t_id]
            if (target != m.target or not m.running) and m.drive_changes(target):
                return 0
        n = limit
        for t_id in self._moving:
            left = self.machines[t_id].steps_left(dt)
            if left is not None:
                n = min(n, left - 1)
        return max(n, 0)

    def rest(self, dt: float, n: int) -> None:
        """``n`` steps of ``dt`` allowed by :meth:`rest_steps`: the running machines' progress and the clock."""
        for t_id in self._moving:
            self.machines[t_id].coast(dt, n)
        for _ in range(n):
            self.t += dt

    def _relight(self, signal: str, lit: set[str]) -> None:
        self.lamp_stamp += 1
        if self.lamps[signal].command(lit):
            self._changes.signals.add(signal)

    # ---- relays the interlocking reads ------------------------------------------------------------------------
    def track_up(self, section: str) -> bool:
        return self.circuits[section].up

    def tracks_down(self, sections: Iterable[str]) -> set[str]:
        """Those of ``sections`` whose track relay is down, read at once (what ``track_up`` says of each)."""
        circuits = self.circuits
        return {s for s in sections if not circuits[s].up}

    def indication(self, turnout: str) -> tuple[bool, bool]:
        m = self.machines[turnout]
        return m.dbj, m.fbj

    def lamp_proven(self, signal: str, lamp: str) -> bool:
        """DJ for a lit lamp; for an unlit one the cold-filament check (冷丝检测): is a filament intact."""
        sl = self.lamps[signal]
        one = sl[lamp]
        return one.dj_up if lamp in sl.commanded else (one.main_ok or one.backup_ok)

    def filament_alarm(self, signal: str) -> bool:
        """The filament alarm unit: a main filament broken (the lamp burns on its backup, or is dark)."""
        return any(not lamp.main_ok for lamp in self.lamps[signal].lamps.values())

    def flasher_ok(self, signal: str) -> bool:
        """The flash check (SNJJ) while USU is shown; with the flasher idle there is no evidence of a failure."""
        fl = self.flashers.get(signal)
        if fl is None:
            return False
        return fl.healthy if fl.energised else True

    def doors_relays(self, key: str) -> tuple[bool, bool]:
        d = self.doors[key]
        return d.pdkj, d.pdqcj

    def note_turnout(self, turnout: str) -> None:
        """A turnout's indication may have changed outside a step (a train trailed through it)."""
        self._changes.turnouts.add(turnout)

    def take_changes(self) -> FieldChanges:
        out = self._changes
        self._changes = FieldChanges()
        if out.tracks or out.turnouts or out.signals or out.doors:
            self.stamp += 1
        return out

    # ---- what a person at the lineside would see -----------------------------------------------------------------
    def machines_running(self) -> set[str]:
        """Turnouts whose switch machine motors are running now."""
        return {t for t in self._moving if self.machines[t].running}

    def lit_lamps(self, signal: str) -> set[str]:
        """Lamps actually lit now, including the flashing lamp's phase."""
        lit = set(self.lamps[signal].lit())
        fl = self.flashers.get(signal)
        if fl is not None and fl.energised:
            lit.discard(self.flasher_lamp)
            if fl.lamp_lit:
                lit.add(self.flasher_lamp)
        return lit

    # ---- faults -------------------------------------------------------------------------------------------------
    def inject(self, fault: Fault) -> str:
        """Apply a parsed fault; '' or the reason it cannot be applied."""
        why = self._apply(fault, on=True)
        if not why:
            self.faults[(fault.kind, fault.target)] = fault
            self.fault_stamp += 1
        return why

    def repair(self, kind: str, target: str) -> str:
        fault = self.faults.get((kind, target))
        if fault is None:
            return f"there is no {kind} fault on {target}"
        why = self._apply(fault, on=False)
        if not why:
            del self.faults[(kind, target)]
            self.fault_stamp += 1
        return why

    def _apply(self, f: Fault, *, on: bool) -> str:
        k, t = f.kind, f.target
        if k in ("broken-rail", "poor-shunt", "low-ballast", "capacitor"):
            sf = self.circuits[t].faults
            if k == "broken-rail":
                sf.broken_rail_at_m = float(f.get("at")) if on else None
            elif k == "poor-shunt":
                sf.poor_shunt_ohm = float(f.get("ohm")) if on else None
            elif k == "low-ballast":
                sf.ballast_ohm_km = float(f.get("ohm_km")) if on else None
            else:
                n = int(float(f.get("n")))
                count = len(getattr(self.circuits[t].model, "capacitors_m", ()))
                if on and not 1 <= n <= count:
                    return f"section {t} has {count} compensation capacitors; n must be 1..{count}"
                if on:
                    sf.capacitors[n] = str(f.get("mode"))
                else:
                    sf.capacitors.pop(n, None)
            self._reevaluate(t)
        elif k == "axle-miscount":
            # the count stays wrong after the head is repaired, until the operator resets it (计轴复零)
            counter = self.circuits[t].counter
            if on and counter is not None:
                counter.miscount()
                self._reevaluate(t)
        elif k == "insulation":
            if t in self.station.turnouts:
                self.machines[t].faults.insulation = on
                sec = self.station.turnout_section[t]
                self.circuits[sec].faults.insulation_short = on
                self._reevaluate(sec)
            else:
                lo, hi = self.station.joint_sections(t)
                for sec in (lo, hi):
                    self.circuits[sec].faults.joint_failure = on
                    self._reevaluate(sec)
        elif k in ("no-indication", "obstruction", "high-resistance", "squeezed"):
            m = self.machines[t]
            was = (m.dbj, m.fbj)
            if k == "no-indication":
                m.faults.no_indication = on
            elif k == "obstruction":
                m.faults.obstruction_mm = float(f.get("mm")) if on else 0.0
                if not on and m.rails is not None and not m.running:
                    m.locked = True
            elif k == "high-resistance":
                m.faults.resistance_N = float(f.get("N")) if on else None
            elif on:
                m.trail("reverse" if m.rails == "normal" else "normal")
            else:
                m.repair_squeeze()
            if (m.dbj, m.fbj) != was:
                self._changes.turnouts.add(t)
        elif k == "filament":
            lamp = str(f.get("lamp"))
            if on:
                self.lamps[t].break_filament(lamp, str(f.get("which")))  # type: ignore[arg-type]
            else:
                self.lamps[t].repair(lamp)
            self._relight(t, set(self.lamps[t].commanded))
            self._changes.signals.add(t)
        elif k == "flasher":
            fl = self.flashers[t]
            if on:
                fl.bad_contact = True
            else:
                fl.repair()
            self._changes.signals.add(t)
        else:  # screen doors
            pid, _, side = t.partition(":")
            keys = [key for key in self.doors if key.split(":")[0] == pid and (not side or key.endswith(":" + side))]
            for key in keys:
                df = self.doors[key].faults
                if k == "psd-stuck":
                    df.stuck = on
                elif k == "psd-no-close":
                    df.no_close = on
                elif k == "psd-no-open":
                    df.no_open = on
                else:
                    df.bypass = on
                self._changes.doors.add(key)
        return ""

