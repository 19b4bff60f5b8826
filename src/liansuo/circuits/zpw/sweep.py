"""The vectorised sweep of the ZPW-2000A line model (:mod:`.model`): every carrier, ballast, capacitor fault and shunt
position of a section at once, in numpy arrays (``liansuo zpw``, the adjustment table, the article's tables, the
benchmark's ``zpw_configs_per_s``)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from liansuo.circuits.physical import check_ballast
from liansuo.circuits.zpw import ends as zpwends
from liansuo.circuits.zpw.model import FAULT_MODES, CArray, FArray, profile_points, solve, standard_positions
from liansuo.circuits.zpw.params import CARRIERS, DEFAULT_PARAMS, ZpwParams

Case = Mapping[int, str | float]  # 1-based capacitor number -> open / half / short, or a factor of its capacitance


def _capacitor_table(carriers: Sequence[str], faults: Sequence[Case], n: int, params: ZpwParams,
                     capacitance_uF: float | None = None) -> CArray:
    """(C, F, N) admittances: each fault case maps 1-based capacitor numbers to open / half / short, or to a factor
    of the capacitance (a tolerance: 0.9 is -10 %)."""
    ok = np.array([params.capacitor_admittance(c, "ok", capacitance_uF) for c in carriers])
    factor = np.ones((len(faults), n))
    short = np.zeros((len(faults), n), dtype=bool)
    for f, case in enumerate(faults):
        for number, mode in case.items():
            if not 1 <= number <= n:
                raise ValueError(f"capacitor {number} does not exist: the section has {n}")
            if isinstance(mode, float):
                if not 0.0 <= mode < 10.0:
                    raise ValueError(f"capacitor {number}: a factor of its capacitance from 0 to 10, not {mode}")
                factor[f, number - 1] = mode
                continue
            if mode not in FAULT_MODES:
                raise ValueError(f"unknown capacitor fault '{mode}': use open, half or short")
            factor[f, number - 1] = {"open": 0.0, "half": 0.5, "short": 1.0}[mode]
            short[f, number - 1] = mode == "short"
    table = ok[:, None, None] * factor[None]
    table[:, short] = 1.0 / params.capacitor_short_ohm
    return table


def single_faults(n: int, modes: Sequence[str] = FAULT_MODES) -> list[dict[int, str]]:
    """No fault, then every capacitor in every mode, one at a time (Luo Ying's fault cases, docs/references.md)."""
    return [{}] + [{k: m} for m in modes for k in range(1, n + 1)]


def fault_label(case: Case) -> str:
    """'C3 open, C5 half', or 'none'; a capacitance factor as a percentage ('C3 -8.2 %')."""
    return ", ".join(f"C{k} {m}" if isinstance(m, str) else f"C{k} {(m - 1) * 100:+.1f} %"
                     for k, m in sorted(case.items())) or "none"


@dataclass(frozen=True)
class SweepResult:
    """One section length: every carrier x ballast x fault case (x shunt position). Positions from the lower end."""

    length_m: float
    capacitors_m: tuple[float, ...]
    carriers: tuple[str, ...]
    ballasts_ohm_km: tuple[float, ...]
    faults: tuple[Case, ...]
    positions_m: FArray
    adjustment_mV: FArray  # (C, B, F)
    residual_mV: FArray  # (C, B, F, P)
    cab_current_mA: FArray  # (C, B, F, P)
    small_track_mV: FArray  # (C, B, F): the small track (transmitter-end tuning area) as its receiver reads it

    @property
    def max_shunt_residual_mV(self) -> FArray:
        return np.asarray(self.residual_mV.max(axis=-1))

    @property
    def min_cab_current_mA(self) -> FArray:
        return np.asarray(self.cab_current_mA.min(axis=-1))

    @property
    def configurations(self) -> int:
        """Shunted configurations (carrier, ballast, fault case, shunt position) evaluated."""
        return int(self.residual_mV.size)


def sweep_section(length_m: float, capacitors_m: Sequence[float], carriers: Sequence[str] = CARRIERS,
                  ballasts: Sequence[float] = (1.0,), faults: Sequence[Case] | None = None,
                  positions_m: Sequence[float] | None = None, params: ZpwParams = DEFAULT_PARAMS,
                  capacitance_uF: float | None = None) -> SweepResult:
    """Every configuration of one section at once; receiver gain set per carrier as ``ZpwCircuit`` sets it."""
    for b in ballasts:
        check_ballast("ballasts", b)
    caps = sorted(capacitors_m)
    cases = single_faults(len(caps)) if faults is None else list(faults)
    pos = profile_points(length_m, params.profile_step_m) if positions_m is None else np.asarray(positions_m, float)
    z = np.array([params.rail_impedance(c) for c in carriers])
    ycap = _capacitor_table(carriers, cases, len(caps), params, capacitance_uF)
    healthy = _capacitor_table(carriers, [{}], len(caps), params, capacitance_uF)
    design = [[zpwends.section_ends(params, c)] for c in carriers]
    reference, _, _, vtx_ref = solve(length_m, caps, healthy, (), z, (params.ballast_ohm_km,), params, ends=design)
    gain = params.adjust_mV / np.abs(reference[:, 0, 0])  # mV per rail volt, per carrier
    small = np.array([e[0].small_track for e in design])
    reach = np.abs(vtx_ref[:, 0, 0] * small)  # 0 with insulated joints: no small track
    small_gain = np.divide(params.adjust_mV, reach, out=np.zeros_like(reach), where=reach > 0)  # adjusted alike
    ends = [[zpwends.section_ends(params, c, b) for b in ballasts] for c in carriers]
    v0, v, i, vtx = solve(length_m, caps, ycap, pos, z, ballasts, params, ends=ends)
    small_b = np.array([[e.small_track for e in row] for row in ends])[..., None]
    return SweepResult(float(length_m), tuple(caps), tuple(carriers), tuple(float(b) for b in ballasts),
                       tuple(cases), pos, np.abs(v0) * gain[:, None, None], np.abs(v) * gain[:, None, None, None],
                       np.abs(i) * 1000.0, np.abs(vtx * small_b) * small_gain[:, None, None])


def sweep(lengths: Sequence[float], carriers: Sequence[str] = CARRIERS, ballasts: Sequence[float] = (1.0,),
          faults: Sequence[Mapping[int, str]] | None = None, params: ZpwParams = DEFAULT_PARAMS,
          ) -> list[SweepResult]:
    """Sections of each length with standard capacitors; ``faults`` None = every single capacitor fault."""
    return [sweep_section(length, standard_positions(length, None, params), carriers, ballasts, faults,
                          params=params) for length in lengths]
