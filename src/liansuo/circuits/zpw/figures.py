"""The ZPW-2000A figures of a station's sections (adjustment, worst shunt residual, minimum cab current), optionally
with compensation-capacitor faults, as rows, text and CSV: what ``liansuo zpw`` prints (:mod:`.cli`). The model
is :mod:`.model`; see docs/zpw2000a.md."""

from __future__ import annotations

import csv
from collections.abc import Sequence
from typing import Any, TextIO

from liansuo.kit.fit import fit_all
from liansuo.stations.station import Station

COLUMNS = ("id", "carrier", "length_m", "capacitors", "adjustment_mV", "max_shunt_residual_mV",
           "min_cab_current_mA", "cab_min_mA", "relay", "fault")
MODES = ("open", "half", "short")
FAULT_FORM = "SECTION:capacitor:N:open|half|short"


class FaultSpecError(ValueError):
    """A --fault argument that cannot be applied; the message is one line."""


def parse_fault(text: str) -> tuple[str, int, str]:
    """``'X2JG:capacitor:3:open'`` -> ('X2JG', 3, 'open')."""
    parts = text.split(":")
    if len(parts) != 4 or parts[1].lower() != "capacitor":
        raise FaultSpecError(f"--fault '{text}': write {FAULT_FORM}, e.g. X2JG:capacitor:3:open")
    section, _, number, mode = parts
    if not number.isdigit() or int(number) < 1:
        raise FaultSpecError(f"--fault '{text}': the capacitor number must be a whole number from 1")
    if mode.lower() not in MODES:
        raise FaultSpecError(f"--fault '{text}': the fault is open, half or short, not '{mode}'")
    return section, int(number), mode.lower()


def zpw_sections(station: Station) -> list[str]:
    return [s.id for s in station.model.sections if s.type.value == "zpw2000a" and s.carrier is not None]


def collect_faults(station: Station, specs: Sequence[str]) -> dict[str, dict[int, str]]:
    """Every --fault, checked against the station: section -> {capacitor number: mode}."""
    from liansuo.circuits.zpw.model import (
        capacitor_positions,  # numpy loads when figures are asked for, not with the command line
    )

    zpw = set(zpw_sections(station))
    out: dict[str, dict[int, str]] = {}
    for text in specs:
        section, number, mode = parse_fault(text)
        if section not in station.sections:
            raise FaultSpecError(f"--fault '{text}': {station.id} has no section '{section}'")
        if section not in zpw:
            raise FaultSpecError(f"--fault '{text}': section {section} is not a ZPW-2000A section")
        count = len(capacitor_positions(station, section))
        if number > count:
            have = f"capacitors 1-{count}" if count else "no compensation capacitors"
            raise FaultSpecError(f"--fault '{text}': section {section} has {have}")
        out.setdefault(section, {})[number] = mode
    return out


def section_rows(station: Station, faults: dict[str, dict[int, str]] | None = None) -> list[dict[str, Any]]:
    """One row per ZPW-2000A section, in file order, with the fault applied where one is given."""
    from liansuo.circuits.zpw.adjust import section_circuit
    from liansuo.circuits.zpw.model import ZpwFaults
    from liansuo.circuits.zpw.sweep import fault_label

    rows = []
    for sid in zpw_sections(station):
        circuit = section_circuit(station, sid)
        case = (faults or {}).get(sid, {})
        f = ZpwFaults(capacitors=dict(case))
        adjustment = circuit.adjustment(f)
        _, residual, cab = circuit.profile(f)
        relay = "up" if adjustment.relay_up else ("marginal" if adjustment.relay_up_after(True) else "down")
        row: dict[str, Any] = {
            "id": sid, "carrier": circuit.carrier, "length_m": round(circuit.length_m, 1),
            "ballast_ohm_km": circuit.params.ballast_ohm_km,
            "capacitors": len(circuit.capacitors_m), "adjustment_mV": round(adjustment.voltage_mV, 1),
            "max_shunt_residual_mV": round(float(residual.max()), 1),
            "min_cab_current_mA": round(float(cab.min()), 1), "cab_min_mA": circuit.cab_min_mA, "relay": relay,
            "fault": fault_label(case) if case else None,
        }
        if case:
            _, residual0, cab0 = circuit.profile()
            row["healthy"] = {"adjustment_mV": round(circuit.adjustment().voltage_mV, 1),
                              "max_shunt_residual_mV": round(float(residual0.max()), 1),
                              "min_cab_current_mA": round(float(cab0.min()), 1)}
        rows.append(row)
    return rows


def _line(values: Sequence[object], widths: Sequence[int]) -> str:
    return "".join(f"{v!s:>{w}}" if w else f"  {v}" for v, w in zip(values, widths, strict=True)).rstrip()


def as_text(station: Station, rows: list[dict[str, Any]]) -> str:
    from liansuo.circuits.zpw.params import DEFAULT_PARAMS as P

    if not rows:
        return f"{station.id} has no ZPW-2000A sections"
    widths = (9, 8, 9, 5, 10, 13, 11, 9, 0)
    ballasts = "/".join(f"{b:g}" for b in sorted({r["ballast_ohm_km"] for r in rows}))
    lines = [f"{station.display_name()}: ZPW-2000A sections ({P.standard_shunt_ohm:g} ohm shunt, ballast "
             f"{ballasts} ohm*km (each section's design minimum); relay pick-up {P.pickup_mV:g} mV, drop "
             f"{P.drop_mV:g} mV)",
             _line(("id", "carrier", "length_m", "caps", "adjust_mV", "max_resid_mV", "min_cab_mA", "relay", "fault"),
                   widths)]
    for r in rows:
        low = "*" if r["min_cab_current_mA"] < r["cab_min_mA"] else ""
        lines.append(_line((r["id"], r["carrier"], f"{r['length_m']:.1f}", r["capacitors"],
                            f"{r['adjustment_mV']:.1f}", f"{r['max_shunt_residual_mV']:.1f}",
                            f"{r['min_cab_current_mA']:.0f}{low}", r["relay"], r["fault"] or ""), widths))
    if any(r["min_cab_current_mA"] < r["cab_min_mA"] for r in rows):
        lines.append(f"* under the cab-signal minimum ({P.cab_min_mA[0]:g} mA; {P.cab_min_mA[3]:g} mA at 2600 Hz)")
    if any(r["relay"] != "up" for r in rows):
        lines.append(f"relay: marginal = under the {P.pickup_mV:g} mV pick-up (an up relay holds, a dropped one "
                     "stays down); down = red band")
    return fit_all(lines)


def write_csv(out: TextIO, rows: list[dict[str, Any]]) -> None:
    """The rows as CSV, one line a section, the columns of :data:`COLUMNS`."""
    writer = csv.DictWriter(out, fieldnames=COLUMNS, extrasaction="ignore")
    writer.writeheader()
    for r in rows:
        writer.writerow({**r, "fault": r["fault"] or ""})
