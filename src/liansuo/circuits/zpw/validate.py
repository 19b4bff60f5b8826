"""The ZPW-2000A model against the capacitor-fault article (Luo Ying 2023, docs/references.md): ``liansuo zpw
validate`` (:mod:`.cli`).

The article's four configurations (``validate.yaml``: a passenger-line and a conventional open-line section of
1400 m, station sections of 650 m without and with frequency selection) are run on :mod:`.model` with every
single capacitor open and at -50 %, on every carrier, at the design ballast. Per row of the article's tables 1 and 2
(section, fault, quantity) the model's largest rise and largest fall, in percent against the healthy section, are put
beside the article's, and :func:`trend_ok` says whether the trend agrees. docs/zpw2000a.md ("Validation against the
capacitor-fault article") gives the rule and the table.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import yaml

from liansuo.kit.fit import fit_all

DATA_FILE = Path(__file__).with_name("validate.yaml")
MATERIAL_PCT = 5.0  # a change larger than this is material (docs/zpw2000a.md)
TARGET_SHARE = 0.8  # issue 15: the trend agrees on at least 80 % of the rows
QUANTITIES = ("adjustment_voltage", "min_cab_current", "max_shunt_residual", "small_track_voltage")
QUANTITY_TEXT = {"adjustment_voltage": "adjustment", "min_cab_current": "min cab current",
                 "max_shunt_residual": "max residual", "small_track_voltage": "small track"}
FAULT_TEXT = {"open": "open", "half": "-50 %"}


@dataclass(frozen=True)
class ArticleSection:
    """One of the article's configurations: an id, the article's name, the length, the kind of ends and the layout
    whose standard figures it has (:data:`.model.LAYOUTS`)."""

    id: str
    name: str
    length_m: float
    ends: str  # 'tuned' (the model's ZPW-2000A ends) or 'insulated' (insulated joints, no tuning unit)
    layout: str = "conventional"


@dataclass(frozen=True)
class PaperRow:
    """One cell of the article's tables: the largest rise and fall in percent (None: the article gives none)."""

    table: int
    section: str
    fault: str  # 'open' (table 1) or 'half' (table 2, capacitance down 50 %)
    quantity: str
    rise_pct: float | None
    fall_pct: float | None


@dataclass(frozen=True)
class Article:
    """The data file: the configurations, the carriers, the ballast and the table rows."""

    sections: tuple[ArticleSection, ...]
    carriers: tuple[str, ...]
    ballast_ohm_km: float
    rows: tuple[PaperRow, ...]


def _pct(value: Any) -> float | None:
    return None if value is None else float(value)


def read_article(path: Path = DATA_FILE) -> Article:
    """The article's configurations and table rows as stored in ``validate.yaml``."""
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    sections = tuple(ArticleSection(s["id"], s["name"], float(s["length_m"]), s["ends"],
                                    s.get("layout", "conventional")) for s in data["sections"])
    rows = tuple(PaperRow(int(t["table"]), r["section"], t["fault"], r["quantity"], _pct(r["rise_pct"]),
                          _pct(r["fall_pct"]))
                 for t in data["tables"] for r in t["rows"])
    return Article(sections, tuple(str(c) for c in data["carriers"]), float(data["ballast_ohm_km"]), rows)


def trend_ok(paper_rise: float | None, paper_fall: float | None, model_rise: float | None,
             model_fall: float | None, material: float = MATERIAL_PCT) -> bool:
    """Whether the model's trend agrees with the article's, direction by direction (rise, fall):

    * the article gives a material change (more than ``material`` %): the model's is material too;
    * the article gives none in that direction (None): the model's is not material;
    * the article gives a small one (up to ``material`` %): any model figure agrees.

    A quantity the model does not compute (None) never agrees.
    """
    if model_rise is None or model_fall is None:
        return False
    for paper, model in ((paper_rise, model_rise), (paper_fall, model_fall)):
        if paper is None and model > material:
            return False
        if paper is not None and paper > material and model <= material:
            return False
    return True


def _changes(section: ArticleSection, carriers: Sequence[str], ballast: float) -> dict[str, dict[str, list[float]]]:
    """Percent change against the healthy section, per fault mode and computed quantity, over every carrier and
    every single faulted capacitor. A conventional section is swept at ``ballast``; a passenger-dedicated one at its
    own design minimum, with its layout's capacitors (which differ by carrier)."""
    import numpy as np

    from liansuo.circuits.zpw.model import layout_params, standard_positions
    from liansuo.circuits.zpw.sweep import sweep_section

    modes = ("open", "half")
    per_carrier: list[dict[str, Any]] = []
    for carrier in carriers:
        params = layout_params(section.layout, carrier)
        if section.ends == "insulated":
            params = dataclasses.replace(params, tuning_units=False)
        at = ballast if section.layout == "conventional" else params.ballast_ohm_km
        caps = standard_positions(section.length_m, None, params)
        n = len(caps)
        cases: list[Mapping[int, str]] = [{}] + [{k: m} for m in modes for k in range(1, n + 1)]
        result = sweep_section(section.length_m, caps, [carrier], (at,), cases, params=params)
        figures = {"adjustment_voltage": result.adjustment_mV[0, 0, :],
                   "min_cab_current": result.min_cab_current_mA[0, 0, :],
                   "max_shunt_residual": result.max_shunt_residual_mV[0, 0, :]}
        if section.ends == "tuned":  # the small track is the tuning area at the transmitter end
            figures["small_track_voltage"] = result.small_track_mV[0, 0, :]
        per_carrier.append({"n": n, "figures": figures})
    out: dict[str, dict[str, list[float]]] = {}
    for m, mode in enumerate(modes):
        out[mode] = {}
        for q in per_carrier[0]["figures"]:
            values: list[float] = []
            for c in per_carrier:
                f, n = c["figures"][q], c["n"]
                values += [float(x) for x in np.ravel(f[1 + m * n:1 + (m + 1) * n] / f[0] - 1.0) * 100.0]
            out[mode][q] = values
    return out


def _range(changes: Sequence[float]) -> tuple[float, float]:
    """(largest rise, largest fall) in percent, each >= 0, to 0.1 %."""
    rise = max([0.0, *changes])
    fall = max([0.0, *(-c for c in changes)])
    return round(rise, 1) + 0.0, round(fall, 1) + 0.0


@cache
def validate(path: Path = DATA_FILE) -> tuple[dict[str, Any], ...]:
    """Every row of the article's tables beside the model's figures, in the JSON report's shape."""
    article = read_article(path)
    changes = {s.id: _changes(s, article.carriers, article.ballast_ohm_km) for s in article.sections}
    rows = []
    for r in article.rows:
        found = changes[r.section][r.fault].get(r.quantity)
        rise, fall = _range(found) if found is not None else (None, None)
        rows.append({"table": r.table, "section": r.section, "fault": r.fault, "quantity": r.quantity,
                     "paper_rise_pct": r.rise_pct, "paper_fall_pct": r.fall_pct,
                     "model_rise_pct": rise, "model_fall_pct": fall,
                     "trend_ok": trend_ok(r.rise_pct, r.fall_pct, rise, fall)})
    return tuple(rows)


def summary(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """How many rows, how many agree, and the share that agrees (0..1, to 0.001)."""
    agree = sum(1 for r in rows if r["trend_ok"])
    return {"rows": len(rows), "trend_ok": agree, "share": round(agree / len(rows), 3) if rows else 0.0}


def _range_text(rise: float | None, fall: float | None) -> str:
    """'↑83.4 ↓19.3', '↓11.6', or '0' when neither direction has a figure."""
    parts = []
    if rise:
        parts.append(f"↑{rise:.1f}")
    if fall:
        parts.append(f"↓{fall:.1f}")
    return " ".join(parts) or "0"


def as_text(rows: Sequence[Mapping[str, Any]], path: Path = DATA_FILE) -> str:
    """The side-by-side table: one line per row of the article's tables, then the agreement."""
    names = {s.id: s for s in read_article(path).sections}
    lines = ["ZPW-2000A model against Luo Ying 2023 (capacitor faults, tables 1 and 2): largest rise and fall in %",
             "over every carrier and every single faulted capacitor, design ballast; trend: docs/zpw2000a.md",
             f"{'table':<5} {'section':<28} {'fault':<5} {'quantity':<15} {'paper %':>13} {'model %':>13}  trend"]
    for r in rows:
        section = names[r["section"]]
        where = f"{section.id} {section.length_m:.0f} m"
        model = ("not modelled" if r["model_rise_pct"] is None
                 else _range_text(r["model_rise_pct"], r["model_fall_pct"]))
        lines.append(f"{r['table']:<5} {where:<28} {FAULT_TEXT[r['fault']]:<5} {QUANTITY_TEXT[r['quantity']]:<15} "
                     f"{_range_text(r['paper_rise_pct'], r['paper_fall_pct']):>13} {model:>13}  "
                     f"{'ok' if r['trend_ok'] else 'DIFFERS'}")
    total = summary(rows)
    lines.append(f"trend agrees on {total['trend_ok']} of {total['rows']} rows ({total['share'] * 100:.0f} %; target "
                 f"{TARGET_SHARE * 100:.0f} %)")
    return fit_all(lines)
