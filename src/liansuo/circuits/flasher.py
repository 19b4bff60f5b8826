"""USU flasher (黄闪黄闪光电路): the classic resistor-capacitor relay flasher and the improved electronic one.

When a home signal shows USU, the top yellow lamp flashes 30-40 times a minute, nominally 35 (period 1.714 s,
50 % duty). The interlocking may show USU only while the flasher proves itself healthy (flash-check relay SNJJ up);
otherwise it falls back to UU. Chen Xinmei 2023 (docs/references.md) describes both forms modelled here.

Classic circuit (``RelayFlasher``), an equivalent model of the paper's circuit with its figures (24 V, JWXC-1700
relays: pick-up 16.8 V, drop 3.4 V, two 850 ohm coils; R3 = 100 ohm in the pick-up coil feed):

* dark phase, SNJ down (slow pick-up, 缓吸): coil 1-2 sees ``V12 = U*Rc/(Rc+R3)``; the opposing coil 3-4 carries the
  charging current of capacitor C from the supply, so its voltage ``U - Vc`` decays with ``tau = Rc*C``. SNJ picks
  up when ``V12 - (U - Vc)`` reaches the pick-up value. A larger R3 lowers V12 and lengthens the dark phase.
* lit phase, SNJ up (slow release, 缓放): the supply is cut and C holds SNJ up, discharging through the coil pair
  (1700 ohm) in parallel with R1, until the coil voltage falls to the drop value. A larger R1 bleeds less and
  lengthens the lit phase.
* SNJ's second contact group shorts a series resistor in the lamp circuit: bright while SNJ is up, dim (current
  still above the DJ release value) while it is down. SNJJ is a slow-release relay picked by XSJ and kept up by
  SNJ's movement; it drops when SNJ stops moving.

Known failure: a bad contact in SNJ's second group leaves the lamp dim (dark to the eye) while SNJ keeps flashing
and SNJJ stays up: the classic circuit does not notice, the signal silently shows UU (or a single yellow).

The electronic flasher (``ElectronicFlasher``) is fixed at 35/min, 50 % duty, and checks that the lamp current
pulsates; when it stops pulsating it drops SNJ and with it SNJJ, so the interlocking downgrades USU to UU.

Time is passed in (``step(dt)``); nothing here reads a clock.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field, replace

BRIGHT_MA = 180.0  # lamp current in the lit phase (modelled value, above DJ pick-up 140 mA)
DIM_MA = 70.0  # lamp current in the dark phase (not fully off; between DJ release 40 mA and pick-up 140 mA)


class _FlasherOutputs:
    """What both flashers show the rest of the simulator; each defines ``phase_on`` and its relay states."""

    energised: bool
    snjj_up: bool
    bad_contact: bool
    bright_mA: float
    dim_mA: float

    @property
    def phase_on(self) -> bool:
        raise NotImplementedError

    @property
    def lamp_lit(self) -> bool:
        """What the flashing lamp actually shows now: dark in the dim phase and whenever the contact is bad."""
        return self.phase_on and not self.bad_contact

    @property
    def lamp_current_mA(self) -> float:
        if not self.energised:
            return 0.0
        return self.bright_mA if self.lamp_lit else self.dim_mA

    @property
    def healthy(self) -> bool:
        """Flash check (SNJJ up) as the interlocking reads it."""
        return self.energised and self.snjj_up


@dataclass
class RelayFlasher(_FlasherOutputs):
    """Classic RC + relay flasher: SNJ (flasher relay) with capacitor C, resistors R1/R3, and SNJJ (check)."""

    supply_V: float = 24.0
    coil_ohm: float = 850.0  # each of the two JWXC-1700 coils
    pickup_V: float = 16.8
    drop_V: float = 3.4
    capacitance_F: float = 680e-6
    r1_ohm: float = 1270.0  # bleed across the coil pair in the lit phase: sets the lit time
    r3_ohm: float = 100.0  # in the pick-up coil feed: sets the dark time
    snjj_hold_s: float = 1.5  # SNJJ slow release: drops when SNJ has not moved for this long
    bright_mA: float = BRIGHT_MA
    dim_mA: float = DIM_MA
    # faults
    bad_contact: bool = False  # SNJ second contact group open: the lamp stays dim while SNJ keeps flashing
    snj_stuck: bool = False  # SNJ armature stuck: it stops moving (SNJJ notices)
    # state
    energised: bool = False  # XSJ up: USU commanded
    capacitor_V: float = 0.0
    snj_up: bool = False
    snjj_up: bool = False
    time_s: float = 0.0
    last_move_s: float = 0.0
    transitions: int = field(default=0, repr=False)

    # --- component figures ------------------------------------------------------------------------------------
    @property
    def pick_coil_V(self) -> float:
        """Voltage on coil 1-2 through R3 in the dark phase."""
        return self.supply_V * self.coil_ohm / (self.coil_ohm + self.r3_ohm)

    @property
    def high_threshold_V(self) -> float:
        """Capacitor voltage at which SNJ picks up (opposing coil voltage down to V12 - pick-up)."""
        return self.supply_V - (self.pick_coil_V - self.pickup_V)

    @property
    def low_threshold_V(self) -> float:
        """Capacitor voltage at which SNJ drops (the coil pair sits directly across C)."""
        return self.drop_V

    @property
    def charge_tau_s(self) -> float:
        return self.coil_ohm * self.capacitance_F

    @property
    def discharge_tau_s(self) -> float:
        pair = 2.0 * self.coil_ohm
        bleed = pair * self.r1_ohm / (pair + self.r1_ohm) if self.r1_ohm > 0 else 0.0
        return bleed * self.capacitance_F

    def _dark_time(self, from_V: float) -> float:
        headroom = self.supply_V - self.high_threshold_V  # = V12 - pick-up
        if headroom <= 0.0 or self.high_threshold_V <= self.low_threshold_V:
            return math.inf  # the pick-up coil alone cannot pick SNJ up: it never flashes
        if from_V >= self.high_threshold_V:
            return 0.0
        return self.charge_tau_s * math.log((self.supply_V - from_V) / headroom)

    def _lit_time(self, from_V: float) -> float:
        if from_V <= self.low_threshold_V or self.discharge_tau_s <= 0.0:
            return 0.0
        return self.discharge_tau_s * math.log(from_V / self.low_threshold_V)

    def dark_time_s(self) -> float:
        """Steady-state dark phase (SNJ pick-up delay)."""
        return self._dark_time(self.low_threshold_V)

    def lit_time_s(self) -> float:
        """Steady-state lit phase (SNJ release delay)."""
        return self._lit_time(self.high_threshold_V)

    def period_s(self) -> float:
        return self.dark_time_s() + self.lit_time_s()

    def rate_per_min(self) -> float:
        """Flashes per minute from the component values (0 when it cannot flash)."""
        period = self.period_s()
        return 0.0 if not math.isfinite(period) or period <= 0.0 else 60.0 / period

    def duty(self) -> float:
        """Fraction of the period the lamp is lit."""
        period = self.period_s()
        return 0.0 if not math.isfinite(period) or period <= 0.0 else self.lit_time_s() / period

    def trim(self, rate_per_min: float = 35.0, duty: float = 0.5) -> bool:
        """Re-adjust R3 (dark time) then R1 (lit time), as a maintainer does after changing the RC box.
        Returns False when the resistors cannot reach the target (e.g. a capacitor far too large)."""
        period = 60.0 / rate_per_min
        target_dark, target_lit = period * (1.0 - duty), period * duty
        r3_max = self.coil_ohm * (self.supply_V / self.pickup_V - 1.0)  # beyond this SNJ can never pick up
        self.r3_ohm = _bisect(lambda r: replace(self, r3_ohm=r).dark_time_s() - target_dark, 0.0, r3_max * 0.999)
        self.r1_ohm = _bisect(lambda r: replace(self, r1_ohm=r).lit_time_s() - target_lit, 1.0, 1e6)
        return math.isclose(self.dark_time_s(), target_dark, rel_tol=5e-3) and math.isclose(
            self.lit_time_s(), target_lit, rel_tol=5e-3)

    # --- running ------------------------------------------------------------------------------------------------
    def energise(self, on: bool) -> None:
        """XSJ picks (USU commanded) or drops. Dropping resets the circuit: SNJ, SNJJ down, C discharged."""
        if on and not self.energised:
            self.energised = True
            self.snjj_up = True  # picked through XSJ, then kept up by SNJ's movement
            self.last_move_s = self.time_s
        elif not on and self.energised:
            self.energised = False
            self.snj_up = False
            self.snjj_up = False
            self.capacitor_V = 0.0

    def step(self, dt: float) -> None:
        """Advance ``dt`` seconds, switching SNJ exactly at its threshold crossings."""
        if dt < 0.0:
            raise ValueError("dt must be >= 0")
        end = self.time_s + dt
        while self.energised and not self.snj_stuck and self.time_s < end:
            remaining = end - self.time_s
            if self.snj_up:
                to_switch = self._lit_time(self.capacitor_V)
                span = min(to_switch, remaining)
                self.capacitor_V *= math.exp(-span / self.discharge_tau_s) if self.discharge_tau_s > 0 else 0.0
            else:
                to_switch = self._dark_time(self.capacitor_V)
                span = min(to_switch, remaining)
                self.capacitor_V = self.supply_V - (self.supply_V - self.capacitor_V) * math.exp(
                    -span / self.charge_tau_s)
            self.time_s += span
            if to_switch <= remaining:
                self.snj_up = not self.snj_up
                self.capacitor_V = self.high_threshold_V if self.snj_up else self.low_threshold_V
                self.last_move_s = self.time_s
                self.transitions += 1
        self.time_s = end
        if self.energised and self.time_s - self.last_move_s > self.snjj_hold_s:
            self.snjj_up = False

    # --- what the rest of the simulator reads -----------------------------------------------------------------
    @property
    def phase_on(self) -> bool:
        """The flasher's lit phase (SNJ up): what a healthy lamp would show now."""
        return self.energised and self.snj_up

    def repair(self) -> None:
        self.bad_contact = False
        self.snj_stuck = False


@dataclass
class ElectronicFlasher(_FlasherOutputs):
    """Improved electronic flasher: fixed rate and 50 % duty, proves the pulsating lamp current."""

    rate: float = 35.0  # flashes per minute, set by R9/C6 at the factory and not adjusted in the field
    duty_fraction: float = 0.5  # PWM controller at its maximum duty
    detect_periods: float = 1.25  # SNJ drops when no current pulse was seen for this many periods
    bright_mA: float = BRIGHT_MA
    dim_mA: float = DIM_MA
    pulse_threshold_mA: float = 140.0  # a pulse is the lamp current rising to at least this
    # faults
    bad_contact: bool = False  # the lamp output no longer passes the bright current
    # state
    energised: bool = False
    snj_up: bool = False
    snjj_up: bool = False
    time_s: float = 0.0
    started_s: float = 0.0
    last_pulse_s: float = 0.0

    @property
    def period(self) -> float:
        return 60.0 / self.rate

    def rate_per_min(self) -> float:
        return self.rate

    def duty(self) -> float:
        return self.duty_fraction

    def energise(self, on: bool) -> None:
        """XSJ picks or drops. At power-on SNJJ is picked at once and SNJ follows the pulsation check."""
        if on and not self.energised:
            self.energised = True
            self.snj_up = True
            self.snjj_up = True
            self.started_s = self.time_s
            self.last_pulse_s = self.time_s
        elif not on and self.energised:
            self.energised = False
            self.snj_up = False
            self.snjj_up = False

    def _pulsing(self) -> bool:
        return self.bright_mA >= self.pulse_threshold_mA and not self.bad_contact

    def step(self, dt: float) -> None:
        if dt < 0.0:
            raise ValueError("dt must be >= 0")
        self.time_s += dt
        if not self.energised:
            return
        if self._pulsing():
            cycles = math.floor((self.time_s - self.started_s) / self.period)
            self.last_pulse_s = max(self.last_pulse_s, self.started_s + cycles * self.period)
        if self.snj_up and self.time_s - self.last_pulse_s > self.detect_periods * self.period:
            self.snj_up = False  # no pulsation: SNJ drops and takes SNJJ with it, until re-energised
            self.snjj_up = False

    @property
    def phase_on(self) -> bool:
        if not self.energised or not self.snj_up:
            return False
        into = (self.time_s - self.started_s) % self.period
        return into < self.duty_fraction * self.period

    def repair(self) -> None:
        self.bad_contact = False


def _bisect(f: Callable[[float], float], lo: float, hi: float, iterations: int = 60) -> float:
    """Root of an increasing function ``f`` on [lo, hi] (clamped to the bounds)."""
    f_lo, f_hi = f(lo), f(hi)
    if f_lo >= 0.0:
        return lo
    if f_hi <= 0.0:
        return hi
    for _ in range(iterations):
        mid = (lo + hi) / 2.0
        if f(mid) < 0.0:
            lo = mid
        else:
            hi = mid
    return (lo + hi) / 2.0
