"""The guide aspect without a route (引导信号 under 引导总锁闭): a home signal's guide aspect over a throat whose
turnouts are all locked by the guide total lock, given by the operator and kept each cycle until the guided train
has entered, or closed when it is not used in time or a lamp it needs goes dark."""

from __future__ import annotations

from liansuo.interlocking.aspects import stop_aspect
from liansuo.interlocking.core import Core
from liansuo.interlocking.state import GuideOnly


class ThroatGuide:
    """The guide aspects without a route of one interlocking ``core`` (``core.guide_only``)."""

    def __init__(self, core: Core) -> None:
        self.core = core

    def open(self, signal: str) -> None:
        core = self.core
        core.guide_only[signal] = GuideOnly(core.now)
        guide = core.rules.aspects.guide
        core.out.set_aspect(signal, guide)
        core.event("signal", f"guide aspect {guide} on {signal} under guide total lock")

    def close(self, signal: str, alarm: str = "") -> None:
        core = self.core
        del core.guide_only[signal]
        core.out.set_aspect(signal, stop_aspect(core.station, signal))
        if alarm:
            core.alarm("closed", signal, f"signal {signal} closed: {alarm}")

    def cycle(self) -> None:
        core = self.core
        for sig, g in list(core.guide_only.items()):
            occupied = any(not core.clear(s) for s in core.station.approach_sections(sig))
            if occupied:
                g.approach_seen = True
            entered = not core.clear(core.entry_section[sig])
            if entered or (not occupied and g.approach_seen) or (
                    not g.approach_seen and core.now - g.since > core.rules.guide_close_s):
                self.close(sig)
                core.event("signal", f"guide aspect of {sig} closed")
            elif not core.board.lamp_ok(sig, stop_aspect(core.station, sig)):
                self.close(sig, "red lamp dark, the guide aspect needs it lit")
            elif core.proven(sig, core.rules.aspects.guide) != core.rules.aspects.guide:
                self.close(sig, f"a lamp of the guide aspect {core.rules.aspects.guide} is dark")
            elif doors := core.doors_blocker(core.guide_only_doors(sig)):
                self.close(sig, doors)
