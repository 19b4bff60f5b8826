"""``liansuo run SCENARIO --plot FILE [--plot-csv FILE]``: where every train's head was and how fast it ran, every
cycle of the run, as rows (CSV) and as time-distance and speed-distance plots (matplotlib, the ``plot`` extra).

:class:`TrainTrace` wraps the simulation's ``step`` on that instance, as the oracle's watch does, and reads the query
API's train views (:meth:`~liansuo.simulation.world.World.train_views`) after every cycle: the head's position along
the line (the station's running coordinate, metres) and its speed. docs/trains.md, "Plots".
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from liansuo.kit.plotfiles import new_figure, save_figure
from liansuo.simulation.sim import Simulation

COLUMNS = ("t_s", "train", "head_track", "head_m", "speed_kmh", "direction", "state")


@dataclass
class TrainTrace:
    """Every train's head and speed after every cycle; ``rows`` in time order, one per train and cycle."""

    rows: list[dict[str, Any]] = field(default_factory=list)

    def attach(self, sim: Simulation) -> None:
        """Record after every cycle of ``sim`` from now on."""
        step = sim.step

        def traced_step() -> None:
            step()
            self.record(sim)

        sim.step = traced_step  # type: ignore[method-assign]

    def record(self, sim: Simulation) -> None:
        for v in sim.train_views():
            self.rows.append({"t_s": round(sim.t, 3), "train": v.name, "head_track": v.head_track or "",
                              "head_m": "" if v.head_m is None else v.head_m, "speed_kmh": v.speed_kmh,
                              "direction": v.direction, "state": v.state})

    def trains(self) -> list[str]:
        return list(dict.fromkeys(r["train"] for r in self.rows))


def draw(trace: TrainTrace, title: str, path: str) -> str:
    """Time-distance (left) and speed-distance (right), one colour a train; '' or why it could not be written."""
    fig, (td, sd) = new_figure(1, 2)
    for n, name in enumerate(trace.trains()):
        mine = [r for r in trace.rows if r["train"] == name]
        t = [r["t_s"] for r in mine]
        x = [math.nan if r["head_m"] == "" else r["head_m"] for r in mine]  # a gap once the head has left
        v = [r["speed_kmh"] for r in mine]
        td.plot(t, x, color=f"C{n % 10}", linewidth=1.5, label=name)
        sd.plot(x, v, color=f"C{n % 10}", linewidth=1.5, label=name)
    td.set_title("time-distance", fontsize=10)
    td.set_xlabel("time (s)")
    td.set_ylabel("head position along the line (m)")
    sd.set_title("speed-distance", fontsize=10)
    sd.set_xlabel("head position along the line (m)")
    sd.set_ylabel("speed (km/h)")
    sd.set_ylim(bottom=0)
    for ax in (td, sd):
        ax.grid(True, color="0.9")
        if trace.rows:
            ax.legend(fontsize=8, loc="best")
    fig.suptitle(title, fontsize=10)
    return save_figure(fig, path)
