"""``liansuo zpw STATION --plot FILE [--plot-csv FILE] [--section ID]``: the profiles along one ZPW-2000A section,
healthy and with compensation-capacitor faults, as rows (CSV) and as a figure (matplotlib, the ``plot`` extra).

A profile puts the standard shunt (0.15 ohm) at each point along the section in turn, every ``profile_step_m``
(10 m) from the lower end to the upper end, and reads two things of the model (:meth:`.ZpwCircuit.profile`): the
main-track output at the receiver (主轨出, mV: the shunt residual the track relay sees) and the rail current through
the shunt (mA: the cab-signal current a leading wheelset there receives). The no-train adjustment of each case is in
the legend and the CSV. What is plotted is described in docs/zpw2000a.md, "Plots".
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from liansuo.circuits.zpw.figures import FaultSpecError, collect_faults, parse_fault, zpw_sections
from liansuo.kit.plotfiles import new_figure, save_figure
from liansuo.stations.station import Station

COLUMNS = ("section", "case", "position_m", "shunt_residual_mV", "cab_current_mA", "adjustment_mV")
DEFAULT_ALL_UP_TO = 8  # with no --fault, every single open capacitor up to this many, else the worst few
WORST_FEW = 3


@dataclass(frozen=True)
class Profile:
    """One case along the section: positions from the lower end (m), residual (mV), cab current (mA)."""

    case: str  # "healthy" or e.g. "C3 open"
    capacitors: dict[int, str]
    adjustment_mV: float
    positions_m: list[float]
    residual_mV: list[float]
    cab_mA: list[float]


def plotted_section(station: Station, section: str | None, faults: Sequence[str]) -> str:
    """The section to plot: ``--section``, else the one the faults name, else the first ZPW-2000A section."""
    zpw = zpw_sections(station)
    if section is not None:
        if section not in station.sections:
            raise FaultSpecError(f"--section {section}: {station.id} has no section '{section}'")
        if section not in zpw:
            raise FaultSpecError(f"--section {section}: not a ZPW-2000A section (those are {', '.join(zpw) or 'none'})")
        return section
    named = list(dict.fromkeys(parse_fault(f)[0] for f in faults))
    if len(named) > 1:
        raise FaultSpecError(f"the faults name sections {', '.join(named)}: plot one, with --section")
    if named:
        return named[0]
    if not zpw:
        raise FaultSpecError(f"{station.id} has no ZPW-2000A section to plot")
    return zpw[0]


def fault_cases(station: Station, section: str, faults: Sequence[str]) -> list[dict[int, str]]:
    """Each ``--fault`` on its own (every one checked; one on another section is refused); with none, each single
    open capacitor, or the worst few of them when the section has more than :data:`DEFAULT_ALL_UP_TO`."""
    collect_faults(station, faults)  # every spec checked against the station
    cases = []
    for text in faults:
        where, number, mode = parse_fault(text)
        if where != section:
            raise FaultSpecError(f"--fault '{text}': the plot is of section {section}; give faults on it only")
        if {number: mode} not in cases:
            cases.append({number: mode})
    if faults:
        return cases
    from liansuo.circuits.zpw.adjust import section_circuit

    circuit = section_circuit(station, section)
    opens = [{k: "open"} for k in range(1, len(circuit.capacitors_m) + 1)]
    if len(opens) <= DEFAULT_ALL_UP_TO:
        return opens
    worst = _worst(circuit, opens)
    return sorted(worst, key=lambda case: next(iter(case)))


def _worst(circuit: Any, cases: list[dict[int, str]]) -> list[dict[int, str]]:
    """The cases that raise the shunt residual most, then those that lower the cab current most (up to
    :data:`WORST_FEW` each)."""
    from liansuo.circuits.zpw.model import ZpwFaults

    figures = []
    for case in cases:
        _, residual, cab = circuit.profile(ZpwFaults(capacitors=case))
        figures.append((float(residual.max()), float(cab.min()), case))
    by_residual = sorted(figures, key=lambda f: -f[0])[:WORST_FEW]
    by_cab = sorted(figures, key=lambda f: f[1])[:WORST_FEW]
    chosen: list[dict[int, str]] = []
    for _, _, case in [*by_residual, *by_cab]:
        if case not in chosen:
            chosen.append(case)
    return chosen


def profiles(station: Station, section: str, cases: Sequence[dict[int, str]]) -> list[Profile]:
    """The healthy profile, then one per fault case."""
    from liansuo.circuits.zpw.adjust import section_circuit
    from liansuo.circuits.zpw.model import ZpwFaults
    from liansuo.circuits.zpw.sweep import fault_label

    circuit = section_circuit(station, section)
    out = []
    for case in [{}, *cases]:
        f = ZpwFaults(capacitors=dict(case))
        pos, residual, cab = circuit.profile(f)
        out.append(Profile(fault_label(case) if case else "healthy", dict(case), circuit.adjustment(f).voltage_mV,
                           [float(x) for x in pos], [float(v) for v in residual], [float(i) for i in cab]))
    return out


def rows(section: str, profs: Sequence[Profile]) -> list[dict[str, object]]:
    """One CSV row per case and position, the columns of :data:`COLUMNS`."""
    return [{"section": section, "case": p.case, "position_m": round(x, 2), "shunt_residual_mV": round(v, 3),
             "cab_current_mA": round(i, 3), "adjustment_mV": round(p.adjustment_mV, 3)}
            for p in profs for x, v, i in zip(p.positions_m, p.residual_mV, p.cab_mA, strict=True)]


def draw(station: Station, section: str, profs: Sequence[Profile], path: str) -> str:
    """The figure: residual over cab current, one line per case, the relay's levels and the cab minimum; '' or why
    it could not be written."""
    from liansuo.circuits.zpw.adjust import section_circuit
    from liansuo.circuits.zpw.params import DEFAULT_PARAMS as P

    circuit = section_circuit(station, section)
    fig, (top, bottom) = new_figure(2, 1, sharex=True)
    for n, p in enumerate(profs):
        style: dict[str, Any] = ({"color": "black", "linewidth": 2.0, "zorder": 3} if n == 0
                                 else {"linewidth": 1.1, "color": f"C{(n - 1) % 10}"})
        label = f"{p.case} (no train {p.adjustment_mV:.0f} mV)"
        top.plot(p.positions_m, p.residual_mV, label=label, **style)
        bottom.plot(p.positions_m, p.cab_mA, label=p.case, **style)
    top.axhline(P.pickup_mV, color="tab:green", linestyle="--", linewidth=1)
    top.axhline(P.drop_mV, color="tab:red", linestyle="--", linewidth=1)
    top.text(0.005, P.pickup_mV, f" pick-up {P.pickup_mV:g} mV", color="tab:green", va="bottom", fontsize=8,
             transform=top.get_yaxis_transform())
    top.text(0.005, P.drop_mV, f" drop {P.drop_mV:g} mV", color="tab:red", va="bottom", fontsize=8,
             transform=top.get_yaxis_transform())
    top.set_ylim(0, max(P.pickup_mV * 1.15, max(max(p.residual_mV) for p in profs) * 1.1))
    top.set_ylabel("receiver output (mV)")
    top.set_title(f"{station.id} {section}: ZPW-2000A {circuit.carrier}, {circuit.length_m:g} m, "
                  f"{P.standard_shunt_ohm:g} ohm shunt at each point, ballast {circuit.params.ballast_ohm_km:g} ohm*km",
                  fontsize=10)
    top.legend(fontsize=7, loc="upper right", ncol=2)
    bottom.axhline(circuit.cab_min_mA, color="tab:red", linestyle="--", linewidth=1)
    bottom.text(0.995, circuit.cab_min_mA, f"cab minimum {circuit.cab_min_mA:g} mA ", color="tab:red", va="bottom",
                ha="right", fontsize=8, transform=bottom.get_yaxis_transform())
    bottom.set_ylim(0, max(max(p.cab_mA) for p in profs) * 1.1)
    bottom.set_ylabel("cab-signal current (mA)")
    rx, tx = ("receiver", "transmitter") if circuit.transmitter_end == "upper" else ("transmitter", "receiver")
    bottom.set_xlabel(f"shunt position from the lower end (m): {rx} at 0, {tx} at {circuit.length_m:g}")
    for x in circuit.capacitors_m:
        for ax in (top, bottom):
            ax.axvline(x, color="0.85", linewidth=0.6, zorder=0)
    bottom.set_xlim(0, circuit.length_m)
    return save_figure(fig, path)
