"""The independent safety oracle: it imports nothing of the interlocking, and of the rules only their data; random
operation of the stations keeps every property; it catches an interlocking broken on purpose with the property that
breaks; what the interlocking cannot see by design is a hazard, not a violation."""

from __future__ import annotations

import ast
import random
from contextlib import ExitStack
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from liansuo.proving.mutation.mutants import MUTANTS
from liansuo.proving.oracle import Watch
from liansuo.proving.oracle.ceiling import permits
from liansuo.proving.oracle.lamps import DARK, UNDEFINED, LampReader
from liansuo.proving.soak.run import StepGenerator
from liansuo.rules import load_rules
from liansuo.simulation.sim import Simulation
from liansuo.stations.loader import load

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
SHUANGXIAN = str(PKG / "examples" / "stations" / "shuangxian.yaml")
DANXIAN = str(PKG / "examples" / "stations" / "danxian.yaml")
BROKEN = PKG / "examples" / "broken" / "gaotie-no-diamond-protection.yaml"


# ---- independence ---------------------------------------------------------------------------------------------------
ORACLE = PKG / "proving" / "oracle"


def imported(path: Path) -> set[str]:
    """Modules imported at run time (not those imported for type checking only), relative imports made absolute."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and getattr(node.test, "id", "") == "TYPE_CHECKING":
            node.body = []
    package = path.relative_to(ROOT / "src").parent.parts  # ("liansuo", "proving", "oracle")
    out: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = package[:len(package) - node.level + 1] if node.level else ()
            out.add(".".join([*base, *([node.module] if node.module else [])]))
        elif isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
    return out


def test_the_oracle_imports_nothing_of_the_interlocking_and_of_the_rules_only_their_data() -> None:
    """Neither the table, nor the route engine, nor the aspect rules: the oracle's judgment is its own. Of the
    national rules it reads the rule set's data (``liansuo.rules``), which holds no rule code and imports no layer."""
    files = sorted(ORACLE.glob("*.py"))
    assert len(files) >= 8  # the check reads the oracle where it is
    judge = sorted((ORACLE.parent / "judge").glob("*.py"))  # the reference judge beside it, by the same rule
    assert len(judge) >= 3
    files += judge
    seen: set[str] = set()
    for path in files:
        for module in imported(path):
            seen.add(module)
            assert not module.startswith("liansuo.interlocking"), f"{path.name} imports {module}"
            if module.startswith("liansuo.rules"):
                assert module == "liansuo.rules", f"{path.name} imports {module}"
            assert not module.startswith(("liansuo.proving.verify", "liansuo.proving.soak",
                                          "liansuo.proving.mutation")), (path.name, module)
    assert "liansuo.rules" in seen
    for path in sorted((PKG / "rules").glob("*.py")):
        below = {m for m in imported(path)
                 if m.startswith("liansuo.") and not m.startswith(("liansuo.rules", "liansuo.kit."))}
        assert not below, f"rules/{path.name} imports {below}: the rule set is data, it imports no layer but the kit"
    assert "liansuo.stations.station" in seen and "liansuo.proving.oracle.authority" in seen  # imports were read


# ---- random operation -----------------------------------------------------------------------------------------------
def random_run(station: str, rnd: random.Random, steps: int) -> tuple[Watch, list[str]]:
    sim = Simulation(station)
    watch = Watch(sim)
    gen = StepGenerator(sim, rnd)
    script: list[str] = []
    for _ in range(steps):
        lines, cycles = gen.next()
        for line in lines:
            script.append(line)
            sim.command(line)
        script.append(f"run {cycles * 250}ms")
        sim.run(cycles * 0.25)
        if watch.violations:
            break
    return watch, script


@pytest.mark.parametrize("station", ["jiaopei", "gaotie", "shuangxian", "danxian"])  # names: the same in any checkout
@settings(max_examples=8, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(rnd=st.randoms(use_true_random=False))
def test_random_operation_keeps_every_safety_property(station: str, rnd: random.Random) -> None:
    path = {"shuangxian": SHUANGXIAN, "danxian": DANXIAN}.get(station, station)
    watch, script = random_run(path, rnd, 80)
    assert not watch.violations, f"{watch.violations[0]}\nsteps:\n" + "\n".join(script)


# ---- a broken interlocking is caught ---------------------------------------------------------------------------------
def run_lines(station: str, *lines: str, mutant: str | tuple[str, ...] = ()) -> Watch:
    """Run ``lines`` with the oracle watching, on an interlocking with the named mutants
    (proving/mutation/mutants.py)."""
    names = (mutant,) if isinstance(mutant, str) else mutant
    with ExitStack() as stack:
        for m in MUTANTS:
            if m.name in names:
                stack.enter_context(m.applied())
        sim = Simulation(station)
        watch = Watch(sim)
        for line in lines:
            sim.command(line)
        return watch


def props(watch: Watch) -> set[str]:
    return {v.prop for v in watch.violations}


def test_no_violation_in_ordinary_operation() -> None:
    watch = run_lines("jiaopei", "route X XI", "run 2s", "route XI S", "block-line SL request", "run 5s",
                      "occupy IAG", "run 1s", "occupy 7DG", "run 1s", "vacate IAG", "occupy 1DG", "run 1s",
                      "vacate 7DG", "occupy IG", "run 1s", "vacate 1DG", "run 1s", "occupy 2DG", "run 1s",
                      "vacate IG", "occupy 6DG", "run 1s", "vacate 2DG", "occupy IIAG", "vacate 6DG", "run 30s")
    assert watch.cycles > 100 and watch.violations == [] and watch.hazards == []


def test_enemies_the_table_forgets_meet_head_on() -> None:
    watch = run_lines("jiaopei", "route X XI", "run 10s", "shunt D2 XI", "run 10s", mutant="no-head-on-enemies")
    assert len(watch.violations) == 1 and watch.violations[0].prop == "head-on"
    text = watch.violations[0].text
    assert "X (train)" in text and "D2 (shunt)" in text and text.endswith("lead head-on onto IG")


def test_two_routes_over_one_section_share_it() -> None:
    # with the table's conflicts and the section locks both ignored (one alone is caught by the other)
    watch = run_lines("jiaopei", "route X XI", "run 10s", "route S SI", "run 10s",
                      mutant=("table-conflicts-skipped", "route-over-locked-sections"))
    assert "shared" in props(watch)
    assert any("share section IG" in v.text for v in watch.violations)


def test_a_signal_open_over_an_occupied_section_is_caught() -> None:
    watch = run_lines("jiaopei", "route X XI", "run 2s", "occupy IG", "run 2s", mutant="blind-to-occupancy")
    assert [v.text for v in watch.violations] == ["signal X shows U over occupied section IG"]


def test_a_turnout_moved_under_an_open_signal_is_caught() -> None:
    watch = run_lines("jiaopei", "route X XI", "run 2s", "throw 7 reverse", "run 2s", mutant="throw-ignores-locks")
    assert "turnout 7 is moving towards reverse while the authority of X needs it normal (path)" in \
        [v.text for v in watch.violations]


def test_a_turnout_driven_under_a_standing_vehicle_is_a_violation_under_one_entering_a_hazard() -> None:
    """The interlocking's output drives a turnout whose section is occupied (a defect: its own checks are skipped).
    Occupied since before, the interlocking could see it: a violation. Occupied in the very step the move begins
    (a vehicle entering as the machine starts), it could not: the world's hazard."""
    sim = Simulation("jiaopei")
    watch = Watch(sim)
    sim.command("occupy 7DG")
    sim.command("run 2s")
    sim.interlocking.core.out.drive("7", "reverse")
    sim.command("run 1s")
    assert [v.text for v in watch.violations] == ["turnout 7 started moving towards reverse with its section 7DG "
                                                  "occupied"]
    assert watch.hazards == []

    sim = Simulation("jiaopei")
    watch = Watch(sim)
    sim.command("run 1s")
    sim.interlocking.core.out.drive("7", "reverse")
    sim.command("occupy 7DG")
    sim.command("run 1s")
    assert watch.violations == []
    assert [v.text for v in watch.hazards] == ["turnout 7 started moving towards reverse with its section 7DG "
                                               "occupied (entered as the move began)"]


def test_a_signal_reopening_by_itself_is_caught() -> None:
    lines = ("route X XI", "run 2s", "fault no-indication 1", "run 1s", "repair no-indication 1", "run 2s")
    watch = run_lines("jiaopei", *lines, mutant="reopens-by-itself")
    assert props(watch) == {"reopened"}
    # with the operator's reopen command it is no violation
    assert run_lines("jiaopei", *lines, "reopen X", "run 2s").violations == []


def test_a_lone_yellow_over_a_diverging_route_is_too_permissive() -> None:
    """A dark second yellow on UU must give H, not a lone U: the driver would take the route for straight."""
    watch = run_lines("jiaopei", "route X X3", "run 10s", "fault filament X lamp=U2 which=both", "run 2s",
                      mutant="no-lamp-proving")
    assert any(v.prop == "aspect" and "shows U" in v.text and "at most UU" in v.text for v in watch.violations)
    assert run_lines("jiaopei", "route X X3", "run 10s", "fault filament X lamp=U2 which=both",
                     "run 2s").violations == []


def test_usu_over_an_onward_route_on_no12_turnouts_is_caught() -> None:
    lines = ("line-direction SL-II out", "route X X3", "route X3 XFK2", "run 20s")
    watch = run_lines(SHUANGXIAN, *lines, mutant="usu-without-onward-check")
    assert any("X3 is open over turnout 2 reversed (45 km/h)" in v.text for v in watch.violations)
    assert run_lines(SHUANGXIAN, *lines).violations == []


def test_a_flank_turnout_the_table_forgets_is_caught_when_it_lies_the_wrong_way() -> None:
    watch = run_lines(str(BROKEN), "throw 5/7 reverse", "run 10s", "route X BA1 XI", "run 20s")
    texts = [v.text for v in watch.violations]
    assert any(t.startswith("signal X shows UU but flank turnout 5 lies reverse") for t in texts), texts
    assert run_lines("gaotie", "throw 5/7 reverse", "run 10s", "route X BA1 XI", "run 20s").violations == []


# ---- hazards ---------------------------------------------------------------------------------------------------------
def test_a_vehicle_hidden_in_a_dead_zone_is_a_hazard_not_a_violation() -> None:
    watch = run_lines("gaotie", "axles trolley t-3r 4569 4576", "route SII SFCK", "run 15s")
    assert watch.violations == []
    assert [h.prop for h in watch.hazards] == ["invisible"] and "3-5DG" in watch.hazards[0].text


def test_a_relay_flasher_failing_silently_is_a_hazard_an_electronic_one_is_answered() -> None:
    relay = run_lines("gaotie", "route S S4", "route S4 SFCK", "run 15s", "fault flasher S", "run 10s")
    assert relay.violations == [] and any(h.prop == "aspect" and "1270" in h.text for h in relay.hazards)
    electronic = run_lines("gaotie", "route X X3", "route X3 XFCK", "run 15s", "fault flasher X", "run 10s")
    assert electronic.violations == []


def test_a_guide_aspect_is_an_authority_like_any_other() -> None:
    # two guide aspects under guide total lock towards the same tracks: the interlocking refuses the second
    sim = Simulation(DANXIAN)
    locked = Watch(sim)
    refused = [line for line in ("guide-lock X", "guide-lock S", "guide X", "guide S", "run 2s")
               if not sim.command(line).ok]
    assert locked.violations == [] and refused == ["guide S"]
    # an interlocking that lets them both be given is caught: two signals given at once are its own doing
    both = run_lines(DANXIAN, "guide-lock X", "guide-lock S", "guide X", "guide S", "run 2s", mutant="guide-blind")
    assert any(v.prop == "shared" and "IG" in v.text for v in both.violations)


def test_a_guide_aspect_under_guide_total_lock_waits_for_the_overlap_of_a_received_train() -> None:
    # the train received onto IG stands there, its overlap 2DG held beyond XI for an overrun: a guide aspect from
    # the other end, whose train would run into that overlap, is refused until the overlap has released
    lines = ("route X XI", "run 5s", "occupy IAG", "run 1s", "occupy 1DG", "run 1s", "vacate IAG", "occupy IG",
             "run 1s", "vacate 1DG", "run 1s", "guide-lock S", "guide S", "run 181s", "guide S", "run 2s")
    sim = Simulation(DANXIAN)
    watch = Watch(sim)
    refused = [line for line in lines if not sim.command(line).ok]
    assert refused == ["guide S"] and sim.aspect("S") == "HB"
    assert watch.violations == []


# ---- the rules, stated on their own ----------------------------------------------------------------------------------
def test_aspects_are_read_by_colour_from_the_lamps_lit() -> None:
    reader = LampReader(load_rules().aspects)
    assert reader.read(frozenset({"U", "U2"})) == "UU"
    assert reader.read(frozenset({"U", "U2"}), flashing=True) == "USU"
    assert reader.read(frozenset({"U2"})) == "U"  # one yellow, whichever lamp
    assert reader.read(frozenset({"H", "B"})) == "HB"
    assert reader.read(frozenset()) == DARK
    assert reader.read(frozenset({"L", "H"})) == UNDEFINED


@pytest.mark.parametrize(("limit", "shown", "ok"), [
    ("L", "LU", True), ("LU", "L", False), ("U", "U", True), ("U", "H", True),
    ("UU", "U", False),  # a lone yellow over a diverging route
    ("UU", "LU", False), ("USU", "UU", True), ("USU", "LU", False), ("H", "U", False),
])
def test_an_aspect_never_more_permissive_than_its_path(limit: str, shown: str, ok: bool) -> None:
    assert permits(limit, shown, load_rules().aspects) is ok


def test_the_oracle_reads_the_station_not_the_table() -> None:
    """The oracle traces the scissors' diamond from the station's geometry."""
    from liansuo.proving.oracle import Tracer

    gaotie = load("gaotie")
    a = Tracer(gaotie).trace("X", "train", {"1": "reverse", "3": "reverse", "13": "reverse", "15": "reverse",
                                           "9": "normal"}.get)
    assert a.diamonds == {"XD1"} and a.end_signal == "XI" and a.sections[-1] == "IG"


@pytest.mark.parametrize("name", ["gaotie", DANXIAN])
def test_the_view_reads_what_the_field_shows_now(name: str) -> None:
    """What the oracle's view reads again only after a lamp command (the signals lit beyond stop), and what it reads
    of many sections at once (the occupied ones), is what the field shows at every cycle of random operation."""
    sim = Simulation(load(name))
    watch = Watch(sim)
    gen = StepGenerator(sim, random.Random(11))
    field, sections = sim.field, list(sim.station.sections)
    stop = {s: set(lamps.commanded) for s, lamps in field.lamps.items()}  # every signal at stop at power-on
    seen: set[tuple[str, ...]] = set()
    for _ in range(120):
        lines, cycles = gen.next()
        for line in lines:
            sim.command(line)
        for _ in range(cycles):
            sim.step()
            showing = watch.view.showing()
            assert showing == tuple(s for s, lamps in field.lamps.items() if lamps.commanded - stop[s])
            assert watch.view.occupied(sections) == {s for s in sections if not field.circuits[s].up}
            seen.add(showing)
    assert len(seen) >= 2  # a signal opened
