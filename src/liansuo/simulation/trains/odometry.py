"""Speed and distance measurement of a shunting locomotive (测速测距), after Liu Bin et al. (docs/references.md).

The tacho (光电速度传感器) turns wheel revolutions into pulses; over a sampling time ``t`` with ``n`` pulses the speed
is ``v = pi * d * n / (N * t)`` (``d`` wheel diameter, ``N`` pulses per revolution). A wheel that spins (空转, slip)
or locks (打滑, slide) makes the tacho lie: the tacho's acceleration jumps above ``a_max`` (slip) or below ``a_min``
(slide), both configurable from the vehicle's performance and the gradients. While it lies, the odometer goes back
to the speed before the episode and integrates a compensated acceleration instead (the accelerometer, less the
gradient term, else the last plausible acceleration), until the wheel agrees again. Balises and RFID tags give the
absolute position (``correct``); so does a track section in the direction of travel going from locked to occupied
(``section_transition``). An error made in the last section before a stopping point cannot be corrected any more,
and a slide there leaves the measured position short of the true one: the dangerous side.

``research/sliprun.py`` scripts a run with a slip while accelerating and a slide while braking, the test runs of
Liu Bin et al.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass
from typing import Literal, NamedTuple

G = 9.81
State = Literal["normal", "slip", "slide"]


@dataclass(frozen=True)
class Correction:
    t: float
    kind: str  # "balise" (balise or RFID tag) or "section" (section ahead locked -> occupied)
    before_m: float
    after_m: float


class _Sample(NamedTuple):
    t: float
    wheel_ms: float  # tacho speed over the window
    est_ms: float  # estimated speed
    position_m: float
    accel_ms2: float  # tacho acceleration


class Odometer:
    """Tacho odometry with slip/slide detection and compensation.

    ``wheel_diameter_m`` and ``pulses_per_rev`` as for a shunting locomotive; ``a_max`` / ``a_min`` (m/s2) are the
    slip and slide thresholds (Liu Bin et al. leave them configurable: above what the locomotive can do on the steepest
    gradient); ``window_s`` the time over which the tacho speed ``pi d n / (N t)`` and its acceleration are taken;
    an episode ends when the tacho agrees with the estimate for ``recover_s`` (within ``recover_tol_ms`` plus
    ``drift_ms2`` per second of compensation, for the accelerometer's drift), or after ``max_compensation_s`` (n_max
    in Liu Bin et al.). ``compensate=False`` gives the plain odometer that trusts the wheel.
    ``position_m`` is the running position along the movement's path, increasing as the locomotive runs.
    """

    def __init__(self, wheel_diameter_m: float = 1.05, pulses_per_rev: int = 200, a_max: float = 0.6,
                 a_min: float = -1.2, *, window_s: float = 0.5, recover_s: float = 0.5, recover_tol_ms: float = 0.1,
                 drift_ms2: float = 0.05, max_compensation_s: float = 10.0, compensate: bool = True,
                 position_m: float = 0.0) -> None:
        if wheel_diameter_m <= 0 or pulses_per_rev <= 0 or a_max <= 0 or a_min >= 0:
            raise ValueError("need d > 0, N > 0, a_max > 0 and a_min < 0")
        self.wheel_diameter_m = wheel_diameter_m
        self.pulses_per_rev = pulses_per_rev
        self.a_max, self.a_min = a_max, a_min
        self.window_s, self.recover_s, self.recover_tol_ms = window_s, recover_s, recover_tol_ms
        self.drift_ms2 = drift_ms2
        self.max_compensation_s = max_compensation_s
        self.compensate = compensate
        self.t = 0.0
        self._position = position_m
        self._speed = 0.0  # the speed given out
        self._est = 0.0  # speed estimate now (the window speed lags by half a window; given out when compensating)
        self._hold = 0.0  # plausible acceleration before the episode, used without an accelerometer
        self._state: State = "normal"
        self._win_dt: deque[float] = deque()  # the sampling intervals over the window
        self._win_n: deque[int] = deque()  # and the pulses in each
        self._hist: deque[_Sample] = deque()
        self._carry = 0.0  # fraction of a pulse (update())
        self._episode_t = 0.0
        self._agree_t = 0.0
        self.episodes: list[tuple[float, State]] = []  # (start time, kind)
        self.corrections: list[Correction] = []

    # ---- readings -------------------------------------------------------------------------------------------
    @property
    def metres_per_pulse(self) -> float:
        return math.pi * self.wheel_diameter_m / self.pulses_per_rev

    @property
    def position_m(self) -> float:
        return self._position

    @property
    def speed_ms(self) -> float:
        return self._speed

    @property
    def slipping(self) -> bool:
        return self._state == "slip"

    @property
    def sliding(self) -> bool:
        return self._state == "slide"

    def error_m(self, true_position_m: float) -> float:
        """Measured minus true position; negative means the locomotive is further on than it believes."""
        return self._position - true_position_m

    # ---- inputs ---------------------------------------------------------------------------------------------
    def update(self, dt: float, wheel_speed_ms: float, accel_ms2: float | None = None,
               gradient_permille: float = 0.0) -> None:
        """One sampling interval of a wheel turning at ``wheel_speed_ms``: the tacho gives whole pulses."""
        self._carry += max(wheel_speed_ms, 0.0) * dt / self.metres_per_pulse
        count = int(self._carry)
        self._carry -= count
        self.pulses(count, dt, accel_ms2, gradient_permille)

    def pulses(self, count: int, dt: float, accel_ms2: float | None = None, gradient_permille: float = 0.0) -> None:
        """``count`` tacho pulses in ``dt`` seconds; ``accel_ms2`` the accelerometer (which also feels the gradient,
        ``gradient_permille`` rising in the direction of travel: from the line data, or the steepest as a bound)."""
        if dt <= 0 or count < 0:
            raise ValueError("need dt > 0 and count >= 0")
        t = self.t = self.t + dt
        window = self.window_s
        win_dt, win_n = self._win_dt, self._win_n
        win_dt.append(dt)
        win_n.append(count)
        while len(win_dt) > 1 and sum(win_dt) - win_dt[0] >= window - 1e-9:
            win_dt.popleft()
            win_n.popleft()
        span = sum(win_dt)
        wheel = math.pi * self.wheel_diameter_m * sum(win_n) / (self.pulses_per_rev * span)
        hist = self._hist
        ref = None
        since = t - window + 1e-9
        for h in reversed(hist):  # the newest sample a window ago
            if h.t <= since:
                ref = h
                break
        a_wheel = (wheel - ref.wheel_ms) / (t - ref.t) if ref is not None else 0.0
        a_comp = self._hold if accel_ms2 is None else accel_ms2 - G * gradient_permille / 1000.0
        mpp = self.metres_per_pulse
        step = count * mpp
        state = self._state
        if state == "normal":
            kind: State | None = "slip" if a_wheel > self.a_max else "slide" if a_wheel < self.a_min else None
            if kind is None or ref is None:
                self._est = wheel + self._hold * window / 2
                self._hold = min(max(a_wheel, self.a_min), self.a_max)
                self._position += step
            else:
                self._begin(kind, hist[0], accel_ms2, gradient_permille, step)
        else:
            before = self._est
            est = max(0.0, before + a_comp * dt)
            # a spinning wheel runs faster than the locomotive (an upper bound), a locked one slower (a lower bound)
            est = min(est, (count + 1) * mpp / dt) if state == "slip" else max(est, (count - 1) * mpp / dt)
            self._est = est
            self._position += (before + est) / 2 * dt if self.compensate else step
            self._episode_t += dt
            lagged = est - a_comp * window / 2  # what the window speed should read
            tol = self.recover_tol_ms + self.drift_ms2 * self._episode_t
            agree = abs(wheel - lagged) <= tol or (wheel == 0.0 and est == 0.0)
            self._agree_t = self._agree_t + dt if agree else 0.0
            if self._agree_t >= self.recover_s or self._episode_t >= self.max_compensation_s:
                self._state = "normal"
        self._speed = self._est if self.compensate and self._state != "normal" else wheel
        hist.append(_Sample(t, wheel, self._est, self._position, a_wheel))
        forget = t - 2 * window + 1e-9
        while len(hist) > 1 and hist[1].t <= forget:
            hist.popleft()

    def _begin(self, kind: State, ref: _Sample, accel_ms2: float | None, gradient_permille: float,
               step: float) -> None:
        """An episode starts: go back to the sample before the tacho went wrong and integrate from there."""
        self._state = kind
        self._episode_t = self._agree_t = 0.0
        self.episodes.append((self.t, kind))
        before = [h.accel_ms2 for h in self._hist if h.t <= self.t - self.window_s + 1e-9] or [ref.accel_ms2]
        self._hold = min(max(sum(before) / len(before), self.a_min), self.a_max)  # the acceleration before it
        a = self._hold if accel_ms2 is None else accel_ms2 - G * gradient_permille / 1000.0
        span = self.t - ref.t
        self._est = max(0.0, ref.est_ms + a * span)
        if self.compensate:
            self._position = ref.position_m + (ref.est_ms + self._est) / 2 * span
        else:
            self._position += step

    # ---- absolute corrections -------------------------------------------------------------------------------
    def correct(self, position_m: float, kind: str = "balise", *, since_s: float = 0.0) -> float:
        """A balise or RFID tag at ``position_m`` was passed ``since_s`` ago (the reader's time stamp, or its fixed
        response delay): take it as the position. Returns the correction (m)."""
        new = position_m + self._speed * since_s
        self.corrections.append(Correction(self.t, kind, self._position, new))
        delta = new - self._position
        self._position = new
        for i, s in enumerate(self._hist):
            self._hist[i] = s._replace(position_m=s.position_m + delta)
        return delta

    def section_transition(self, position_m: float, *, since_s: float = 0.0) -> float:
        """The section in the direction of travel went from locked to occupied: the leading wheelset is at its
        joint ``position_m`` (the running position of that joint on the movement's path)."""
        return self.correct(position_m, "section", since_s=since_s)


