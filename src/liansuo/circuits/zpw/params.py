"""The physical parameters of a ZPW-2000A section (:class:`ZpwParams`) and its carriers: what the line model
(:mod:`.model`) and its ends (:mod:`.ends`) are both built from. Sources: docs/zpw2000a.md."""

from __future__ import annotations

import math
from dataclasses import dataclass

from liansuo.circuits.physical import check_ballast

BASE_CARRIERS = ("1700", "2000", "2300", "2600")
CARRIERS = tuple(f"{b}-{v}" for b in BASE_CARRIERS for v in (1, 2))
VARIANT_OFFSET_HZ = {"1": 1.4, "2": -1.3}  # TB/T 3206 (docs/references.md): -1 is +1.4 Hz, -2 is -1.3 Hz


def carrier_frequency_Hz(carrier: str) -> float:
    """``'2300-1'`` -> 2301.4 Hz; a bare ``'2300'`` is the nominal carrier."""
    base, _, variant = carrier.partition("-")
    if base not in BASE_CARRIERS or (variant and variant not in VARIANT_OFFSET_HZ):
        raise ValueError(f"'{carrier}' is not a ZPW-2000A carrier: use 1700, 2000, 2300 or 2600 with -1 or -2")
    return float(base) + (VARIANT_OFFSET_HZ[variant] if variant else 0.0)


def base_index(carrier: str) -> int:
    carrier_frequency_Hz(carrier)  # validates
    return BASE_CARRIERS.index(carrier.partition("-")[0])


@dataclass(frozen=True)
class ZpwParams:
    """Physical parameters; per-carrier tuples are in the order 1700, 2000, 2300, 2600 Hz. Sources: docs/zpw2000a.md.
    """

    # line (typical ZPW-2000A design values, 60 kg/m jointless rail; not given by Luo Ying 2023 (docs/references.md):
    # verify)
    rail_resistance_ohm_km: tuple[float, float, float, float] = (1.177, 1.306, 1.435, 1.558)
    rail_inductance_mH_km: tuple[float, float, float, float] = (1.314, 1.304, 1.297, 1.291)
    ballast_ohm_km: float = 1.0  # TB/T 3206: design (minimum) value, at which sections are adjusted
    # compensation capacitors (typical line values; station coding uses 80/80/60/60 uF)
    capacitance_uF: tuple[float, float, float, float] = (55.0, 50.0, 46.0, 40.0)
    capacitor_spacing_m: float = 100.0  # TB/T 3206: about every 100 m, half a spacing at the ends
    capacitor_min_section_m: float = 300.0  # Luo Ying 2023 (docs/references.md): only sections over 300 m
    capacitor_short_ohm: float = 0.01  # a shorted capacitor (modelled)
    # transmitter and receiver (typical: level-1 output 161-170 V, 1:9 matching transformer; impedances modelled)
    transmitter_V: float = 170.0  # the level in use (the adjustment table chooses it: circuits/zpw/adjust.py)
    transmitter_levels_V: tuple[float, float, float, float, float] = (170.0, 154.0, 135.0, 111.5, 79.5)  # levels 1-5
    matching_ratio: float = 9.0  # equipment side : rail side
    source_ohm: complex = complex(10.0, 0.0)  # transmitter output impedance, equipment room (modelled)
    receiver_ohm: complex = complex(800.0, 0.0)  # receiver input impedance, equipment room (modelled)
    # cable between the equipment room and the track (SPT signalling cable, 1.0 mm conductors, a pair; TB/T 3100,
    # verify): the ZPW-2000A cable simulation network pads every cable to the standard 10 km
    cable_km: float = 10.0
    cable_ohm_km: float = 47.0  # loop resistance (2 x 23.5 ohm/km)
    cable_mH_km: float = 0.75
    cable_nF_km: float = 28.0
    # tuning areas (circuits/zpw/ends.py): 29 m electrical insulation joint, air-core coil, tuning units designed
    # for the zero at the neighbour's carrier and the pole at the own one
    tuning_units: bool = True  # False: insulated joints at both ends, no tuning area across the rails
    tuning_area_m: float = 29.0
    air_core_uH: float = 33.5
    tuning_q: float = 30.0  # quality factor of the air-core coil and the tuning units' inductors (modelled)
    f2_inductance_uH: float = 100.0  # L2 of the 2300 / 2600 Hz units: not fixed by the two resonances (modelled)
    # receiver (维规 TG/XH 101-2015, docs/references.md: pick-up about 200-210 mV, drop 153 mV; verify)
    pickup_mV: float = 210.0
    drop_mV: float = 153.0
    adjust_mV: float = 240.0  # no-train main-track output the attenuator is set to at the design ballast
    # shunts, other faults
    standard_shunt_ohm: float = 0.15  # TB/T 3206
    broken_rail_ohm: float = 1.0e6
    insulation_short_ohm: float = 0.01
    # cab signal: minimum entry current with the standard shunt (station coding standard, commonly quoted)
    cab_min_mA: tuple[float, float, float, float] = (500.0, 500.0, 500.0, 450.0)
    profile_step_m: float = 10.0  # shunt positions for max residual / min cab current: every 10 m, ends included

    def __post_init__(self) -> None:
        check_ballast("ballast_ohm_km", self.ballast_ohm_km)

    def rail_impedance(self, carrier: str) -> complex:
        i = base_index(carrier)
        omega = 2 * math.pi * carrier_frequency_Hz(carrier)
        return complex(self.rail_resistance_ohm_km[i], omega * self.rail_inductance_mH_km[i] * 1e-3)

    def capacitor_admittance(self, carrier: str, mode: str = "ok", capacitance_uF: float | None = None) -> complex:
        """Admittance (S) of one capacitor: ``ok``, ``half`` (-50 %), ``open`` or ``short``."""
        c = (capacitance_uF or self.capacitance_uF[base_index(carrier)]) * 1e-6
        if mode == "open":
            return 0j
        if mode == "short":
            return complex(1.0 / self.capacitor_short_ohm)
        if mode not in ("ok", "half"):
            raise ValueError(f"unknown capacitor fault '{mode}': use open, half or short")
        return complex(0.0, 2 * math.pi * carrier_frequency_Hz(carrier) * c * (0.5 if mode == "half" else 1.0))

    def cab_min(self, carrier: str) -> float:
        return self.cab_min_mA[base_index(carrier)]


DEFAULT_PARAMS = ZpwParams()
