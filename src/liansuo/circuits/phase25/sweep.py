"""A 25 Hz phase-sensitive section against ballast resistance: the track-coil voltage and phase with no train, the
relay's torque component, and the worst shunt residual, as the live simulation builds the section (its length, the
feed tap a maintainer sets, :func:`.trackcircuits.build_circuit`). Rows for ``liansuo 25hz`` (:mod:`.cli`),
its CSV and its figure; docs/track-circuits-25hz.md, "Against ballast".
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from liansuo.circuits.phase25.model import Phase25HzCircuit, Phase25HzFaults
from liansuo.circuits.trackcircuits import build_circuit
from liansuo.kit.fit import fit_all
from liansuo.kit.plotfiles import new_figure, save_figure
from liansuo.stations.station import Station

COLUMNS = ("section", "ballast_ohm_km", "voltage_V", "phase_deg", "phase_error_deg", "effective_V", "relay",
           "max_residual_V")
PER_DECADE = 12
LOWEST_OHM_KM, HIGHEST_OHM_KM = 0.1, 100.0
TEXT_POINTS = (0.1, 0.2, 0.3, 0.5, 0.6, 1.0, 2.0, 3.0, 5.0, 10.0, 20.0, 50.0, 100.0)  # the text report's rows
RESIDUAL_POINTS = 61  # shunt positions for the worst residual, both ends included


class SectionChoiceError(ValueError):
    """--section names no 25 Hz section of the station; the message is one line."""


def phase25_sections(station: Station) -> list[str]:
    return [s.id for s in station.model.sections if s.type.value == "25hz"]


def check_section(station: Station, section: str) -> None:
    if section not in station.sections:
        raise SectionChoiceError(f"--section {section}: {station.id} has no section '{section}'")
    if section not in phase25_sections(station):
        kinds = ", ".join(phase25_sections(station)[:8]) or "none"
        raise SectionChoiceError(f"--section {section}: not a 25 Hz section (those are {kinds}; ZPW-2000A sections: "
                                 "liansuo zpw)")


def section_model(station: Station, section: str) -> Phase25HzCircuit:
    """The section's circuit exactly as the simulation's field builds it (its main run along the line)."""
    model = build_circuit(station, section, max(station.section_span(section), 1.0)).model
    assert isinstance(model, Phase25HzCircuit)
    return model


def ballast_points(per_decade: int = PER_DECADE) -> list[float]:
    """Ballast resistances from :data:`LOWEST_OHM_KM` to :data:`HIGHEST_OHM_KM`, evenly on a log scale, with the
    text report's points among them."""
    decades = round(math.log10(HIGHEST_OHM_KM / LOWEST_OHM_KM) * per_decade)
    grid = {round(LOWEST_OHM_KM * 10 ** (k / per_decade), 6) for k in range(decades + 1)}
    return sorted(grid | set(TEXT_POINTS))


@dataclass(frozen=True)
class BallastPoint:
    ballast_ohm_km: float
    voltage_V: float
    phase_deg: float
    phase_error_deg: float
    effective_V: float
    relay: str  # up (picks up), holds (an up relay stays up, a dropped one stays down), down
    max_residual_V: float


def sweep(model: Phase25HzCircuit, ballasts: Sequence[float]) -> list[BallastPoint]:
    out = []
    for b in ballasts:
        faults = Phase25HzFaults(ballast_ohm_km=b)
        s = model.adjustment(faults)
        relay = "up" if s.relay_up else ("holds" if s.relay_up_after(True) else "down")
        out.append(BallastPoint(b, s.voltage_V, s.phase_deg, s.phase_error_deg, s.effective_V, relay,
                                model.max_residual_V(points=RESIDUAL_POINTS, faults=faults)))
    return out


def rows(section: str, points: Sequence[BallastPoint]) -> list[dict[str, Any]]:
    return [{"section": section, "ballast_ohm_km": p.ballast_ohm_km, "voltage_V": round(p.voltage_V, 4),
             "phase_deg": round(p.phase_deg, 3), "phase_error_deg": round(p.phase_error_deg, 3),
             "effective_V": round(p.effective_V, 4), "relay": p.relay, "max_residual_V": round(p.max_residual_V, 4)}
            for p in points]


def as_text(station: Station, section: str, model: Phase25HzCircuit, points: Sequence[BallastPoint]) -> str:
    p = model.params
    lines = [f"{station.display_name()} {section}: 25 Hz phase-sensitive, {model.length_m:g} m, feed tap "
             f"{p.feed_tap_V:g} V (set at the design ballast {p.ballast_ohm_km:g} ohm*km); pick-up {p.pickup_V:g} V "
             f"within +-{p.phase_window_deg:g} deg, drop {p.drop_V:g} V; residual limit {p.residual_max_V:g} V with "
             f"{p.standard_shunt_ohm:g} ohm",
             f"{'ballast':>9}{'track_V':>9}{'phase':>8}{'error':>7}{'torque_V':>10}{'relay':>7}{'max_resid_V':>13}"]
    for q in points:
        lines.append(f"{q.ballast_ohm_km:>9g}{q.voltage_V:>9.2f}{q.phase_deg:>8.1f}{q.phase_error_deg:>7.1f}"
                     f"{q.effective_V:>10.2f}{q.relay:>7}{q.max_residual_V:>13.2f}")
    lines.append("ballast in ohm*km; phase: track coil against the local coil (ideal -90 deg); torque_V: the component "
                 "in the ideal phase; relay: holds = under pick-up, an up relay stays up")
    return fit_all(lines)


def draw(station: Station, section: str, model: Phase25HzCircuit, points: Sequence[BallastPoint], path: str) -> str:
    """Voltages over phase against ballast (log scale), with the relay's levels; '' or why it was not written."""
    p = model.params
    fig, (top, bottom) = new_figure(2, 1, sharex=True)
    x = [q.ballast_ohm_km for q in points]
    top.plot(x, [q.voltage_V for q in points], color="black", linewidth=2, label="track coil, no train")
    top.plot(x, [q.effective_V for q in points], color="tab:blue", linewidth=1.2,
             label="in the ideal phase (torque), no train")
    top.plot(x, [q.max_residual_V for q in points], color="tab:purple", linewidth=1.2,
             label=f"worst residual, {p.standard_shunt_ohm:g} ohm shunt")
    levels = ((p.pickup_V, "tab:green", f"pick-up {p.pickup_V:g} V", "bottom"),
              (p.drop_V, "tab:red", f"drop {p.drop_V:g} V", "bottom"),
              (p.residual_max_V, "tab:purple", f"residual limit {p.residual_max_V:g} V", "top"))
    for level, colour, text, side in levels:
        top.axhline(level, color=colour, linestyle="--", linewidth=1)
        top.text(0.995, level, f"{text} ", color=colour, va=side, ha="right", fontsize=8,
                 transform=top.get_yaxis_transform())
    top.set_ylim(0, max(q.voltage_V for q in points) * 1.45)  # room for the legend above the curves
    top.set_ylabel("track-coil voltage (V)")
    top.set_title(f"{station.id} {section}: 25 Hz phase-sensitive, {model.length_m:g} m, feed tap {p.feed_tap_V:g} V "
                  f"set at {p.ballast_ohm_km:g} ohm*km", fontsize=10)
    top.legend(fontsize=7, loc="upper right", ncol=3)
    bottom.plot(x, [q.phase_deg for q in points], color="black", linewidth=2, label="track coil against local coil")
    ideal = -p.ideal_lag_deg
    bottom.axhline(ideal, color="tab:green", linestyle="--", linewidth=1, label=f"ideal {ideal:g} deg")
    bottom.axhspan(ideal - p.phase_window_deg, ideal + p.phase_window_deg, color="tab:green", alpha=0.1,
                   label=f"pick-up window +-{p.phase_window_deg:g} deg")
    bottom.set_ylabel("phase (deg)")
    bottom.set_xlabel("ballast resistance (ohm*km, log scale)")
    for ax in (top, bottom):
        ax.set_xscale("log")
        ax.axvline(p.ballast_ohm_km, color="0.6", linewidth=0.8, linestyle=":",
                   label=f"design ballast {p.ballast_ohm_km:g} ohm*km")
    bottom.legend(fontsize=7, loc="lower right")
    bottom.set_xlim(x[0], x[-1])
    return save_figure(fig, path)
