"""Platform stop with door linkage (Xu Yue et al., docs/references.md): train doors and platform screen doors open and
close together.

Once the train has stopped in the stopping window, the door-open permission for the platform side is given and the
open command goes to the screen doors through the interlocking (KMJ with ZCKJ); after the dwell both close (GMJ);
the train may leave only when the screen doors are proven closed and locked (PDKJ) or bypassed (PDQCJ), and the
starting signal (which checks the same) is open.
"""

from __future__ import annotations

from liansuo.simulation.trains.lineside import Lineside


def platform_doors(sim: Lineside) -> None:
    rules = sim.rules.driving
    for tr in sim.fleet.trains.values():
        ps = tr.platform_stop
        if ps is None:
            continue
        if ps.state == "stopped":
            result = sim.doors(ps.platform, "open")
            if result.ok:
                tr.train_doors_open = True
                ps.state = "doors_open"
                ps.until = sim.t + rules.platform_dwell_s
                sim.log("train", f"train {tr.name}: train doors and screen doors of {ps.platform} opening")
            else:
                sim.log("train", f"train {tr.name}: doors stay closed: {result.message}")
                ps.state = "closing"
        elif ps.state == "doors_open" and sim.t >= ps.until:
            sim.doors(ps.platform, "close")
            tr.train_doors_open = False
            ps.state = "closing"
            sim.log("train", f"train {tr.name}: doors closing at {ps.platform}")
        elif ps.state == "closing" and all(sim.view.doors_safe(k) for k in ps.door_keys):
            ps.state = "done"
            sim.log("train", f"train {tr.name}: doors closed and locked at {ps.platform}; ready to depart")
