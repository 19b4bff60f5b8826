"""Platform screen doors (站台门) and their interface relays (Yu Qinlong 2023, docs/references.md).

Interlocking -> doors: ZCKJ (platform track occupied / authorised), KMJ (open), GMJ (close).
Doors -> interlocking: PDKJ (all doors closed and locked), PDQCJ (interlock bypass, 互锁解除).
The doors open only with KMJ AND ZCKJ; with KMJ but no ZCKJ they stay closed. GMJ closes them.
Faults: ``stuck`` (a door stuck open: PDKJ never returns), ``no_close`` (GMJ failed: no closing),
``no_open`` (occupancy detection disturbed: ZCKJ never reaches the doors, so they do not open),
``bypass`` (the bypass switch: PDQCJ up whatever the doors do).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from liansuo.rules import DoorSpec, load_rules


@dataclass
class DoorFaults:
    stuck: bool = False
    no_close: bool = False
    no_open: bool = False
    bypass: bool = False


@dataclass
class PlatformDoors:
    key: str  # "P3:right"
    opening: float = 0.0  # 0 closed and locked, 1 fully open
    moving: int = 0  # +1 opening, -1 closing, 0 still
    faults: DoorFaults = field(default_factory=DoorFaults)
    spec: DoorSpec = field(default_factory=lambda: load_rules().equipment.doors)  # opening and closing times

    @property
    def pdkj(self) -> bool:
        return self.opening <= 0.0 and self.moving == 0 and not self.faults.stuck

    @property
    def pdqcj(self) -> bool:
        return self.faults.bypass

    @property
    def is_open(self) -> bool:
        return self.opening > 0.0 or self.faults.stuck

    def still_under(self, zckj: bool, kmj: bool, gmj: bool) -> bool:
        """Standing still, and :meth:`command` with these relays would not set it moving."""
        return not self.moving and not self._set_moving(zckj, kmj, gmj)

    def command(self, zckj: bool, kmj: bool, gmj: bool) -> None:
        way = self._set_moving(zckj, kmj, gmj)
        if way:
            self.moving = way

    def _set_moving(self, zckj: bool, kmj: bool, gmj: bool) -> int:
        """The way these relays set the doors moving: +1 opening, -1 closing, 0 as they are."""
        authorised = zckj and not self.faults.no_open
        if kmj and authorised and not gmj:
            return 1
        if gmj and not self.faults.no_close and self.opening > 0.0:
            return -1
        return 0

    def step(self, dt: float) -> bool:
        """Advance the doors; True when PDKJ may have changed."""
        if self.moving == 0:
            return False
        spec = self.spec
        before = self.pdkj
        if self.moving > 0:
            self.opening = min(1.0, self.opening + dt / spec.open_s)
            if self.opening >= 1.0:
                self.moving = 0
        else:
            self.opening = max(0.0, self.opening - dt / spec.close_s)
            if self.opening <= 0.0:
                self.moving = 0
        return before != self.pdkj
