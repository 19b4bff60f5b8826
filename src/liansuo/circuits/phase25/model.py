"""97-type 25 Hz phase-sensitive track circuit (97型25Hz相敏轨道电路) as a small AC circuit model.

The section is a uniform two-rail line of ``length_m`` between the feed end (送电端, x = 0) and the relay end
(受电端, x = length_m), solved exactly with the hyperbolic (telegrapher) solution in ABCD form. Everything is
referred to the rails:

    feed:  supply 220 V 25 Hz -> feed track transformer BG25 (tap ``feed_tap_V``) -> limiting resistor Rx
           -> choke transformer BE25 (1:n) -> rails
    line:  rail impedance z (ohm/km) in series, ballast conductance 1/R_ballast (S*km) in parallel,
           wheelset shunts (and a failed insulation) as resistors across the rails at their positions
    relay: rails -> choke BE25 (n:1) -> relay transformer BG25 (1:15) -> JRJC track coil with its HF protective box

The two-element relay JRJC (二元二位继电器) has a local coil fed at 110 V 25 Hz leading the track supply by a fixed
angle. Its vane torque is proportional to the component of the track-coil voltage that lags the local voltage by
90 degrees (``effective_V``): the relay picks up when that component reaches ``pickup_V`` AND the phase error is
inside ``phase_window_deg``; once up it holds while the component stays at or above ``drop_V``. A voltage of the
opposite phase (neighbour's supply through a failed insulated joint, rail polarity alternating) gives negative
torque and can never pick it up.

Time does not appear: the circuit is quasi-static at 25 Hz. Hysteresis needs the previous relay state, passed in.
Figures and their sources are in docs/track-circuits-25hz.md.

Range: the model vouches for sections up to ``MAX_LENGTH_M``. Longer ones are refused unless asked for
(``beyond_range=True``): in dry ballast a standard shunt no longer drops their relay. Ballast resistances <= 0 or
NaN and positions that are not finite numbers raise ``ValueError`` (:mod:`.physical`).
"""

from __future__ import annotations

import cmath
import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass, replace
from functools import lru_cache

from liansuo.circuits.physical import check_ballast, check_position, check_shunts

# one ABCD (transmission) matrix: (A, B, C, D) with V1 = A V2 + B I2, I1 = C V2 + D I2
_Abcd = tuple[complex, complex, complex, complex]
_IDENTITY: _Abcd = (1 + 0j, 0j, 0j, 1 + 0j)
_MIN_SHUNT_OHM = 1e-6
# The longest section the model vouches for (the design rule's 1500 m, rules/china/design.yaml): with the tap a
# maintainer sets, a 0.06 ohm shunt anywhere leaves at most 7.4 V on the track coil even in dry (infinite) ballast
# (6.9 V at 1500 m, 7.4 V at about 1650 m). Past it dry ballast holds the relay up under a train: 8.8 V at 2000 m,
# 11.3 V at 2500 m, above the 8.6 V drop level (docs/track-circuits-25hz.md).
MAX_LENGTH_M = 1500.0


@dataclass(frozen=True)
class Phase25HzParams:
    """Physical parameters of one section. Units are in the names; lengths in the line model are km."""

    frequency_Hz: float = 25.0
    # 25 Hz power panel (电源屏): track supply and local supply
    supply_V: float = 220.0  # actual track supply; the tap voltage below is at the nominal supply
    nominal_supply_V: float = 220.0
    feed_phase_deg: float = 0.0  # track supply phase vs the panel reference (180 = reversed feed wiring)
    local_V: float = 110.0  # torque scales with the local voltage; 0 = local supply lost
    nominal_local_V: float = 110.0
    local_lead_deg: float = 90.0  # local supply phase vs the panel reference: leads the track supply by 90
    # feed end: track transformer tap, limiting resistor, choke transformer
    feed_tap_V: float = 2.0  # BG25 secondary at nominal supply; set per section by adjusted_params()
    limiting_resistor_ohm: float = 4.4  # Rx on the transformer secondary (R1-4.4/440)
    feed_choke_ratio: float = 3.0  # BE25 choke, equipment side : rail side (1.0 = no choke, non-electrified)
    # the line (textbook-typical 25 Hz values, verify)
    rail_resistance_ohm_km: float = 0.35  # two-rail loop, 60 kg/m rails with bonded joints
    rail_reactance_ohm_km: float = 0.30  # two-rail loop at 25 Hz (about 1.9 mH/km)
    ballast_ohm_km: float = 0.6  # design minimum for station tracks, crushed stone, AC track circuits
    # relay end: choke, relay transformer, relay track coil with HF protective box (equipment side)
    relay_choke_ratio: float = 3.0
    relay_transformer_ratio: float = 15.0  # BG25 used as relay (中继) transformer, 1:15
    relay_load_ohm: float = 800.0  # |Z| of track coil with protective box (modelled value)
    relay_load_angle_deg: float = 25.0
    # JRJC relay and maintenance figures (维规 TG/XH 101-2015, docs/references.md; pick-up/drop textbook-typical,
    # verify)
    pickup_V: float = 15.0  # track-coil voltage at ideal phase that picks the relay up
    drop_V: float = 8.6  # below this in-phase component the relay drops (hysteresis)
    ideal_lag_deg: float = 90.0  # track voltage lags local voltage by this angle for maximum torque
    phase_window_deg: float = 30.0  # pick-up only within +-this of the ideal angle
    adjustment_min_V: float = 18.0
    adjustment_typical_V: tuple[float, float] = (15.0, 26.0)
    residual_max_V: float = 7.4
    standard_shunt_ohm: float = 0.06
    insulation_short_ohm: float = 0.01  # a failed switch-machine / joint insulation bridging the rails

    def __post_init__(self) -> None:
        check_ballast("ballast_ohm_km", self.ballast_ohm_km)

    @property
    def feed_transformer_ratio(self) -> float:
        """Turns ratio of the feed track transformer (primary : secondary) for the chosen tap."""
        return self.nominal_supply_V / self.feed_tap_V

    @property
    def relay_step_up(self) -> float:
        """Voltage ratio from the rails to the track coil (choke times relay transformer)."""
        return self.relay_choke_ratio * self.relay_transformer_ratio

    @property
    def rail_impedance_ohm_km(self) -> complex:
        return complex(self.rail_resistance_ohm_km, self.rail_reactance_ohm_km)


@dataclass(frozen=True)
class Phase25HzFaults:
    """Trackside faults of one section. A poor shunt is not a fault here: pass a high shunt resistance."""

    broken_rail_at_m: float | None = None  # open rail: no loop, the relay drops wherever the break is
    ballast_ohm_km: float | None = None  # low (wet, dirty) ballast overriding the design value
    insulation_short: bool = False  # failed insulation bridging the rails (red band)
    insulation_short_at_m: float | None = None  # where; None = at the relay end
    feed_lost: bool = False  # feed fuse blown / supply lost
    joint_failure: bool = False  # the insulated joint at the relay end failed: the neighbour's feed leaks in
    neighbour_phase_deg: float = 180.0  # neighbour feed phase vs ours: 180 with rail polarity alternating
    joint_leak_ohm: float = 0.1  # resistance of the leak path through the failed joint (rail side)

    def __post_init__(self) -> None:
        if self.ballast_ohm_km is not None:
            check_ballast("ballast_ohm_km", self.ballast_ohm_km)
        if self.broken_rail_at_m is not None:
            check_position("broken_rail_at_m", self.broken_rail_at_m)
        if self.insulation_short_at_m is not None:
            check_position("insulation_short_at_m", self.insulation_short_at_m)


@dataclass(frozen=True)
class TrackCircuitState:
    """What the relay end sees: the track-coil voltage phasor and the JRJC pick-up rule."""

    voltage_V: float  # rms track-coil voltage
    phase_deg: float  # track-coil voltage phase minus local-coil phase, (-180, 180]; ideal -ideal_lag_deg
    phase_error_deg: float  # deviation from the ideal lag, (-180, 180]
    effective_V: float  # component in the ideal (torque) phase, scaled by local/nominal local voltage; < 0 = reverse
    pickup_V: float
    drop_V: float
    phase_window_deg: float

    @property
    def relay_up(self) -> bool:
        """Pick-up rule from the released state: enough voltage AND phase inside the window."""
        return self.effective_V >= self.pickup_V and abs(self.phase_error_deg) <= self.phase_window_deg

    def relay_up_after(self, previous_up: bool) -> bool:
        """Relay state given its previous state: an up relay holds down to ``drop_V`` (hysteresis)."""
        if previous_up:
            return self.effective_V >= self.drop_V
        return self.relay_up


def _wrap_deg(angle: float) -> float:
    """Wrap an angle to (-180, 180]."""
    wrapped = math.fmod(angle, 360.0)
    if wrapped <= -180.0:
        wrapped += 360.0
    elif wrapped > 180.0:
        wrapped -= 360.0
    return wrapped


def _mul(m: _Abcd, n: _Abcd) -> _Abcd:
    a, b, c, d = m
    e, f, g, h = n
    return (a * e + b * g, a * f + b * h, c * e + d * g, c * f + d * h)


def _line(length_km: float, z: complex, g: float) -> _Abcd:
    """Exact ABCD matrix of a uniform line with series z (ohm/km) and shunt conductance g (S/km)."""
    if length_km <= 0.0:
        return _IDENTITY
    if g <= 0.0:  # no leakage (infinite ballast resistance): a plain series impedance
        return (1 + 0j, z * length_km, 0j, 1 + 0j)
    gamma = cmath.sqrt(z * g)
    zc = cmath.sqrt(z / g)
    ch = cmath.cosh(gamma * length_km)
    sh = cmath.sinh(gamma * length_km)
    return (ch, zc * sh, sh / zc, ch)


def _shunt(resistance_ohm: float) -> _Abcd:
    return (1 + 0j, 0j, complex(1.0 / max(resistance_ohm, _MIN_SHUNT_OHM)), 1 + 0j)


class Phase25HzCircuit:
    """One 25 Hz phase-sensitive section of ``length_m``; ``params`` None = adjusted as a maintainer would.

    A section longer than ``MAX_LENGTH_M`` is refused (``ValueError``) unless ``beyond_range`` is true, as for a
    study of the model's limits: there a standard shunt does not drop the relay in dry ballast.
    """

    def __init__(self, length_m: float, params: Phase25HzParams | None = None, *, beyond_range: bool = False
                 ) -> None:
        if not (math.isfinite(length_m) and length_m > 0.0):
            raise ValueError(f"length_m must be a positive number of metres, got {length_m!r}")
        if length_m > MAX_LENGTH_M and not beyond_range:
            raise ValueError(f"length_m {length_m:g} m is past the 25 Hz model's range ({MAX_LENGTH_M:g} m): in dry "
                             "ballast a standard shunt would not drop the relay; split the section, or pass "
                             "beyond_range=True to study the model there")
        self.length_m = float(length_m)
        self.params = params if params is not None else adjusted_params(length_m)

    # --- the circuit ------------------------------------------------------------------------------------------
    def relay_phasor(self, shunts: Sequence[tuple[float, float]] = (),
                     faults: Phase25HzFaults | None = None) -> complex:
        """Track-coil voltage phasor (V rms) with the track supply at phase 0, before the local reference."""
        p = self.params
        f = faults or Phase25HzFaults()
        n_feed = p.feed_choke_ratio
        feed_phase = math.radians(p.feed_phase_deg)
        e_magnitude = p.feed_tap_V * p.supply_V / p.nominal_supply_V / n_feed  # rail-side EMF
        zs = complex(p.limiting_resistor_ohm / n_feed**2)  # rail-side source impedance
        zl = cmath.rect(p.relay_load_ohm, math.radians(p.relay_load_angle_deg)) / p.relay_step_up**2
        # nodal equation at the relay-end rails: sum of (source current, admittance) pairs
        admittance = 1 / zl
        current = 0j
        broken = f.broken_rail_at_m is not None and 0.0 <= f.broken_rail_at_m <= self.length_m
        if not broken:  # an open rail leaves no loop: nothing reaches the relay end from our feed
            a, b, c, d = self._chain(shunts, f)
            denom = a + zs * c
            e_rail = 0j if f.feed_lost else cmath.rect(e_magnitude, feed_phase)
            z_th = (b + zs * d) / denom or complex(1e-12)  # Thevenin impedance of feed + line at the relay end
            admittance += 1 / z_th
            current += (e_rail / denom) / z_th
        if f.joint_failure:
            # the neighbour's feed end adjoins our relay end; its supply arrives through the failed joint
            z_n = zs + f.joint_leak_ohm
            admittance += 1 / z_n
            current += cmath.rect(e_magnitude, feed_phase + math.radians(f.neighbour_phase_deg)) / z_n
        return current / admittance * p.relay_step_up

    def _chain(self, shunts: Sequence[tuple[float, float]], f: Phase25HzFaults) -> _Abcd:
        p = self.params
        z = p.rail_impedance_ohm_km
        ballast = f.ballast_ohm_km if f.ballast_ohm_km is not None else p.ballast_ohm_km
        g = 0.0 if math.isinf(ballast) else 1.0 / ballast
        elements: list[tuple[float, float]] = [
            (min(max(x, 0.0), self.length_m), r) for x, r in shunts if -1e-9 <= x <= self.length_m + 1e-9
        ]
        if f.insulation_short:
            at = self.length_m if f.insulation_short_at_m is None else f.insulation_short_at_m
            elements.append((min(max(at, 0.0), self.length_m), p.insulation_short_ohm))
        elements.sort()
        m = _IDENTITY
        pos = 0.0
        for x, r in elements:
            m = _mul(m, _line((x - pos) / 1000.0, z, g))
            m = _mul(m, _shunt(r))
            pos = x
        return _mul(m, _line((self.length_m - pos) / 1000.0, z, g))

    def evaluate(self, shunts: Sequence[tuple[float, float]] = (), faults: Phase25HzFaults | None = None
                 ) -> TrackCircuitState:
        """Relay-end state for wheelset shunts ``(distance_from_feed_end_m, resistance_ohm)`` and faults. A shunt
        position that is not a finite number raises ``ValueError``: such a wheelset lies nowhere."""
        if not shunts and (faults is None or faults == _HEALTHY):
            return _adjustment(self.length_m, self.params)  # the same for every circuit of this length and tap
        check_shunts(shunts)
        return self._evaluate(shunts, faults)

    def _evaluate(self, shunts: Sequence[tuple[float, float]], faults: Phase25HzFaults | None) -> TrackCircuitState:
        p = self.params
        v = self.relay_phasor(shunts, faults)
        magnitude = abs(v)
        phase = _wrap_deg(math.degrees(cmath.phase(v)) - p.local_lead_deg) if magnitude > 0 else -p.ideal_lag_deg
        error = _wrap_deg(phase + p.ideal_lag_deg)
        return TrackCircuitState(
            voltage_V=magnitude,
            phase_deg=phase,
            phase_error_deg=error,
            effective_V=magnitude * math.cos(math.radians(error)) * p.local_V / p.nominal_local_V,
            pickup_V=p.pickup_V,
            drop_V=p.drop_V,
            phase_window_deg=p.phase_window_deg,
        )

    # --- what a maintainer measures ----------------------------------------------------------------------------
    def adjustment(self, faults: Phase25HzFaults | None = None) -> TrackCircuitState:
        """Adjustment state (调整状态): no train."""
        return self.evaluate((), faults)

    def residual_profile(self, positions_m: Iterable[float], shunt_ohm: float | None = None,
                         faults: Phase25HzFaults | None = None) -> list[float]:
        """Track-coil voltage with one shunt (default the 0.06 ohm standard shunt) at each position."""
        r = self.params.standard_shunt_ohm if shunt_ohm is None else shunt_ohm
        return [self.evaluate([(x, r)], faults).voltage_V for x in positions_m]

    def max_residual_V(self, shunt_ohm: float | None = None, points: int = 61,
                       faults: Phase25HzFaults | None = None) -> float:
        """Worst residual voltage (分路残压) over ``points`` evenly spaced shunt positions, both ends included."""
        step = self.length_m / (points - 1)
        return max(self.residual_profile((i * step for i in range(points)), shunt_ohm, faults))

    def poor_shunt_limit_ohm(self, points: int = 31, faults: Phase25HzFaults | None = None) -> float:
        """Shunt resistance above which a wheelset at the worst position no longer drops an up relay."""
        step = self.length_m / (points - 1)
        positions = [i * step for i in range(points)]

        def holds(r: float) -> bool:
            return any(self.evaluate([(x, r)], faults).effective_V >= self.params.drop_V for x in positions)

        lo, hi = 0.0, 0.06
        while not holds(hi):
            lo, hi = hi, hi * 2.0
            if hi > 1e4:
                return math.inf
        for _ in range(40):
            mid = (lo + hi) / 2.0
            if holds(mid):
                hi = mid
            else:
                lo = mid
        return hi


_HEALTHY = Phase25HzFaults()


@lru_cache(maxsize=4096)
def _adjustment(length_m: float, params: Phase25HzParams) -> TrackCircuitState:
    """The adjustment state (no train, no fault) of a circuit: pure in its length and parameters, so worked out once
    for every simulation of a station (verify builds hundreds)."""
    return Phase25HzCircuit(length_m, params, beyond_range=True)._evaluate((), None)


TAP_STEP_V = 0.05  # feed transformer tap resolution of the model (secondary volts at nominal supply)


@lru_cache(maxsize=4096)
def adjusted_params(length_m: float, base: Phase25HzParams | None = None, target_V: float = 20.0
                    ) -> Phase25HzParams:
    """Pick the feed tap as a maintainer adjusts a section: the lowest tap giving at least ``target_V`` on the
    track coil at the base's ballast (the design minimum by default). 20 V keeps >= 18 V with the supply 10 % low.
    """
    p = base or Phase25HzParams()
    unit = Phase25HzCircuit(length_m, replace(p, feed_tap_V=1.0, supply_V=p.nominal_supply_V), beyond_range=True)
    per_volt = unit.adjustment().voltage_V  # the circuit is linear in the feed voltage
    tap = math.ceil(target_V / per_volt / TAP_STEP_V - 1e-9) * TAP_STEP_V
    return replace(p, feed_tap_V=round(tap, 4))
