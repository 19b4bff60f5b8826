"""The ZPW-2000A model against the capacitor-fault article (Luo Ying 2023, docs/references.md): ``liansuo zpw
validate`` (:mod:`.cli`).

The article's four configurations (``validate.yaml``: a passenger-line and a conventional open-line section of
1400 m, station sections of 650 m without and with frequency selection) are run on :mod:`.model` with every
single capacitor open and at -50 %, on every carrier, at the design ballast. Per row of the article's tables 1 and 2
(section, fault, quantity) the model's largest rise and largest fall, in percent against the healthy section, are put
beside the article's with their ratio. :func:`magnitude_ok` says whether the size agrees (the score), :func:`trend_ok`
whether only the direction does; both are also given for two null models, which know nothing of track circuits, so
that a score can be read against what no model at all would get. :func:`conclusions` checks the article's absolute
findings (the residual under the 153 mV drop, the cab current above its minimum). docs/zpw2000a.md ("Validation
against the capacitor-fault article") gives the rules and the table.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import yaml

from liansuo.circuits.zpw.params import DEFAULT_PARAMS, ZpwParams
from liansuo.kit.fit import fit_all

DATA_FILE = Path(__file__).with_name("validate.yaml")
MATERIAL_PCT = 5.0  # a change larger than this is material (docs/zpw2000a.md)
TARGET_SHARE = 0.8  # the share of rows that must agree in magnitude (--strict)
MAGNITUDE_FACTOR = 1.5  # the model's change within this factor of the article's ...
SMALL_PCT, SMALL_PP = 5.0, 3.0  # ... or, where the article's is under SMALL_PCT %, within SMALL_PP points of it
# models that know nothing of track circuits: every row's (rise, fall) the same, scored by the same rules
NULL_MODELS = {"no change": (0.0, 0.0), "20 % either way": (20.0, 20.0)}
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


def magnitude_ok(paper_rise: float | None, paper_fall: float | None, model_rise: float | None,
                 model_fall: float | None) -> bool:
    """Whether the model's change has the article's size, direction by direction (rise, fall): within a factor of
    :data:`MAGNITUDE_FACTOR` of the article's; within :data:`SMALL_PP` percentage points where the article's is
    under :data:`SMALL_PCT` %, or where it gives none that way (read as no change). A quantity the model does not
    compute (None) never agrees."""
    if model_rise is None or model_fall is None:
        return False
    for paper, model in ((paper_rise, model_rise), (paper_fall, model_fall)):
        if paper is None or paper < SMALL_PCT:
            if abs(model - (paper or 0.0)) > SMALL_PP:
                return False
        elif not paper / MAGNITUDE_FACTOR <= model <= paper * MAGNITUDE_FACTOR:
            return False
    return True


def _ratio(paper: float | None, model: float | None) -> float | None:
    """The model's change over the article's, to 0.01; None where the article gives none or the model computes none."""
    if not paper or model is None:
        return None
    return round(model / paper, 2)


Absolute = dict[str, list[tuple[str, float, float, list[float], list[float]]]]


def _changes(section: ArticleSection, carriers: Sequence[str], ballast: float, base: ZpwParams, ballast_scale: float,
             absolute: Absolute) -> dict[str, dict[str, list[float]]]:
    """Percent change against the healthy section, per fault mode and computed quantity, over every carrier and
    every single faulted capacitor. A conventional section is swept at ``ballast``; a passenger-dedicated one at its
    own design minimum, with its layout's capacitors (which differ by carrier)."""
    import numpy as np

    from liansuo.circuits.zpw.model import layout_params, standard_positions
    from liansuo.circuits.zpw.params import base_index
    from liansuo.circuits.zpw.sweep import sweep_section

    modes = ("open", "half")
    per_carrier: list[dict[str, Any]] = []
    for carrier in carriers:
        params = layout_params(section.layout, carrier, base)
        if section.ends == "insulated":
            params = dataclasses.replace(params, tuning_units=False)
        at = (ballast if section.layout == "conventional" else params.ballast_ohm_km) * ballast_scale
        caps = standard_positions(section.length_m, None, params)
        n = len(caps)
        cases: list[Mapping[int, str]] = [{}] + [{k: m} for m in modes for k in range(1, n + 1)]
        result = sweep_section(section.length_m, caps, [carrier], (at,), cases, params=params)
        figures = {"adjustment_voltage": result.adjustment_mV[0, 0, :],
                   "min_cab_current": result.min_cab_current_mA[0, 0, :],
                   "max_shunt_residual": result.max_shunt_residual_mV[0, 0, :]}
        absolute.setdefault(section.id, []).append(
            (carrier, params.cab_min_mA[base_index(carrier)], params.drop_mV,
             [float(x) for x in result.min_cab_current_mA[0, 0, 1:]],
             [float(x) for x in result.max_shunt_residual_mV[0, 0, 1:]]))
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
def _run(path: Path, base: ZpwParams, ballast_scale: float) -> tuple[tuple[dict[str, Any], ...], Absolute]:
    """The rows, and per section (carrier, its cab-current minimum mA, the receiver's drop mV, min cab current per
    faulted case, max shunt residual per faulted case) for :func:`conclusions`."""
    article = read_article(path)
    absolute: Absolute = {}
    changes = {s.id: _changes(s, article.carriers, article.ballast_ohm_km, base, ballast_scale, absolute)
               for s in article.sections}
    rows = []
    for r in article.rows:
        found = changes[r.section][r.fault].get(r.quantity)
        rise, fall = _range(found) if found is not None else (None, None)
        rows.append({"table": r.table, "section": r.section, "fault": r.fault, "quantity": r.quantity,
                     "paper_rise_pct": r.rise_pct, "paper_fall_pct": r.fall_pct,
                     "model_rise_pct": rise, "model_fall_pct": fall,
                     "rise_ratio": _ratio(r.rise_pct, rise), "fall_ratio": _ratio(r.fall_pct, fall),
                     "magnitude_ok": magnitude_ok(r.rise_pct, r.fall_pct, rise, fall),
                     "trend_ok": trend_ok(r.rise_pct, r.fall_pct, rise, fall)})
    return tuple(rows), absolute


def validate(path: Path = DATA_FILE, base: ZpwParams = DEFAULT_PARAMS, ballast_scale: float = 1.0
             ) -> tuple[dict[str, Any], ...]:
    """Every row of the article's tables beside the model's figures, in the JSON report's shape; ``base`` and
    ``ballast_scale`` change the unpublished parameters (:func:`sensitivity`)."""
    return _run(path, base, ballast_scale)[0]


def _share(n: int, of: int) -> float:
    return round(n / of, 3) if of else 0.0


def summary(rows: Sequence[Mapping[str, Any]]) -> dict[str, Any]:
    """How many rows agree in magnitude and in trend, their shares (0..1, to 0.001), the null models' beside them,
    and whether the magnitude share meets :data:`TARGET_SHARE`."""
    n = len(rows)
    magnitude = sum(1 for r in rows if r["magnitude_ok"])
    trend = sum(1 for r in rows if r["trend_ok"])
    nulls = {}
    for name, (rise, fall) in NULL_MODELS.items():
        m = sum(magnitude_ok(r["paper_rise_pct"], r["paper_fall_pct"], rise, fall) for r in rows)
        t = sum(trend_ok(r["paper_rise_pct"], r["paper_fall_pct"], rise, fall) for r in rows)
        nulls[name] = {"magnitude_ok": m, "magnitude_share": _share(m, n), "trend_ok": t, "trend_share": _share(t, n)}
    cab_rows = [r for r in rows if r["quantity"] == "min_cab_current"]
    return {"rows": n, "magnitude_ok": magnitude, "magnitude_share": _share(magnitude, n),
            "trend_ok": trend, "share": _share(trend, n), "target_share": TARGET_SHARE,
            "target_met": _share(magnitude, n) >= TARGET_SHARE,
            "min_cab_current_rows_ok": sum(1 for r in cab_rows if r["magnitude_ok"]),
            "min_cab_current_rows": len(cab_rows), "null_models": nulls}


def conclusions(path: Path = DATA_FILE, base: ZpwParams = DEFAULT_PARAMS, ballast_scale: float = 1.0
                ) -> list[dict[str, Any]]:
    """The article's absolute findings against the model's faulted cases (every carrier, every single capacitor
    open or at -50 %): the shunt residual stays under the receiver's 153 mV drop everywhere, and the cab current
    stays above its minimum everywhere but in the station section with frequency selection."""
    out = []
    for section, per_carrier in _run(path, base, ballast_scale)[1].items():
        cases = sum(len(c[3]) for c in per_carrier)
        under = sum(1 for _, least, _, cab, _ in per_carrier for v in cab if v < least)
        worst_residual = max(max(res) for *_, res in per_carrier)
        drop = per_carrier[0][2]
        expect_under = section == "station-selection"
        out.append({"section": section, "faulted_cases": cases, "cab_under_minimum": under,
                    "article_cab_under_minimum": "some" if expect_under else "none",
                    "cab_holds": (under > 0) == expect_under,
                    "max_residual_mV": round(worst_residual, 1), "drop_mV": drop,
                    "residual_holds": worst_residual < drop})
    return out


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
             "over every carrier and every single faulted capacitor, design ballast; ratio model/article;",
             "size: within 1.5x (3 points under 5 %); trend: direction only ('liansuo docs zpw2000a')",
             f"{'t':<1} {'section':<26} {'fault':<5} {'quantity':<15} {'paper %':>12} {'model %':>12} {'ratio':>9} "
             "size trend"]
    for r in rows:
        section = names[r["section"]]
        where = f"{section.id} {section.length_m:.0f} m"
        model = ("not modelled" if r["model_rise_pct"] is None
                 else _range_text(r["model_rise_pct"], r["model_fall_pct"]))
        ratio = " ".join("-" if v is None else f"{v:.2f}" if v < 10 else f"{v:.1f}"
                         for v in (r["rise_ratio"], r["fall_ratio"]))
        lines.append(f"{r['table']:<1} {where:<26} {FAULT_TEXT[r['fault']]:<5} {QUANTITY_TEXT[r['quantity']]:<15} "
                     f"{_range_text(r['paper_rise_pct'], r['paper_fall_pct']):>12} {model:>12} {ratio:>9} "
                     f"{'ok' if r['magnitude_ok'] else 'NO':<4} {'ok' if r['trend_ok'] else 'NO'}")
    total = summary(rows)
    lines.append(f"size agrees on {total['magnitude_ok']} of {total['rows']} rows "
                 f"({total['magnitude_share'] * 100:.0f} %; target {TARGET_SHARE * 100:.0f} %: "
                 f"{'met' if total['target_met'] else 'not met'}), min cab current {total['min_cab_current_rows_ok']} "
                 f"of {total['min_cab_current_rows']}")
    lines.append(f"trend agrees on {total['trend_ok']} of {total['rows']} rows ({total['share'] * 100:.0f} %)")
    nulls = "; ".join(f"'{name}' size {null['magnitude_ok']}, trend {null['trend_ok']}"
                      for name, null in total["null_models"].items())
    lines.append(f"null models, the same rules: {nulls}")
    lines.append("the article's conclusions over every faulted case (cab current under its minimum; worst residual):")
    for c in conclusions(path):
        lines.append(f"  {c['section']:<21} {c['cab_under_minimum']:>3} of {c['faulted_cases']:<3} (article: "
                     f"{c['article_cab_under_minimum']:<4}) {'holds' if c['cab_holds'] else 'CONTRADICTED':<12} "
                     f"{c['max_residual_mV']:.0f} mV < {c['drop_mV']:.0f} mV "
                     f"{'holds' if c['residual_holds'] else 'CONTRADICTED'}")
    return fit_all(lines)


# The parameters the article does not publish, each at a low and a high value around the model's (docs/zpw2000a.md,
# "Sensitivity"): (name, the change as text, the parameters, the ballast scale)
def _variants() -> list[tuple[str, str, ZpwParams, float]]:
    p = DEFAULT_PARAMS
    out: list[tuple[str, str, ZpwParams, float]] = []
    for name, field, values in (("cable length", "cable_km", (0.0, 5.0, 15.0)),
                                ("coil and tuning-unit quality", "tuning_q", (10.0, 100.0)),
                                ("air-core coil", "air_core_uH", (p.air_core_uH * 0.8, p.air_core_uH * 1.2)),
                                ("L2 of the 2300/2600 Hz units", "f2_inductance_uH", (50.0, 200.0)),
                                ("transmitter impedance", "source_ohm", (complex(2.0), complex(50.0))),
                                ("receiver impedance", "receiver_ohm", (complex(400.0), complex(1600.0)))):
        for v in values:
            shown = f"{v.real:g}" if isinstance(v, complex) else f"{v:g}"
            changed: Any = {field: v}  # one field of several types: checked by the dataclass itself
            out.append((name, f"{field} = {shown}", dataclasses.replace(p, **changed), 1.0))
    for scale in (0.9, 1.1):
        c1, c2, c3, c4 = (c * scale for c in p.capacitance_uF)
        cap = (c1, c2, c3, c4)
        out.append(("capacitance", f"capacitance x {scale:g}", dataclasses.replace(p, capacitance_uF=cap), 1.0))
    for scale in (1.5, 3.0):
        out.append(("ballast", f"ballast x {scale:g}", p, scale))
    return out


def sensitivity(path: Path = DATA_FILE) -> list[dict[str, Any]]:
    """How the score and the figures that differ most move with each unpublished parameter: per variant, the rows
    that agree in size and in trend, the largest rise of the minimum cab current on the open lines (the article:
    83-112 %), and the faulted cases on the conventional line under the cab-current minimum (the article: none)."""
    out = []
    for name, change, base, scale in [("the model", "as it stands", DEFAULT_PARAMS, 1.0), *_variants()]:
        rows = validate(path, base, scale)
        total = summary(rows)
        cab_rise = max(r["model_rise_pct"] or 0.0 for r in rows
                       if r["quantity"] == "min_cab_current" and r["section"].endswith("-line"))
        line = next(c for c in conclusions(path, base, scale) if c["section"] == "conventional-line")
        out.append({"parameter": name, "change": change, "magnitude_ok": total["magnitude_ok"],
                    "trend_ok": total["trend_ok"], "open_line_cab_rise_pct": cab_rise,
                    "conventional_cab_under_minimum": line["cab_under_minimum"],
                    "conventional_faulted_cases": line["faulted_cases"]})
    return out


def sensitivity_text(found: Sequence[Mapping[str, Any]]) -> str:
    lines = ["sensitivity to the parameters the article does not publish ('liansuo docs zpw2000a'):",
             f"{'parameter':<30} {'change':<26} {'size':>4} {'trend':>5} {'cab rise %':>10} {'cab < min':>10}"]
    for f in found:
        lines.append(f"{f['parameter']:<30} {f['change']:<26} {f['magnitude_ok']:>4} {f['trend_ok']:>5} "
                     f"{f['open_line_cab_rise_pct']:>10.1f} {f['conventional_cab_under_minimum']:>4} of "
                     f"{f['conventional_faulted_cases']}")
    return fit_all(lines)
