"""A train's on-board odometer as the fleet feeds it: every step's readings are noted, and the odometer works them
out only when someone reads it.

Nothing the simulation does depends on what the odometer believes: only an ``expect odometry`` line and the tests
read it, while every moving train fed it a tacho reading each cycle (a third of a busy cycle's train work). So the
readings (and the balise and section corrections among them) are kept in order and played into the
:class:`~.odometry.Odometer` the moment it is read, through any of the properties here: it then holds exactly what it
would have held had it been fed step by step. ``MAX_PENDING`` bounds what is kept for a train nobody reads.
"""

from __future__ import annotations

from typing import cast

from liansuo.simulation.trains.odometry import Correction, Odometer, State

MAX_PENDING = 4096  # steps noted before they are worked out anyway: about 17 simulated minutes at 0.25 s a cycle

# what was noted, in order: ("update", dt, wheel speed, accelerometer) or ("correct", position, kind, since_s)
Noted = tuple[str, float, float | str, float | None]


class OdometerFeed:
    """The odometer of one train, fed every step and worked out when read (``odometer`` gives it up to date)."""

    __slots__ = ("_odometer", "_pending")

    def __init__(self, odometer: Odometer | None = None) -> None:
        self._odometer = odometer if odometer is not None else Odometer()
        self._pending: list[Noted] = []

    # ---- fed by the fleet, every step ------------------------------------------------------------------------
    def update(self, dt: float, wheel_speed_ms: float, accel_ms2: float | None = None) -> None:
        """``Odometer.update``, worked out later (a step that could not be worked out is refused now)."""
        if dt <= 0:
            raise ValueError("need dt > 0")
        pending = self._pending
        pending.append(("update", dt, wheel_speed_ms, accel_ms2))
        if len(pending) >= MAX_PENDING:
            self._work_out()

    def correct(self, position_m: float, kind: str = "balise", *, since_s: float = 0.0) -> None:
        """``Odometer.correct``, worked out later, in its place among the steps."""
        self._pending.append(("correct", position_m, kind, since_s))

    def section_transition(self, position_m: float, *, since_s: float = 0.0) -> None:
        """``Odometer.section_transition``, worked out later."""
        self.correct(position_m, "section", since_s=since_s)

    def _work_out(self) -> None:
        pending, self._pending = self._pending, []
        o = self._odometer
        for what, a, b, c in pending:  # each entry as ``update`` or ``correct`` noted it
            if what == "update":
                o.update(a, cast(float, b), accel_ms2=c)
            else:
                o.correct(a, cast(str, b), since_s=cast(float, c))

    # ---- read: everything noted is worked out first -----------------------------------------------------------
    @property
    def odometer(self) -> Odometer:
        """The odometer, fed everything noted so far."""
        if self._pending:
            self._work_out()
        return self._odometer

    @property
    def pending(self) -> int:
        """How many steps and corrections are noted and not yet worked out."""
        return len(self._pending)

    @property
    def position_m(self) -> float:
        return self.odometer.position_m

    @property
    def speed_ms(self) -> float:
        return self.odometer.speed_ms

    @property
    def state(self) -> State:
        """'normal', 'slip' or 'slide'."""
        return "slip" if self.odometer.slipping else "slide" if self.odometer.sliding else "normal"

    @property
    def episodes(self) -> list[tuple[float, State]]:
        return self.odometer.episodes

    @property
    def corrections(self) -> list[Correction]:
        return self.odometer.corrections

    def error_m(self, true_position_m: float) -> float:
        return self.odometer.error_m(true_position_m)


__all__ = ["MAX_PENDING", "OdometerFeed"]
