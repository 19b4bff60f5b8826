"""Switch machines (转辙机) ZD6, ZDJ9, S700K with their indication relays DBJ / FBJ.

A drive command starts the motor; the switch rails arrive after the machine's throw time if the switching resistance
is within the rated force, and lock; only a locked turnout in an end position gives an indication (DBJ normal,
FBJ reverse). Faults (switching resistance and the 4 mm obstruction test: Liu Zhenhua 2023 (docs/references.md);
insulation burning: the S700K insulation-burning article, 2023 (docs/references.md)):

- ``obstruction``: something of ``mm`` (>= 4 mm) between switch rail and stock rail: the rails cannot close and lock,
  so no indication at either end;
- ``high_resistance``: switching resistance above the rated force: the clutch slips, the motor runs, the turnout
  never arrives (and keeps its old position's rails unlocked, so no indication);
- ``no_indication``: the indication circuit is broken: the turnout may be in position, DBJ and FBJ stay down;
- ``squeezed``: trailed through in the wrong position (挤岔): the lock is broken, no indication until repaired;
- ``insulation``: broken insulation at the machine shorts the track circuit: a red band on its section (the field
  applies it to the section's track circuit).
"""

from __future__ import annotations

from dataclasses import dataclass

from liansuo.rules import Equipment, MachineSpec, load_rules


@dataclass
class MachineFaults:
    obstruction_mm: float = 0.0
    resistance_N: float | None = None  # switching resistance override
    no_indication: bool = False
    squeezed: bool = False
    insulation: bool = False

    def any(self) -> bool:
        return bool(self.obstruction_mm or self.resistance_N is not None or self.no_indication or self.squeezed
                    or self.insulation)


class SwitchMachine:
    def __init__(self, turnout: str, machine: str, position: str = "normal", *,
                 equipment: Equipment | None = None) -> None:
        self.turnout = turnout
        self.type = machine
        self.equipment = equipment or load_rules().equipment
        if machine not in self.equipment.machines:
            raise ValueError(f"turnout {turnout}: the rule set has no figures for switch machine {machine} (its "
                             f"equipment.yaml knows {', '.join(self.equipment.machines)})")
        self.spec: MachineSpec = self.equipment.machines[machine]
        self.rails: str | None = position  # where the switch rails lie (None: between positions)
        self.locked = True
        self.target: str | None = None
        self.progress = 0.0  # seconds of successful movement towards target
        self.running = False  # motor current flowing
        self.faults = MachineFaults()

    # ---- what the interlocking reads --------------------------------------------------------------------------
    @property
    def dbj(self) -> bool:
        return self._indicates("normal")

    @property
    def fbj(self) -> bool:
        return self._indicates("reverse")

    def _indicates(self, position: str) -> bool:
        f = self.faults
        if f.no_indication or f.squeezed or not self.locked or self.rails != position:
            return False
        return f.obstruction_mm < self.equipment.obstruction_lock_mm

    @property
    def resistance_N(self) -> float:
        r = self.faults.resistance_N
        return self.spec.nominal_resistance_N if r is None else r

    @property
    def clutch_slips(self) -> bool:
        return self.resistance_N > self.spec.rated_force_N

    # ---- commands and time ------------------------------------------------------------------------------------
    def drive(self, target: str | None) -> None:
        """The interlocking's drive command (None: no drive)."""
        if not self.drive_changes(target):
            return
        if target is None:
            self.running = False
            self.target = None
            return
        self.target = target
        self.running = True
        self.locked = False
        self.progress = 0.0
        self.rails = None if self.rails != target else self.rails

    def drive_changes(self, target: str | None) -> bool:
        """Would :meth:`drive` with ``target`` change anything? Not a drive to where it is already going, nor to
        where its rails already lie locked with no move under way."""
        if target is None:
            return self.running or self.target is not None
        if target == self.target and self.running:
            return False
        return not (target == self.rails and self.locked and self.target is None)

    def steps_left(self, dt: float) -> int | None:
        """How many steps of ``dt`` until the one that ends the move, counted as :meth:`step` adds them up (the same
        float sums); None when no step ends it (the motor is not running, or its clutch slips)."""
        if not self.running or self.target is None or self.clutch_slips:
            return None
        progress, n = self.progress, 0
        while True:
            progress += dt
            n += 1
            if self._thrown(progress):
                return n

    def coast(self, dt: float, n: int) -> None:
        """``n`` steps that do not end the move (fewer than :meth:`steps_left`): only the progress runs on."""
        if not self.running or self.target is None or self.clutch_slips:
            return
        for _ in range(n):
            self.progress += dt

    def _thrown(self, progress: float) -> bool:
        """``progress`` seconds of movement have brought the rails over (the step that gets there ends the move)."""
        return not progress + 1e-9 < self.spec.throw_s

    def step(self, dt: float) -> bool:
        """Advance the motor; True when the indication may have changed."""
        if not self.running or self.target is None:
            return False
        if self.clutch_slips:
            return False  # the motor runs, the clutch slips, the rails do not move
        self.progress += dt
        if not self._thrown(self.progress):
            return False
        self.rails = self.target
        self.running = False
        self.target = None
        # the lock closes only if nothing holds the switch rail off the stock rail
        self.locked = self.faults.obstruction_mm < self.equipment.obstruction_lock_mm
        return True

    def trail(self, position: str) -> None:
        """A train trails through in ``position`` while the turnout lies otherwise: it is squeezed (挤岔)."""
        if self.rails != position:
            self.rails = position
            self.locked = False
            self.faults.squeezed = True

    def repair_squeeze(self) -> None:
        self.faults.squeezed = False
        self.locked = self.rails is not None and self.faults.obstruction_mm < self.equipment.obstruction_lock_mm
