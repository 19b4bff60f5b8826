"""The JSON Schemas of the file kinds (``liansuo schema KIND``): generated from the models the loaders validate with,
shipped as ``liansuo/schemas/KIND-N.json`` with a stable ``$id``, referenced by a modeline in every bundled file, and
in agreement with the loaders on what a valid file is."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest
import yaml
from jsonschema import Draft202012Validator

from liansuo.classroom.exercise import parse_exercise
from liansuo.cli.main import main
from liansuo.cli.schemas import KINDS, file_name, generate, shipped
from liansuo.kit.source import StationError
from liansuo.proving.scenario import parse_scenario
from liansuo.proving.scripts import parse_script

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
MODELINE = re.compile(r"^# yaml-language-server: \$schema=(\S+)$")
# every folder of bundled YAML files of a kind that has a schema, and that kind
BUNDLED = {"src/liansuo/stations/library": "station", "src/liansuo/examples/stations": "station",
           "src/liansuo/examples/broken": "station", "src/liansuo/examples/scripts": "script",
           "tests/scripts": "script", "src/liansuo/examples/scenarios": "scenario", "src/liansuo/exercises": "exercise",
           "src/liansuo/examples/points": "points"}
BUNDLED_FILES = sorted((ROOT / folder / f.name, kind) for folder, kind in BUNDLED.items()
                       for f in (ROOT / folder).glob("*.yaml"))


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def validator(kind: str) -> Draft202012Validator:
    return Draft202012Validator(json.loads(shipped(kind).read_text(encoding="utf-8")))


@pytest.mark.parametrize("kind", KINDS)
def test_the_shipped_schema_is_what_the_model_generates(kind: str, capsys: pytest.CaptureFixture[str]) -> None:
    text = shipped(kind).read_text(encoding="utf-8")
    assert json.loads(text) == generate(kind), (
        f"{shipped(kind)} differs from its model: rewrite it with 'liansuo schema {kind} > schemas/{file_name(kind)}' "
        "(and raise the version in cli/schemas.py if a file valid before no longer is)")
    code, out, err = run(capsys, "schema", kind)
    assert (code, err) == (0, "")
    assert out == text  # byte for byte: what the command writes is the file that ships


@pytest.mark.parametrize("kind", KINDS)
def test_every_schema_is_valid_and_has_a_stable_id(kind: str) -> None:
    schema = json.loads(shipped(kind).read_text(encoding="utf-8"))
    Draft202012Validator.check_schema(schema)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert schema["$id"] == f"https://liansuo.dev/schema/{kind}-1.json"
    assert shipped(kind).name == f"{kind}-1.json"
    assert schema["title"].startswith("liansuo ") and schema["additionalProperties"] is False


def test_schema_without_a_kind_prints_the_station_schema(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "schema")
    assert code == 0 and json.loads(out)["$id"] == "https://liansuo.dev/schema/station-1.json"


def test_schema_of_an_unknown_kind_is_a_usage_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exc:
        main(["schema", "recording"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert "invalid choice" in err and "recording" in err and "exercise" in err


def test_every_bundled_yaml_file_is_of_a_kind_with_a_schema() -> None:
    """A new folder of YAML files must be added to BUNDLED (and its files given a modeline); the rule sets have
    models of their own (rules/), not a schema for editors; so has the model data the code writes and reads (the
    ZPW-2000A adjustment table, circuits/zpw/adjust.py; the capacitor-fault article's tables,
    circuits/zpw/validate.py)."""
    skipped = {".venv", ".git", "build", "dist", "rules"}
    model_data = {PKG / "circuits" / "zpw" / "adjust.yaml", PKG / "circuits" / "zpw" / "validate.yaml"}
    found = {p for p in ROOT.rglob("*.yaml") if not skipped & set(p.relative_to(ROOT).parts)} - model_data
    assert found == {path for path, _ in BUNDLED_FILES}
    assert {kind for _, kind in BUNDLED_FILES} == set(KINDS)


@pytest.mark.parametrize(("path", "kind"), BUNDLED_FILES, ids=lambda v: v.name if isinstance(v, Path) else v)
def test_every_bundled_file_names_its_schema_and_validates_against_it(path: Path, kind: str) -> None:
    text = path.read_text(encoding="utf-8")
    first = text.splitlines()[0]
    m = MODELINE.match(first)
    assert m, f"{path.relative_to(ROOT)}: the first line should be the modeline, not {first!r}"
    target = (path.parent / m.group(1)).resolve()
    assert target == shipped(kind).resolve(), f"{path.relative_to(ROOT)}: the modeline names {m.group(1)}"
    errors = [f"{'.'.join(map(str, e.absolute_path))}: {e.message}" for e in validator(kind).iter_errors(
        yaml.safe_load(text))]
    assert not errors, f"{path.relative_to(ROOT)} against {shipped(kind).name}:\n" + "\n".join(errors)


SCRIPT = "station: jiaopei\ntests:\n  - name: a\n    steps:\n      - route X XI\n"
SCENARIO = "station: jiaopei\nsteps:\n  - route X XI\nuntil: 3min\n"
EXERCISE = "title: t\nstation: jiaopei\nsetup: [run 1s]\ngoal:\n  expect: [signal X H]\n"
PARSE = {"script": parse_script, "scenario": parse_scenario, "exercise": parse_exercise}


@pytest.mark.parametrize(("kind", "text", "loads"), [
    ("script", SCRIPT, True),
    ("script", SCRIPT + "cycle_ms: 100\nsafety: true\n", True),
    ("script", SCRIPT + "cycle_ms: 5\n", False),
    ("script", SCRIPT + "safety: 1\n", False),
    ("script", SCRIPT + "colour: red\n", False),
    ("script", SCRIPT.replace("station: jiaopei", "station: 7"), False),
    ("script", "station: jiaopei\ntests: []\n", False),
    ("script", SCRIPT.replace("- name: a", "- title: a"), False),
    ("script", SCRIPT + "    speed: 3\n", False),
    ("scenario", SCENARIO, True),
    ("scenario", SCENARIO.replace("3min", "180"), True),
    ("scenario", SCENARIO.replace("3min", "soon"), False),
    ("scenario", SCENARIO.replace("3min", "-5"), False),
    ("scenario", SCENARIO + "description: 12\n", True),
    ("scenario", "station: jiaopei\nsteps: []\n", False),
    ("scenario", SCENARIO.replace("- route X XI", "- 5"), False),
    ("exercise", EXERCISE, True),
    ("exercise", "title: t\nstation: jiaopei\n", True),
    ("exercise", EXERCISE.replace("title: t", "title: ''"), False),
    ("exercise", EXERCISE + "  colour: red\n", False),
    ("exercise", EXERCISE.replace("[signal X H]", "[3]"), False),
    ("exercise", EXERCISE.replace("setup: [run 1s]", "setup: run 1s"), False),
])
def test_the_schema_and_the_loader_agree(tmp_path: Path, kind: str, text: str, loads: bool) -> None:
    path = tmp_path / f"{kind}.yaml"
    path.write_text(text, encoding="utf-8")
    valid = not list(validator(kind).iter_errors(yaml.safe_load(text)))
    try:
        PARSE[kind](path)
        loaded = True
    except StationError:
        loaded = False
    assert (valid, loaded) == (loads, loads)


def test_a_malformed_script_is_reported_at_its_lines(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text("station: jiaopei\ncycle_ms: 5\ntests:\n  - name: a\n    steps:\n      - fly X\n"
                    "    colour: red\n", encoding="utf-8")
    code, _, err = run(capsys, "test", str(path))
    assert code != 0 and "Traceback" not in err
    lines = [line for line in err.splitlines() if not line.startswith("    hint:")]
    assert lines[:3] == [f"{path}:2:11: error: cycle_ms: Input should be greater than or equal to 10 (got 5)",
                         f"{path}:6:9: error: unknown command 'fly'",
                         f"{path}:7:5: error: unknown key 'colour'"]
    assert "check its spelling against 'liansuo schema script'" in err
