"""The slip-and-slide test run of Liu Bin et al. (docs/references.md), scripted (research code, tested, used by no
command): a locomotive accelerates, slips, runs, brakes and slides before a stop, and two odometers of
``odometry.py`` measure it side by side, one compensating, one trusting the wheel (docs/trains-automation.md).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from liansuo.simulation.trains.odometry import Correction, Odometer


@dataclass
class RunResult:
    """Time series of a scripted run; ``measured`` with compensation, ``naive`` trusting the wheel; both get the
    same balise and section corrections."""

    t: list[float] = field(default_factory=list)
    true_m: list[float] = field(default_factory=list)
    measured_m: list[float] = field(default_factory=list)
    naive_m: list[float] = field(default_factory=list)
    true_ms: list[float] = field(default_factory=list)
    wheel_ms: list[float] = field(default_factory=list)
    slipping: list[bool] = field(default_factory=list)
    sliding: list[bool] = field(default_factory=list)
    corrections: list[Correction] = field(default_factory=list)
    naive_corrections: list[Correction] = field(default_factory=list)
    stop_m: float = 0.0
    last_section_m: float = 0.0  # where the last section before the stopping point begins

    @property
    def error_m(self) -> list[float]:
        return [m - x for m, x in zip(self.measured_m, self.true_m, strict=True)]

    @property
    def naive_error_m(self) -> list[float]:
        return [m - x for m, x in zip(self.naive_m, self.true_m, strict=True)]

    def figures(self) -> dict[str, float]:
        """Max |error| with and without compensation over the run and before the first correction (the slip), the
        first correction and the error just after it, and the residual at the stop, made in the last section."""
        err, naive = self.error_m, self.naive_error_m
        first = self.corrections[0].t if self.corrections else math.inf
        pre = [i for i, t in enumerate(self.t) if t < first] or [0]
        post = next((i for i, t in enumerate(self.t) if t >= first), len(self.t) - 1)
        dt = self.t[1] - self.t[0] if len(self.t) > 1 else 0.0

        def jump(cs: list[Correction]) -> float:
            return cs[0].after_m - cs[0].before_m if cs else 0.0

        return {
            "max_error_m": max(map(abs, err)),
            "max_error_naive_m": max(map(abs, naive)),
            "slip_max_error_m": max(abs(err[i]) for i in pre),
            "slip_max_error_naive_m": max(abs(naive[i]) for i in pre),
            "first_correction_m": jump(self.corrections),
            "first_correction_naive_m": jump(self.naive_corrections),
            "after_correction_error_m": err[post],
            "stop_error_m": err[-1],
            "stop_error_naive_m": naive[-1],
            "slip_s": sum(self.slipping) * dt,
            "slide_s": sum(self.sliding) * dt,
        }


def _ramp(t: float, start: float, duration: float, rise: float) -> float:
    """0 outside [start, start + duration], 1 inside, linear over ``rise`` seconds at both ends."""
    if t <= start or t >= start + duration:
        return 0.0
    return min(1.0, (t - start) / rise, (start + duration - t) / rise)


def simulate_run(*, length_m: float = 600.0, v_max_kmh: float = 20.0, accel_ms2: float = 0.28,
                 decel_ms2: float = 0.37, dt: float = 0.1, slip: tuple[float, float, float] | None = (8.0, 4.0, 1.5),
                 slide: tuple[float, float, float] | None = (3.0, 5.0, 0.4),
                 balises: tuple[float, ...] = (100.0, 300.0), joints: tuple[float, ...] = (250.0, 450.0, 520.0),
                 accelerometer: bool = True, accel_bias_ms2: float = 0.02, true_wheel_diameter_m: float | None = None,
                 **odometer: Any) -> RunResult:
    """Accelerate, run at ``v_max_kmh``, brake to a stand at ``length_m``, reading balises at ``balises`` and
    correcting at the section joints ``joints`` (the front entering the next section).

    ``slip = (start s, duration s, excess m/s)``: the wheel spins that much faster than the locomotive runs, while
    accelerating; ``slide = (start s after braking begins, duration s, wheel/true speed ratio)``: the wheel locks
    partly while braking; ``None`` for a clean run. The accelerometer reads the true acceleration plus a bias.
    Odometer keyword arguments (``a_max``, ``window_s`` ...) go to both odometers.
    """
    v_max = v_max_kmh / 3.6
    d_acc = v_max * v_max / (2 * accel_ms2)
    d_dec = v_max * v_max / (2 * decel_ms2)
    if d_acc + d_dec > length_m:
        raise ValueError("the run is too short to reach v_max")
    t_acc = v_max / accel_ms2
    t_brake = t_acc + (length_m - d_acc - d_dec) / v_max
    t_end = t_brake + v_max / decel_ms2

    def motion(t: float) -> tuple[float, float, float]:
        """(position, speed, acceleration) of the locomotive at time t."""
        if t < t_acc:
            return accel_ms2 * t * t / 2, accel_ms2 * t, accel_ms2
        if t < t_brake:
            return d_acc + v_max * (t - t_acc), v_max, 0.0
        u = min(t, t_end) - t_brake
        return length_m - d_dec + v_max * u - decel_ms2 * u * u / 2, v_max - decel_ms2 * u, -decel_ms2

    d = float(odometer.pop("wheel_diameter_m", 1.05))
    real_d = true_wheel_diameter_m if true_wheel_diameter_m is not None else d
    comp = Odometer(d, **odometer)
    naive = Odometer(d, compensate=False, **odometer)
    out = RunResult(stop_m=length_m, last_section_m=max((j for j in joints if j < length_m), default=0.0))
    marks = sorted([(b, "balise") for b in balises] + [(j, "section") for j in joints])
    k = 0
    t = x = 0.0
    while t < t_end - 1e-9:
        h = min(dt, t_end - t)
        x_new, v, _ = motion(t + h)
        wheel = (x_new - x) / h  # the tacho counts the distance run in the interval
        a = motion(t + h / 2)[2]
        t, x = t + h, x_new
        if slip is not None:
            wheel += slip[2] * _ramp(t, slip[0], slip[1], 0.5)
        if slide is not None:
            wheel *= 1.0 - (1.0 - slide[2]) * _ramp(t, t_brake + slide[0], slide[1], 0.3)
        wheel *= real_d / d  # a worn wheel turns faster than the odometer thinks
        acc = a + accel_bias_ms2 if accelerometer else None
        for o in (comp, naive):
            o.update(h, wheel, acc)
        while k < len(marks) and marks[k][0] <= x:
            since = (x - marks[k][0]) / v if v > 0 else 0.0  # the reader's time stamp: passed during this interval
            for o in (comp, naive):
                o.correct(marks[k][0], marks[k][1], since_s=since)
            k += 1
        out.t.append(t)
        out.true_m.append(x)
        out.measured_m.append(comp.position_m)
        out.naive_m.append(naive.position_m)
        out.true_ms.append(v)
        out.wheel_ms.append(wheel)
        out.slipping.append(comp.slipping)
        out.sliding.append(comp.sliding)
    out.corrections = comp.corrections
    out.naive_corrections = naive.corrections
    return out
