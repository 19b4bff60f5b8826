"""What the element under the keyboard cursor is, in a signaller's words, for the answer line: ``X 进站信号机 列车按钮
train button L``, ``道岔 turnout 5 at normal (定位)``, ``区段 section IG: free``. Read through the query API
(``sim.view``), as the diagram is painted.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from liansuo.tui.grid import Ref

if TYPE_CHECKING:
    from liansuo.tui.consolesim import ConsoleSim

SIGNAL_KIND = {"home": "进站信号机 home signal", "starting": "出站信号机 starting signal",
               "route": "进路信号机 route signal", "shunting": "调车信号机 shunting signal",
               "block": "通过信号机 block signal"}
BUTTON_KIND = {"train": "列车按钮 train button L", "shunt": "调车按钮 shunting button D",
               "end": "终端按钮 end button", "exit": "发车按钮 departure button", "variant": "变通按钮 variant button"}
POSITION = {"normal": "at normal (定位)", "reverse": "at reverse (反位)", None: "without indication (无表示)"}
MARK = {"locked": ", single-locked (单锁)", "blocked": ", single-blocked (单封)",
        "guide": ", guide total lock (引导总锁)"}


def describe(sim: ConsoleSim, ref: Ref) -> str:
    """The element ``ref`` with its state, as the answer line names it."""
    st = sim.station
    if ref.kind == "signal" and ref.id in st.signals:
        aspect = sim.view.aspect(ref.id)
        return f"{ref.id} {SIGNAL_KIND.get(st.signals[ref.id].kind.value, '信号机 signal')}: {aspect or 'dark'}"
    if ref.kind == "button":
        if ref.id in st.signals:
            return f"{ref.id} {SIGNAL_KIND.get(st.signals[ref.id].kind.value, '信号机 signal')} " \
                   f"{BUTTON_KIND.get(ref.sub, '按钮 button')}"
        return f"{ref.id} {BUTTON_KIND.get(ref.sub, '按钮 button')}"
    if ref.kind == "turnout" and ref.id in st.turnouts:
        t = sim.view.turnout(ref.id)
        moving = ", moving" if t.moving else ""
        return f"道岔 turnout {ref.id} {POSITION[t.position]}{MARK.get(t.mark, '')}{moving}"
    if ref.kind == "section" and ref.id in st.sections:
        return f"区段 section {ref.id}: {sim.view.section(ref.id).state}"
    if ref.kind == "platform":
        return f"站台 platform {ref.id}: screen doors {ref.sub}"
    return f"{ref.kind} {ref.id}"
