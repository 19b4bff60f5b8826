"""The ZPW-2000A adjustment table (调整表): per carrier, cable length and section length, the transmitter level and
the receiver setting a maintainer applies, and the check that a section so adjusted detects a standard-shunted train.

A maintainer does not tune a section by trial: the table, looked up by the section's carrier, cable and length, gives
the transmitter level (发送电平, levels 1-5) and the main-track output (主轨出, mV) the receiver level is set to with no
train at the design minimum ballast. The table in ``adjust.yaml`` is derived from this model (:func:`derive_table`)
and a test checks that it still is; it is model data, not a national rule, because its figures follow from the model's
line and end impedances (rebuild it with ``python -m liansuo.circuits.zpw.adjust`` when they change).

How a row is derived, over every length of its band and both variants of the carrier (docs/zpw2000a.md):

* **Safety first.** Everything is linear, so the worst shunt residual is proportional to the receiver setting: the
  setting is at most ``drop_mV`` divided by the worst residual per mV of adjustment, over the design ballast range
  (minimum to dry), healthy and every single capacitor fault, a 0.15 ohm shunt every 10 m; less a safety margin.
* **Then availability.** The setting is the nominal ``adjust_nominal_mV`` when that is safe, else the safe limit; a
  row whose safe limit is under ``adjust_floor_mV`` (pick-up plus a margin) cannot be adjusted: it is set to the
  floor (the relay picks up in wet ballast) and ``adjustable: false`` (``liansuo check`` warns for such sections).
* **Transmitter level.** The lowest output (the highest level number) that still gives the cab-signal minimum current
  (plus a margin) everywhere on the healthy section at the design minimum ballast; level 1 when none does.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import yaml

from liansuo.circuits.zpw.model import (
    LAYOUTS,
    ZpwCircuit,
    ZpwFaults,
    capacitor_positions,
    layout_params,
    section_layout,
    standard_positions,
)
from liansuo.circuits.zpw.params import BASE_CARRIERS, DEFAULT_PARAMS, ZpwParams
from liansuo.circuits.zpw.sweep import fault_label, sweep_section
from liansuo.kit.safeyaml import build, compose, read_file

if TYPE_CHECKING:
    from liansuo.kit.source import Diagnostic
    from liansuo.stations.station import Station

TABLE_FILE = Path(__file__).with_name("adjust.yaml")
FAULT_MODES_CHECKED = ("open", "half", "short")


@dataclass(frozen=True)
class AdjustmentRow:
    """One line of the table: sections of ``layout`` (:data:`.model.LAYOUTS`) and ``carrier`` (base frequency)
    with ``cable_km`` of cable, longer than ``from_m`` up to ``to_m``."""

    layout: str
    carrier: str
    cable_km: float
    from_m: float
    to_m: float
    level: int
    adjust_mV: float
    adjustable: bool


@dataclass(frozen=True)
class AdjustmentTable:
    """The table's settings (what it was derived for) and its rows."""

    ballasts_ohm_km: tuple[float, ...]  # the ballasts swept, from the lowest design minimum of any layout to dry
    adjust_nominal_mV: float
    adjust_floor_mV: float
    safety_margin: float  # fraction kept below the drop level
    cab_margin: float  # fraction kept above the cab-signal minimum
    band_m: float
    max_length_m: float
    cable_km: tuple[float, ...]
    rows: tuple[AdjustmentRow, ...]

    def ballasts(self, minimum: float) -> tuple[float, ...]:
        """The design ballast range of a layout whose design minimum is ``minimum``, as swept: the minimum, then every
        ballast of the table above it."""
        return (minimum, *(b for b in self.ballasts_ohm_km if b > minimum))

    def row(self, carrier: str, length_m: float, cable_km: float | None = None,
            layout: str = "conventional") -> AdjustmentRow:
        """The row of a section; past the table's longest length, the last row of the carrier (not adjustable:
        :func:`check_section` reports it)."""
        base = carrier.partition("-")[0]
        cable = self.cable_km[0] if cable_km is None else cable_km
        rows = [r for r in self.rows if r.layout == layout and r.carrier == base and math.isclose(r.cable_km, cable)]
        if not rows:
            raise LookupError(f"the ZPW-2000A adjustment table has no rows for {layout} carrier {base} with "
                              f"{cable:g} km of cable (it has {', '.join(f'{c:g}' for c in self.cable_km)} km)")
        return next((r for r in rows if r.from_m < length_m <= r.to_m), rows[-1] if length_m > 0 else rows[0])

    def as_dict(self) -> dict[str, Any]:
        return {
            "ballasts_ohm_km": [b if math.isfinite(b) else math.inf for b in self.ballasts_ohm_km],
            "adjust_nominal_mV": self.adjust_nominal_mV, "adjust_floor_mV": self.adjust_floor_mV,
            "safety_margin": self.safety_margin, "cab_margin": self.cab_margin, "band_m": self.band_m,
            "max_length_m": self.max_length_m, "cable_km": list(self.cable_km),
            "rows": [dataclasses.asdict(r) for r in self.rows],
        }


def _settings(data: dict[str, Any]) -> dict[str, Any]:
    return {"ballasts_ohm_km": tuple(float(b) for b in data["ballasts_ohm_km"]),
            "adjust_nominal_mV": float(data["adjust_nominal_mV"]), "adjust_floor_mV": float(data["adjust_floor_mV"]),
            "safety_margin": float(data["safety_margin"]), "cab_margin": float(data["cab_margin"]),
            "band_m": float(data["band_m"]), "max_length_m": float(data["max_length_m"]),
            "cable_km": tuple(float(c) for c in data["cable_km"])}


def load_table(path: Path = TABLE_FILE) -> AdjustmentTable:
    """The table as stored (``adjust.yaml`` by default)."""
    root = compose(read_file(path))
    data: dict[str, Any] = build(root).data if root is not None else {}
    rows = tuple(AdjustmentRow(str(r["layout"]), str(r["carrier"]), float(r["cable_km"]), float(r["from_m"]),
                               float(r["to_m"]), int(r["level"]), float(r["adjust_mV"]), bool(r["adjustable"]))
                 for r in data["rows"])
    return AdjustmentTable(**_settings(data), rows=rows)


_TABLE: AdjustmentTable | None = None


def table() -> AdjustmentTable:
    """The stored table, read once."""
    global _TABLE
    if _TABLE is None:
        _TABLE = load_table()
    return _TABLE


# ---- derivation ----------------------------------------------------------------------------------------------------
def _per_mV(length_m: float, carriers: Sequence[str], ballasts: Sequence[float], params: ZpwParams,
            capacitors_m: Sequence[float] | None = None, capacitance_uF: float | None = None,
            ) -> tuple[float, float, str, str, float]:
    """(worst residual per mV of adjustment, its ballast, its carrier, its fault, least healthy cab current in mA
    at the design minimum ballast) of one section, for the transmitter at ``params.transmitter_V``."""
    caps = standard_positions(length_m, None, params) if capacitors_m is None else list(capacitors_m)
    res = sweep_section(length_m, caps, carriers, ballasts, params=dataclasses.replace(params, adjust_mV=1.0),
                        capacitance_uF=capacitance_uF)
    worst = res.max_shunt_residual_mV  # (C, B, F)
    c, b, f = (int(k) for k in np.unravel_index(int(worst.argmax()), worst.shape))
    return (float(worst[c, b, f]), ballasts[b], carriers[c], fault_label(res.faults[f]),
            float(res.cab_current_mA[:, 0, 0, :].min()))


def derive_table(settings: AdjustmentTable | None = None, params: ZpwParams = DEFAULT_PARAMS,
                 layouts: Sequence[str] = LAYOUTS) -> AdjustmentTable:
    """The rows for the settings of ``settings`` (default: the stored table's), from the model, for ``layouts``."""
    s = settings or table()
    rows = []
    for layout, cable, base in ((lay, c, b) for lay in layouts for c in s.cable_km for b in BASE_CARRIERS):
        rows += _rows(s, layout, cable, base, params)
    return dataclasses.replace(s, rows=tuple(rows))


def _rows(s: AdjustmentTable, layout: str, cable: float, base: str, params: ZpwParams) -> list[AdjustmentRow]:
    """The rows of one layout, cable length and base carrier, band by band of section length."""
    bands = np.arange(0.0, s.max_length_m, s.band_m)
    return [derive_row(s, layout, cable, base, float(lo), float(min(lo + s.band_m, s.max_length_m)), params)
            for lo in bands]


def derive_row(s: AdjustmentTable, layout: str, cable: float, base: str, lo: float, hi: float,
               params: ZpwParams = DEFAULT_PARAMS) -> AdjustmentRow:
    """The row for sections of ``layout`` and ``base`` carrier (both variants) longer than ``lo`` up to ``hi``,
    every 10 m, over the layout's design ballast range."""
    p = dataclasses.replace(layout_params(layout, base, params), transmitter_V=params.transmitter_levels_V[0])
    ballasts = s.ballasts(p.ballast_ohm_km)
    variants = [f"{base}-1", f"{base}-2"]
    worst, cab = 0.0, math.inf
    for length in np.arange(hi, lo, -10.0):
        w, _, _, _, c = _per_mV(float(length), variants, ballasts, p)
        worst, cab = max(worst, w), min(cab, c)
    limit = params.drop_mV / worst * (1.0 - s.safety_margin)
    adjustable = limit >= s.adjust_floor_mV
    adjust = math.floor(min(s.adjust_nominal_mV, limit)) if adjustable else s.adjust_floor_mV
    need = params.cab_min(base) * (1.0 + s.cab_margin)
    level = max((n for n, v in enumerate(params.transmitter_levels_V, start=1)
                 if cab * v / params.transmitter_levels_V[0] >= need), default=1)
    return AdjustmentRow(layout, base, cable, lo, hi, level, float(adjust), adjustable)


def write_table(path: Path = TABLE_FILE) -> None:
    """Derive the table for the stored settings and write it back."""
    t = derive_table()
    head = ("# ZPW-2000A adjustment table (调整表) of liansuo's model: derived by\n"
            "# liansuo.circuits.zpw.adjust.derive_table from the settings above 'rows' (python -m\n"
            "# liansuo.circuits.zpw.adjust rewrites it); docs/zpw2000a.md explains it. Per carrier, cable and\n"
            "# section length (from_m exclusive, to_m inclusive) of each layout (conventional line, passenger-\n"
            "# dedicated line or station): transmitter level (1-5) and the main-track output the receiver is set to\n"
            "# at the layout's design minimum ballast with no train (adjust_mV).\n")
    body = yaml.safe_dump({k: v for k, v in t.as_dict().items() if k != "rows"}, sort_keys=False)
    rows = "".join(f"  - {{layout: {r.layout}, carrier: '{r.carrier}', cable_km: {r.cable_km:g}, "
                   f"from_m: {r.from_m:g}, to_m: {r.to_m:g}, "
                   f"level: {r.level}, adjust_mV: {r.adjust_mV:g}, adjustable: {str(r.adjustable).lower()}}}\n"
                   for r in t.rows)
    path.write_text(head + body + "rows:\n" + rows, encoding="utf-8")


# ---- applying it ---------------------------------------------------------------------------------------------------
def adjusted_params(carrier: str, length_m: float, cable_km: float | None = None, params: ZpwParams = DEFAULT_PARAMS,
                    layout: str = "conventional") -> tuple[ZpwParams, AdjustmentRow]:
    """``params`` with the figures of the layout and the transmitter level and receiver setting of the section's
    row."""
    row = table().row(carrier, length_m, cable_km, layout)
    params = layout_params(layout, carrier, params)
    return dataclasses.replace(params, transmitter_V=params.transmitter_levels_V[row.level - 1],
                               adjust_mV=row.adjust_mV), row


def adjusted_circuit(length_m: float, carrier: str, capacitor_positions_m: Sequence[float] = (),
                     params: ZpwParams = DEFAULT_PARAMS, *, capacitance_uF: float | None = None,
                     cable_km: float | None = None, layout: str = "conventional") -> ZpwCircuit:
    """A ZpwCircuit of a layout (:data:`.model.LAYOUTS`) adjusted by the table, as a maintainer leaves it."""
    p, _ = adjusted_params(carrier, length_m, cable_km, params, layout)
    return ZpwCircuit(length_m, carrier, capacitor_positions_m, p, capacitance_uF=capacitance_uF)


def section_circuit(station: Station, section_id: str, params: ZpwParams = DEFAULT_PARAMS) -> ZpwCircuit:
    """The adjusted ZpwCircuit of a ZPW-2000A section of a station (length, carrier, capacitors from the file)."""
    section = station.sections[section_id]
    if section.type.value != "zpw2000a" or section.carrier is None:
        raise ValueError(f"section {section_id} is not a ZPW-2000A section with a carrier")
    caps = section.capacitors
    length = station.section_run(section_id)  # the main run: a turnout section's branches lie beside it
    return adjusted_circuit(length, section.carrier, capacitor_positions(station, section_id, params, length), params,
                            capacitance_uF=caps.capacitance_uF if caps else None,
                            layout=section_layout(station, section_id))


@dataclass(frozen=True)
class Verdict:
    """A section adjusted by the table, over the design ballast range: what a standard shunt leaves at worst."""

    section: str
    carrier: str
    length_m: float
    level: int
    adjustment_mV: float  # healthy, no train, design minimum ballast
    worst_residual_mV: float  # 0.15 ohm shunt anywhere, healthy and every single capacitor fault, every ballast
    worst_ballast_ohm_km: float
    worst_fault: str
    pickup_mV: float
    drop_mV: float
    ballast_min_ohm_km: float
    min_cab_mA: float = math.inf  # healthy, standard shunt anywhere, design minimum ballast, the row's level
    cab_min_mA: float = 0.0  # the carrier's cab-signal minimum

    @property
    def feeds_cab(self) -> bool:
        """The row's level gives the cab-signal minimum everywhere on the healthy section."""
        return self.min_cab_mA >= self.cab_min_mA

    @property
    def detects(self) -> bool:
        return self.worst_residual_mV <= self.drop_mV

    @property
    def picks_up(self) -> bool:
        return self.adjustment_mV >= self.pickup_mV

    @property
    def ok(self) -> bool:
        return self.detects and self.picks_up


def check_circuit(circuit: ZpwCircuit, section: str = "", layout: str = "conventional") -> Verdict:
    """Sweep an adjusted circuit over the design ballast range of its layout (from the design minimum its
    parameters hold to dry) with every single capacitor fault."""
    t, p = table(), circuit.params
    low = p.ballast_ohm_km
    per_mV, ballast, _, fault, _ = _per_mV(circuit.length_m, [circuit.carrier], t.ballasts(low), p,
                                           circuit.capacitors_m, circuit.capacitance_uF)
    adjust = circuit.adjustment(ZpwFaults(ballast_ohm_km=low)).voltage_mV
    row = t.row(circuit.carrier, circuit.length_m, layout=layout)
    cab = circuit.min_cab_current_mA(ZpwFaults(ballast_ohm_km=low))
    return Verdict(section, circuit.carrier, circuit.length_m, row.level, adjust, per_mV * adjust, ballast, fault,
                   p.pickup_mV, p.drop_mV, low, cab, circuit.cab_min_mA)


def station_verdicts(station: Station) -> list[Verdict]:
    """Every ZPW-2000A section of a station, adjusted by the table and swept."""
    return [check_circuit(section_circuit(station, s.id), s.id, section_layout(station, s.id))
            for s in station.model.sections if s.type.value == "zpw2000a" and s.carrier is not None]


def _ohm_km(b: float) -> str:
    return "dry ballast (infinite resistance)" if math.isinf(b) else f"{b:g} ohm*km"


def station_warnings(station: Station) -> list[Diagnostic]:
    """``liansuo check``'s warnings for the ZPW-2000A sections the adjustment table cannot adjust safely."""
    from liansuo.kit.source import Diagnostic

    out = []
    src = station.source
    for v in station_verdicts(station):
        loc = ("sections", next(i for i, s in enumerate(station.model.sections) if s.id == v.section))
        if not v.feeds_cab:
            message = (f"ZPW-2000A section '{v.section}' ({v.carrier}, {v.length_m:g} m) is longer than its "
                       f"transmitter feeds: at level {v.level} a 0.15 ohm shunt reads {v.min_cab_mA:.0f} mA "
                       f"(cab-signal minimum {v.cab_min_mA:g} mA) at {v.ballast_min_ohm_km:g} ohm*km: the cab may "
                       "lose the code")
            hint = "shorten the section (split it with an electrical joint)"
            out.append(Diagnostic("<station>", 1, 1, message, hint, "warning") if src is None
                       else src.diagnostic(loc, message, hint, severity="warning"))
        if v.ok:
            continue
        message = (f"ZPW-2000A section '{v.section}' ({v.carrier}, {v.length_m:g} m) cannot be adjusted over the "
                   f"design ballast range: set to {v.adjustment_mV:.0f} mV at {v.ballast_min_ohm_km:g} ohm*km "
                   f"(pick-up {v.pickup_mV:g} mV), a 0.15 ohm shunt leaves up to {v.worst_residual_mV:.0f} mV "
                   f"(drop {v.drop_mV:g} mV) in {_ohm_km(v.worst_ballast_ohm_km)} with "
                   f"{'no fault' if v.worst_fault == 'none' else v.worst_fault}: a standard-shunted train may be "
                   "undetected")
        if not v.picks_up:
            message += "; the relay does not pick up at the design minimum ballast"
        hint = "shorten the section (split it with an electrical joint) or check its capacitors"
        out.append(Diagnostic("<station>", 1, 1, message, hint, "warning") if src is None
                   else src.diagnostic(loc, message, hint, severity="warning"))
    return out


if __name__ == "__main__":
    write_table()
