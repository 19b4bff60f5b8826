"""A parameter study of one ZPW-2000A section (``liansuo zpw sweep``): every carrier and ballast, with no fault,
every single capacitor fault, or a Monte Carlo draw of ballast and capacitor tolerances, on the vectorised sweep
(:mod:`.sweep`). One row per (carrier, ballast, case): the adjustment voltage, the minimum cab current and the
worst shunt residual along the section (a 0.15 ohm shunt every 10 m), the small track, and the two absolute checks
(cab current at or above its minimum, residual under the receiver's drop).

The summary gives, per quantity, the range over the cases and, for fault cases, the largest rise and fall against
the healthy section at the same carrier and ballast: the figure of Luo Ying's tables (docs/zpw2000a.md shows one
row reproduced end to end).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from liansuo.circuits.zpw.model import LAYOUTS, layout_params, standard_positions
from liansuo.circuits.zpw.sweep import fault_label, sweep_section

FAULTS = ("none", "single-open", "single-half", "single")  # the fault cases of a study
COLUMNS = ("carrier", "ballast_ohm_km", "case", "adjustment_mV", "min_cab_current_mA", "max_residual_mV",
           "small_track_mV", "cab_min_mA", "cab_ok", "residual_ok")
QUANTITIES = ("adjustment_mV", "min_cab_current_mA", "max_residual_mV", "small_track_mV")


@dataclass(frozen=True)
class Study:
    """What to sweep. ``ballasts`` None: the layout's design minimum. ``samples`` > 0: a Monte Carlo of about that
    many healthy sections per carrier, ballast drawn uniformly within ``ballast_tolerance`` (a fraction) of each
    ballast and every capacitor's capacitance within ``capacitor_tolerance`` of its value (ballast draws x
    capacitor draws, about the square root of ``samples`` each)."""

    length_m: float = 1400.0
    layout: str = "conventional"
    carriers: tuple[str, ...] = ("1700-1", "2000-1", "2300-1", "2600-1")
    ballasts: tuple[float, ...] | None = None
    capacitance_uF: float | None = None
    faults: str = "none"
    samples: int = 0
    ballast_tolerance: float = 0.2
    capacitor_tolerance: float = 0.1
    seed: int = 1

    def problem(self) -> str:
        """Why the study cannot run, in one line ('' when it can)."""
        if self.layout not in LAYOUTS:
            return f"unknown layout '{self.layout}': use {', '.join(LAYOUTS)}"
        if self.faults not in FAULTS:
            return f"unknown fault cases '{self.faults}': use {', '.join(FAULTS)}"
        if self.samples and self.faults != "none":
            return "a Monte Carlo draws healthy sections: give --samples or --faults, not both"
        if not 0 <= self.ballast_tolerance < 1 or not 0 <= self.capacitor_tolerance < 1:
            return "tolerances are fractions from 0 to under 1 (0.2 is +-20 %)"
        return ""


def _cases(study: Study, n: int, rng: np.random.Generator) -> list[Mapping[int, str | float]]:
    if study.samples:
        draws = max(1, math.ceil(math.sqrt(study.samples)))
        tol = study.capacitor_tolerance
        return [{k + 1: float(f) for k, f in enumerate(rng.uniform(1 - tol, 1 + tol, n))} for _ in range(draws)]
    modes = {"none": (), "single-open": ("open",), "single-half": ("half",), "single": ("open", "half")}[study.faults]
    return [{}] + [{k: m} for m in modes for k in range(1, n + 1)]


def _ballasts(study: Study, design: float, rng: np.random.Generator) -> list[float]:
    base = list(study.ballasts or (design,))
    if not study.samples:
        return base
    draws = max(1, math.ceil(math.sqrt(study.samples)))
    tol = study.ballast_tolerance
    return [float(b) for x in base for b in rng.uniform(x * (1 - tol), x * (1 + tol), draws)]


def _label(case: Mapping[int, str | float]) -> str:
    return "sample" if any(isinstance(v, float) for v in case.values()) else fault_label(case)


def run_study(study: Study) -> tuple[list[dict[str, Any]], dict[str, Any]]:
    """The rows and the summary (the shunted configurations solved, per-quantity figures). How fast it runs is
    ``liansuo bench``'s to say (``zpw_configs_per_s``): nothing here reads the clock."""
    rng = np.random.default_rng(study.seed)
    rows: list[dict[str, Any]] = []
    changes: dict[str, list[float]] = {q: [] for q in QUANTITIES}
    configurations = 0
    for carrier in study.carriers:
        params = layout_params(study.layout, carrier)
        caps = standard_positions(study.length_m, None, params)
        cases = _cases(study, len(caps), rng)
        ballasts = _ballasts(study, params.ballast_ohm_km, rng)
        r = sweep_section(study.length_m, caps, [carrier], ballasts, cases, params=params,
                          capacitance_uF=study.capacitance_uF)
        configurations += r.configurations
        least, drop = params.cab_min(carrier), params.drop_mV
        figures = {"adjustment_mV": r.adjustment_mV[0], "min_cab_current_mA": r.min_cab_current_mA[0],
                   "max_residual_mV": r.max_shunt_residual_mV[0], "small_track_mV": r.small_track_mV[0]}
        for b, ballast in enumerate(ballasts):
            for f, case in enumerate(cases):
                values = {q: round(float(v[b, f]), 2) for q, v in figures.items()}
                row: dict[str, Any] = {"carrier": carrier, "ballast_ohm_km": round(ballast, 4), "case": _label(case),
                                       **values, "cab_min_mA": least,
                                       "cab_ok": values["min_cab_current_mA"] >= least,
                                       "residual_ok": values["max_residual_mV"] < drop}
                rows.append(row)
                if case and not study.samples:
                    for q, v in figures.items():
                        if v[b, 0] > 0:
                            changes[q].append(float(v[b, f] / v[b, 0] - 1.0) * 100.0)
    quantities: dict[str, dict[str, Any]] = {}
    summary: dict[str, Any] = {
        "length_m": study.length_m, "layout": study.layout, "carriers": list(study.carriers),
        "faults": study.faults, "samples": study.samples, "rows": len(rows), "configurations": configurations,
        "cab_under_minimum": sum(1 for r in rows if not r["cab_ok"]),
        "residual_over_drop": sum(1 for r in rows if not r["residual_ok"]), "quantities": quantities}
    for q in QUANTITIES:
        column = np.array([r[q] for r in rows], dtype=float)
        entry: dict[str, Any] = {"min": round(float(column.min()), 2), "p5": round(float(np.percentile(column, 5)), 2),
                                 "median": round(float(np.median(column)), 2),
                                 "p95": round(float(np.percentile(column, 95)), 2),
                                 "max": round(float(column.max()), 2)}
        if changes[q]:
            entry["largest_rise_pct"] = round(max([0.0, *changes[q]]), 1)
            entry["largest_fall_pct"] = round(max([0.0, *(-c for c in changes[q])]), 1)
        quantities[q] = entry
    return rows, summary


def summary_text(summary: Mapping[str, Any]) -> str:
    """The summary as a few lines of text."""
    s = summary
    what = f"Monte Carlo of {s['samples']}" if s["samples"] else f"faults: {s['faults']}"
    lines = [f"ZPW-2000A sweep: {s['length_m']:g} m {s['layout']} section, carriers {', '.join(s['carriers'])}, "
             f"{what}",
             f"{s['rows']} rows, {s['configurations']:,} shunted configurations",
             f"{'quantity':<20}{'min':>9}{'p5':>9}{'median':>9}{'p95':>9}{'max':>9}  largest rise / fall"]
    for q, e in s["quantities"].items():
        change = (f"  ↑{e['largest_rise_pct']:.1f} % ↓{e['largest_fall_pct']:.1f} %"
                  if "largest_rise_pct" in e else "")
        lines.append(f"{q:<20}{e['min']:>9.1f}{e['p5']:>9.1f}{e['median']:>9.1f}{e['p95']:>9.1f}{e['max']:>9.1f}"
                     + change)
    lines.append(f"cab current under its minimum in {s['cab_under_minimum']} rows; residual at or over the drop in "
                 f"{s['residual_over_drop']}")
    return "\n".join(lines)


def csv_rows(rows: Sequence[Mapping[str, Any]]) -> list[list[Any]]:
    return [[r[c] for c in COLUMNS] for r in rows]


# ---- the profiles along the section (--plot, --plot-csv) -----------------------------------------------------------
PROFILE_COLUMNS = ("carrier", "ballast_ohm_km", "case", "position_m", "shunt_residual_mV", "cab_current_mA",
                   "adjustment_mV")
WORST_FEW = 3


def profiles(study: Study) -> tuple[str, float, list[dict[str, Any]]]:
    """The study's first carrier and ballast along the section, the standard shunt at each point: the healthy
    section, then the fault cases that raise the residual most and lower the cab current most (a few of each), or
    for a Monte Carlo the 5th and 95th percentile at each point. Returns (carrier, ballast, profiles), each profile
    ``{case, adjustment_mV, positions_m, residual_mV, cab_mA}``."""
    rng = np.random.default_rng(study.seed)
    carrier = study.carriers[0]
    params = layout_params(study.layout, carrier)
    caps = standard_positions(study.length_m, None, params)
    cases = _cases(study, len(caps), rng)
    ballast = _ballasts(study, params.ballast_ohm_km, rng)[0] if study.samples else \
        (study.ballasts or (params.ballast_ohm_km,))[0]
    if study.samples:
        cases = [{}, *cases]
    r = sweep_section(study.length_m, caps, [carrier], [ballast], cases, params=params,
                      capacitance_uF=study.capacitance_uF)
    residual, cab, adjust = r.residual_mV[0, 0], r.cab_current_mA[0, 0], r.adjustment_mV[0, 0]
    pos = [float(x) for x in r.positions_m]

    def one(case: str, f: int) -> dict[str, Any]:
        return {"case": case, "adjustment_mV": float(adjust[f]), "positions_m": pos,
                "residual_mV": [float(v) for v in residual[f]], "cab_mA": [float(v) for v in cab[f]]}

    out = [one("healthy", 0)]
    if study.samples:
        for q in (5, 95):
            out.append({"case": f"p{q} of {len(cases) - 1} samples",
                        "adjustment_mV": float(np.percentile(adjust[1:], q)),
                        "positions_m": pos, "residual_mV": [float(v) for v in np.percentile(residual[1:], q, axis=0)],
                        "cab_mA": [float(v) for v in np.percentile(cab[1:], q, axis=0)]})
    elif len(cases) > 1:
        by_residual = sorted(range(1, len(cases)), key=lambda f: -float(residual[f].max()))[:WORST_FEW]
        by_cab = sorted(range(1, len(cases)), key=lambda f: float(cab[f].min()))[:WORST_FEW]
        for f in dict.fromkeys([*by_residual, *by_cab]):
            out.append(one(_label(cases[f]), f))
    return carrier, ballast, out


def profile_rows(carrier: str, ballast: float, profs: Sequence[Mapping[str, Any]]) -> list[dict[str, Any]]:
    return [{"carrier": carrier, "ballast_ohm_km": round(ballast, 4), "case": p["case"], "position_m": round(x, 2),
             "shunt_residual_mV": round(v, 3), "cab_current_mA": round(i, 3),
             "adjustment_mV": round(p["adjustment_mV"], 3)}
            for p in profs for x, v, i in zip(p["positions_m"], p["residual_mV"], p["cab_mA"], strict=True)]


def draw(study: Study, carrier: str, ballast: float, profs: Sequence[Mapping[str, Any]], path: str) -> str:
    """Residual over cab current along the section, one line per profile, the relay's levels and the cab minimum;
    '' or why the file could not be written."""
    from liansuo.kit.plotfiles import new_figure, save_figure

    params = layout_params(study.layout, carrier)
    fig, (top, bottom) = new_figure(2, 1, sharex=True)
    for n, p in enumerate(profs):
        style: dict[str, Any] = ({"color": "black", "linewidth": 2.0, "zorder": 3} if n == 0
                                 else {"linewidth": 1.1, "color": f"C{(n - 1) % 10}"})
        top.plot(p["positions_m"], p["residual_mV"], label=f"{p['case']} (no train {p['adjustment_mV']:.0f} mV)",
                 **style)
        bottom.plot(p["positions_m"], p["cab_mA"], label=p["case"], **style)
    for level, colour, name in ((params.pickup_mV, "tab:green", "pick-up"), (params.drop_mV, "tab:red", "drop")):
        top.axhline(level, color=colour, linestyle="--", linewidth=1)
        top.text(0.005, level, f" {name} {level:g} mV", color=colour, va="bottom", fontsize=8,
                 transform=top.get_yaxis_transform())
    top.set_ylim(0, max(params.pickup_mV * 1.15, max(max(p["residual_mV"]) for p in profs) * 1.1))
    top.set_ylabel("receiver output (mV)")
    top.set_title(f"ZPW-2000A {carrier}, {study.length_m:g} m {study.layout}, ballast {ballast:.3g} ohm*km, "
                  f"{params.standard_shunt_ohm:g} ohm shunt at each point", fontsize=10)
    top.legend(fontsize=7, loc="upper right", ncol=2)
    least = params.cab_min(carrier)
    bottom.axhline(least, color="tab:red", linestyle="--", linewidth=1)
    bottom.text(0.995, least, f"cab minimum {least:g} mA ", color="tab:red", va="bottom", ha="right", fontsize=8,
                transform=bottom.get_yaxis_transform())
    bottom.set_ylim(0, max(max(p["cab_mA"]) for p in profs) * 1.1)
    bottom.set_ylabel("cab-signal current (mA)")
    bottom.set_xlabel("shunt position from the receiver end (m)")
    bottom.set_xlim(0, study.length_m)
    return save_figure(fig, path)
