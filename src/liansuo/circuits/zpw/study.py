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
import time
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
    """The rows and the summary (configurations, seconds, configurations per second, per-quantity figures)."""
    rng = np.random.default_rng(study.seed)
    rows: list[dict[str, Any]] = []
    changes: dict[str, list[float]] = {q: [] for q in QUANTITIES}
    configurations, seconds = 0, 0.0
    for carrier in study.carriers:
        params = layout_params(study.layout, carrier)
        caps = standard_positions(study.length_m, None, params)
        cases = _cases(study, len(caps), rng)
        ballasts = _ballasts(study, params.ballast_ohm_km, rng)
        t0 = time.perf_counter()
        r = sweep_section(study.length_m, caps, [carrier], ballasts, cases, params=params,
                          capacitance_uF=study.capacitance_uF)
        seconds += time.perf_counter() - t0
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
        "seconds": round(seconds, 3), "configurations_per_s": round(configurations / seconds) if seconds else None,
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
             f"{s['rows']} rows, {s['configurations']:,} shunted configurations in {s['seconds']:.2f} s "
             f"({s['configurations_per_s'] or 0:,}/s)",
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
