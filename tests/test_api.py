"""The Python API as its users expect it: a refused Result is false, a query about an id the station does not have
raises a KeyError that names the kind, the id and the closest ids, a train that has left says so, and the package
is typed (py.typed)."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

import liansuo
from liansuo import Simulation, UnknownId

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def sim() -> Simulation:
    return Simulation("jiaopei")


def test_a_result_is_true_when_accepted_and_false_when_refused() -> None:
    sim = Simulation("jiaopei")
    refused = sim.command("route X XY")
    assert not refused and refused.ok is False and "XY" in refused.message
    accepted = sim.command("route X XI")
    assert accepted and accepted.ok is True
    assert not sim.command("route S SI")  # conflicts with X-XI
    assert sim.command("expect route X XI setting") and not sim.command("expect route X XI open")


# (what is asked, the id, its kind, a close match the error must suggest or None)
QUERIES: list[tuple[str, Callable[[Simulation, str], Any], str, str, str | None]] = [
    ("aspect", lambda s, i: s.aspect(i), "NOSUCH", "signal", None),
    ("aspect, wrong case", lambda s, i: s.aspect(i), "xi", "signal", "XI"),
    ("route_state", lambda s, i: s.route_state(i), "NOPE", "route", None),
    ("route_state, a typo", lambda s, i: s.route_state(i), "X-X1", "route", "X-XI"),
    ("section_state", lambda s, i: s.section_state(i), "ZZ", "section", None),
    ("section_state, wrong case", lambda s, i: s.section_state(i), "1dg", "section", "1DG"),
    ("turnout_state", lambda s, i: s.turnout_state(i), "99", "turnout", None),
    ("turnout_mark", lambda s, i: s.turnout_mark(i), "77", "turnout", "7"),
    ("turnout_locked", lambda s, i: s.turnout_locked(i), "99", "turnout", None),
    ("line_outbound", lambda s, i: s.line_outbound(i), "SLL", "line", "SL"),
    ("train_view", lambda s, i: s.train_view(i), "T9", "train", None),
    ("view.signal", lambda s, i: s.view.signal(i), "XX", "signal", "X"),
    ("view.route", lambda s, i: s.view.route(i), "X-XII", "route", "X-XI"),
    ("view.route_of", lambda s, i: s.view.route_of(i), "NOSUCH", "signal", None),
    ("view.turnout", lambda s, i: s.view.turnout(i), "99", "turnout", None),
    ("view.section", lambda s, i: s.view.section(i), "IGG", "section", "IG"),
    ("view.sections", lambda s, i: s.view.sections(["IG", i]), "ZZ", "section", None),
    ("view.cab_code", lambda s, i: s.view.cab_code(i), "ZZ", "section", None),
    ("view.block_line", lambda s, i: s.view.block_line(i), "ZL", "line", None),
    ("view.doors_safe", lambda s, i: s.view.doors_safe(i), "nowhere:left", "platform door", None),
]


@pytest.mark.parametrize(("what", "ask", "id", "kind", "match"), QUERIES, ids=[q[0] for q in QUERIES])
def test_an_unknown_id_raises_a_key_error_naming_kind_id_and_close_matches(
        sim: Simulation, what: str, ask: Callable[[Simulation, str], Any], id: str, kind: str,
        match: str | None) -> None:
    with pytest.raises(KeyError) as caught:
        ask(sim, id)
    exc = caught.value
    assert isinstance(exc, UnknownId) and (exc.kind, exc.id) == (kind, id)
    text = str(exc)
    assert text.startswith(f"station jiaopei has no {kind} '{id}'"), text
    if match is not None:
        assert match in exc.matches and "did you mean" in text and f"'{match}'" in text, text


def test_known_elements_at_rest_still_answer_with_their_rest_state(sim: Simulation) -> None:
    assert sim.route_state("S-SI") == "released" and sim.view.route("S-SI") is None
    assert sim.view.route_of("S") is None and sim.view.cab_code("IG") is None
    assert sim.section_state("IG") in ("free", "locked") and sim.turnout_state("1")[0] in ("normal", "reverse", None)
    assert sim.view.block_line("SL") == "idle"
    gaotie = Simulation("gaotie")
    assert gaotie.view.block_line("XL-I") is None  # an automatic-block line: known, with no block state


def test_the_command_language_refuses_an_unknown_id_with_the_closest_ids() -> None:
    sim = Simulation("jiaopei")
    result = sim.command("expect code 1dg none")
    assert not result and result.message == "station jiaopei has no section '1dg'; did you mean '1DG', '7DG' or '6DG'?"
    assert not sim.command("expect block-line ZL idle") and sim.command("expect block-line XL idle")
    assert sim.command("expect code IG none")


def test_a_train_that_left_says_so_instead_of_giving_a_position() -> None:
    sim = Simulation("jiaopei")
    for line in ("train T1 at IG mode=signal length=200", "route XI S", "run 5s", "block-line SL request", "run 5s"):
        assert sim.command(line), line
    states = []
    for _ in range(int(240 / sim.cycle_s)):
        sim.step()
        v = sim.train_view("T1")
        if v.state != "running":
            assert v.head_track is None and v.head_m is None, v  # beyond the boundary: no position in the station
        else:
            assert v.head_track in sim.station.tracks and v.head_m is not None, v
        if not states or states[-1] != v.state:
            states.append(v.state)
        if v.left:
            break
    assert states == ["running", "leaving", "left"]
    gone = sim.train_view("T1")
    assert gone.left and gone.sections == () and gone.speed_kmh == 0.0 and gone.direction == "down"
    assert sim.train_views() == []  # no longer in the yard
    assert sim.command("train T1 at IAG")  # the name is free again: a new train in the yard
    assert sim.train_view("T1").state == "running"


USER = """\
import liansuo
sim = liansuo.Simulation("jiaopei")
if sim.command("route X XY"):
    print("accepted?!")
else:
    print("refused")
try:
    sim.aspect("NOSUCH")
except KeyError as exc:
    print(f"KeyError: {exc}")
try:
    sim.section_state("1dg")
except liansuo.UnknownId as exc:
    print(exc.kind, exc.id, exc.matches)
"""


def test_a_user_script_reads_as_it_says() -> None:
    proc = subprocess.run([sys.executable, "-c", USER], capture_output=True, text=True, check=False, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines() == ["refused", "KeyError: station jiaopei has no signal 'NOSUCH'",
                                        "section 1dg ('1DG', '7DG', '6DG')"]


def test_the_package_is_typed() -> None:
    assert (Path(liansuo.__file__).parent / "py.typed").is_file()
