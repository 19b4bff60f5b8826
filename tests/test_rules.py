"""National rule sets: one folder per country, chosen by one name, checked with file and line, read by every layer;
aspect codes appear only in the rule set and in the Chinese aspect selection."""

from __future__ import annotations

import ast
import shutil
from pathlib import Path

import pytest

from liansuo.rules import DEFAULT, FILES, RuleError, RuleSet, bundled, load_rules
from liansuo.simulation.sim import Simulation

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "src" / "liansuo"


@pytest.fixture
def folder(tmp_path: Path) -> Path:
    """A copy of the Chinese rule set to change."""
    out = tmp_path / "mine"
    shutil.copytree(PKG / "rules" / "china", out)
    return out


def edit(path: Path, old: str, new: str) -> None:
    text = path.read_text(encoding="utf-8")
    assert old in text, old
    path.write_text(text.replace(old, new, 1), encoding="utf-8")


def test_the_bundled_rule_set_has_every_part() -> None:
    assert DEFAULT in bundled()
    rules = load_rules()
    assert rules is load_rules(DEFAULT) and rules.name == DEFAULT
    assert sorted(p.stem for p in (PKG / "rules" / DEFAULT).glob("*.yaml")) == sorted(FILES)
    assert rules.aspects.stop in rules.aspects.closed and rules.aspects.guide not in rules.aspects.train_proceed
    assert rules.lamps is rules.aspects.lamps  # the interlocking reads the aspect tables by their old names
    assert rules.driving.platform_dwell_s > 0 and rules.design.tuning_area_m > 0 and rules.equipment.machines


def test_one_name_chooses_every_part(folder: Path) -> None:
    edit(folder / "equipment.yaml", "open_s: 3.0", "open_s: 7.0")
    edit(folder / "driving.yaml", "stop_margin_m: 8", "stop_margin_m: 12")
    edit(folder / "design.yaml", "joint_stagger_max_turnout_m: 5.0", "joint_stagger_max_turnout_m: 0.5")
    edit(folder / "interlocking.yaml", "guide_close_s: 60", "guide_close_s: 45")
    sim = Simulation("jiaopei", rules=str(folder))
    assert sim.rules.name == "mine" and sim.interlocking.rules is sim.rules and sim.rules.guide_close_s == 45
    assert all(d.spec.open_s == 7.0 for d in sim.field.doors.values())
    assert sim.fleet.rules.driving.stop_margin_m == 12
    assert len(sim.station.warnings) > len(Simulation("jiaopei").station.warnings)  # its 0.8-1.2 m staggers now warn


def test_bad_rule_data_names_file_line_and_what_is_wrong(folder: Path) -> None:
    edit(folder / "interlocking.yaml", "turnout_concurrency: 6", "turnout_concurrency: 0")
    edit(folder / "aspects.yaml", "guide: HB ", "guide: BH ")
    edit(folder / "aspects.yaml", "  B: [B]", "  B: [B, Q]")
    edit(folder / "aspects.yaml", "  B:   {B: A}", "  B:   {B: L}")
    edit(folder / "driving.yaml", "  UU: 45", "  UX: 45")
    edit(folder / "equipment.yaml", "doors:", "dors:")
    with pytest.raises(RuleError) as exc:
        load_rules(str(folder))
    text = str(exc.value)
    for want in ("interlocking.yaml:11:22: error: turnout_concurrency: Input should be greater than or equal to 1",
                 "aspects.yaml:15:8: error: 'BH' is no aspect of this rule set",
                 "lamp 'Q' has no colour", "'B' with 'B' dark shows 'L', which is not more restrictive",
                 "driving.yaml:8:7: error: 'UX' is no aspect", "equipment.yaml:", "unknown key 'dors'"):
        assert want in text, (want, text)


def test_a_missing_file_or_rule_set_is_named(folder: Path) -> None:
    (folder / "design.yaml").unlink()
    with pytest.raises(RuleError, match=r"design\.yaml:1:1: error: no such file"):
        load_rules(str(folder))
    with pytest.raises(RuleError, match="no rule set 'atlantis': give one of china"):
        load_rules("atlantis")


def test_a_rule_set_object_is_still_accepted_where_a_name_is() -> None:
    rules = load_rules().model_copy(update={"turnout_concurrency": 1})
    assert isinstance(rules, RuleSet) and Simulation("jiaopei", rules=rules).interlocking.rules is rules


# ---- aspect codes live in the rule set ------------------------------------------------------------------------------
def test_no_aspect_or_lamp_code_outside_the_rule_set_and_the_aspect_selection() -> None:
    """The field, the world and what proves it name aspects by role and lamps by colour or by the station format's
    Lamp values. (The interlocking's own modules and the console's key and button letters are not scanned here.)"""
    rules = load_rules()
    codes = set(rules.lamps) | set(rules.aspects.colours)
    found = []
    for layer in ("circuits", "simulation", "proving"):
        for path in sorted((ROOT / layer).rglob("*.py")):
            tree = ast.parse(path.read_text(encoding="utf-8"))
            pieces = {id(v) for n in ast.walk(tree) if isinstance(n, ast.JoinedStr) for v in n.values}  # ids: B1
            for node in ast.walk(tree):
                if isinstance(node, ast.Constant) and node.value in codes and id(node) not in pieces:
                    found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {node.value!r}")
    assert not found, "name these by their role in the rule set:\n" + "\n".join(found)


def test_a_number_that_is_not_finite_is_refused_in_every_rule_file(folder: Path) -> None:
    """NaN or infinity in a rule set would reach every timer and distance it sets (issue 17: every number finite)."""
    edit(folder / "interlocking.yaml", "overlap_release_s: 180", "overlap_release_s: .nan")
    edit(folder / "driving.yaml", "stop_margin_m: 8", "stop_margin_m: .inf")
    with pytest.raises(RuleError) as exc:
        load_rules(str(folder))
    text = str(exc.value)
    assert "interlocking.yaml:8:" in text and "driving.yaml:" in text and text.count("finite number") >= 2, text


@pytest.mark.parametrize(("file", "old", "new", "said"), [
    ("interlocking.yaml", "overlap_release_s: 180", "overlap_release_s: 100000000",
     "overlap_release_s: Input should be less than or equal to 600"),
    ("interlocking.yaml", "  other: 1", "  other: " + "9" * 400, "other: Input should be less than or equal to 10000"),
    ("driving.yaml", "stop_margin_m: 8", "stop_margin_m: " + "9" * 400,
     "stop_margin_m: a number this large is out of every range"),
    ("design.yaml", "coding_speed_kmh: 45.0", "coding_speed_kmh: 1.0e+300",
     "coding_speed_kmh: Input should be less than or equal to 400"),
    ("equipment.yaml", "rated_force_N: 2450", "rated_force_N: 1.0e+12",
     "rated_force_N: Input should be less than or equal to 100000"),
], ids=["timer", "count", "distance", "speed", "force"])
def test_a_number_out_of_its_range_is_refused_in_a_rule_file(folder: Path, file: str, old: str, new: str,
                                                              said: str) -> None:
    """Every number of a rule file has a range (docs/rules.md), as a station file's have (issue 45, item 6): a
    release of three years or a margin of 400 digits would reach every timer and distance the rule sets."""
    edit(folder / file, old, new)
    with pytest.raises(RuleError) as exc:
        load_rules(str(folder))
    assert f"{file}:" in str(exc.value) and said in str(exc.value), str(exc.value)
