"""Signal lamps (信号机点灯): double-filament lamps (主副灯丝) proved by lamp relays DJ (灯丝继电器).

Each lamp of a colour-light signal has a main and a backup filament. When the main filament breaks while the lamp
is lit, the filament transfer switches to the backup filament and raises the main-filament alarm (主丝断丝报警);
the signal keeps its aspect. With both filaments broken the lamp is dark, the lamp current stops and the DJ in
series with it drops: that is what the interlocking sees (fail-safe: a dark lamp reads as dark, never as lit).

DJ figures (Chen Xinmei 2023, docs/references.md): it works at >= 140 mA and releases at >= 40 mA, i.e. it picks up when
the lamp current reaches 140 mA and drops when the current falls below 40 mA; in between it keeps its state
(hysteresis), which is what holds it up through the dim phase of a flashing lamp. Lamp currents are modelled values for
a 12 V 25 W lamp fed from a lighting transformer, measured in the DJ circuit.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Literal

Filament = Literal["main", "backup", "both"]


@dataclass
class LampRelay:
    """Lamp-proving relay DJ: picks up at ``pickup_mA`` and releases below ``release_mA``. Starts down."""

    pickup_mA: float = 140.0
    release_mA: float = 40.0
    up: bool = False

    def dj_up(self, current_mA: float, previous_up: bool | None = None) -> bool:
        """The relay state for ``current_mA`` given the previous state (default: its own); does not store."""
        was_up = self.up if previous_up is None else previous_up
        if was_up:
            return current_mA >= self.release_mA
        return current_mA >= self.pickup_mA

    def update(self, current_mA: float) -> bool:
        """Apply the lamp current and keep the new state."""
        self.up = self.dj_up(current_mA)
        return self.up


@dataclass
class SignalLamp:
    """One double-filament lamp with its DJ."""

    name: str
    main_ok: bool = True
    backup_ok: bool = True
    main_current_mA: float = 185.0
    backup_current_mA: float = 175.0
    dj: LampRelay = field(default_factory=LampRelay)

    def lit(self, commanded: bool) -> bool:
        """Whether the lamp shows light when ``commanded``: on the main filament or, failing that, the backup."""
        return commanded and (self.main_ok or self.backup_ok)

    def current_mA(self, commanded: bool) -> float:
        """Lamp current through the DJ: main filament if intact, else backup, else 0 (dark)."""
        if not commanded:
            return 0.0
        if self.main_ok:
            return self.main_current_mA
        if self.backup_ok:
            return self.backup_current_mA
        return 0.0

    @property
    def on_backup(self) -> bool:
        """Running on the backup filament (main broken, backup intact)."""
        return not self.main_ok and self.backup_ok

    @property
    def alarm(self) -> bool:
        """Main-filament alarm (主丝断丝报警): the main filament is broken (with or without the backup)."""
        return not self.main_ok

    @property
    def dj_up(self) -> bool:
        return self.dj.up

    def apply(self, commanded: bool) -> bool:
        """Light (or extinguish) the lamp and return the DJ state that proves it."""
        return self.dj.update(self.current_mA(commanded))

    def break_filament(self, which: Filament = "main") -> None:
        if which not in ("main", "backup", "both"):
            raise ValueError(f"filament must be main, backup or both, got {which!r}")
        if which in ("main", "both"):
            self.main_ok = False
        if which in ("backup", "both"):
            self.backup_ok = False

    def repair(self) -> None:
        self.main_ok = True
        self.backup_ok = True


class SignalLamps:
    """The lamps of one signal, by name (e.g. ``U``, ``L``, ``H``, ``2U``, ``B``, ``A``)."""

    def __init__(self, lamp_names: Iterable[str]) -> None:
        self.lamps: dict[str, SignalLamp] = {}
        for name in lamp_names:
            if name in self.lamps:
                raise ValueError(f"lamp {name!r} listed twice")
            self.lamps[name] = SignalLamp(name)
        self.commanded: set[str] = set()

    def __getitem__(self, name: str) -> SignalLamp:
        return self._lamp(name)

    def _lamp(self, name: str) -> SignalLamp:
        try:
            return self.lamps[name]
        except KeyError:
            raise KeyError(f"signal has no lamp {name!r}; lamps: {', '.join(self.lamps)}") from None

    def apply(self, lit_lamps: set[str]) -> dict[str, bool]:
        """Command exactly ``lit_lamps`` lit; return each lamp's proving (DJ up) after the currents settle."""
        self.command(lit_lamps)
        return self.proving()

    def command(self, lit_lamps: set[str]) -> bool:
        """Command exactly ``lit_lamps`` lit; whether the proving of any lamp (its DJ) changed."""
        for name in lit_lamps:
            self._lamp(name)
        commanded = self.commanded = set(lit_lamps)
        changed = False
        for name, lamp in self.lamps.items():
            was = lamp.dj.up
            if lamp.apply(name in commanded) is not was:
                changed = True
        return changed

    def proving(self) -> dict[str, bool]:
        """DJ state per lamp as last applied."""
        return {name: lamp.dj_up for name, lamp in self.lamps.items()}

    def lit(self) -> set[str]:
        """Lamps actually showing light for the last command."""
        return {name for name, lamp in self.lamps.items() if lamp.lit(name in self.commanded)}

    def currents_mA(self) -> dict[str, float]:
        return {name: lamp.current_mA(name in self.commanded) for name, lamp in self.lamps.items()}

    def alarms(self) -> list[str]:
        """Filament alarms, one line per lamp whose main filament is broken. A broken backup filament alone
        raises nothing: it stays latent until the main filament also fails."""
        out: list[str] = []
        for name, lamp in self.lamps.items():
            if not lamp.main_ok and not lamp.backup_ok:
                out.append(f"{name}: both filaments broken, lamp dark")
            elif lamp.on_backup:
                out.append(f"{name}: main filament broken, lit on backup filament")
        return out

    def break_filament(self, lamp: str, which: Filament = "main") -> None:
        self._lamp(lamp).break_filament(which)
        self._refresh()

    def repair(self, lamp: str) -> None:
        self._lamp(lamp).repair()
        self._refresh()

    def _refresh(self) -> None:
        # the lamp circuit reacts at once: re-apply the standing command so DJ follows the new current
        for name, lamp in self.lamps.items():
            lamp.apply(name in self.commanded)
