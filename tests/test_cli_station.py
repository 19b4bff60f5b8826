"""The station commands of ``liansuo``: ``stations``, ``check`` (text and JSON) and ``schema``, as a user sees them."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import yaml
from jsonschema import Draft202012Validator

from liansuo.cli.main import main
from liansuo.stations.library import bundled

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
MINIMAL = PKG / "examples" / "stations" / "minimal.yaml"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_stations_lists_the_bundled_stations(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "stations")
    assert code == 0
    names = [line.split()[0] for line in out.splitlines() if line.strip() and not line.startswith(" ")]
    assert "jiaopei" in names
    assert set(names) == set(bundled())
    assert "教培站" in out


def test_check_bundled_station_prints_the_summary(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "check", "jiaopei")
    assert code == 0, err
    assert out.startswith("jiaopei: 教培站 (Jiaopei teaching station)")
    for label in ("tracks", "turnouts", "sections", "signals", "dead zones", "warnings     0"):
        assert label in out
    assert "crossover pairs 1/3, 2/4" in out
    assert err == ""


def test_check_json_is_valid_and_ok(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "check", "jiaopei", "--format", "json")
    assert code == 0
    report = json.loads(out)
    assert report["ok"] is True
    assert report["station"] == "jiaopei"
    assert report["turnouts"] == 7
    assert report["warnings"] == []


def test_check_a_file_by_path(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "check", str(MINIMAL))
    assert code == 0
    assert out.startswith("minimal: 最小站 (Minimal station)")


def test_check_prints_warnings_with_figures(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "staggered.yaml"
    text = MINIMAL.read_text(encoding="utf-8").replace("at2: 200.5", "at2: 206")
    path.write_text(text, encoding="utf-8")
    before = text[: text.index("206")]
    line, column = before.count("\n") + 1, len(before) - before.rfind("\n")
    code, out, _ = run(capsys, "check", str(path))
    assert code == 0  # warnings do not refuse the file
    assert "warnings     1" in out  # the stagger
    read = " ".join(out.split())  # a long path folds the message onto the next line
    assert f"{path}:{line}:{column}: warning: joint 'J-X': rail joints staggered 6 m (limit 5 m)" in read


def _broken(tmp_path: Path) -> tuple[Path, int, int]:
    text = MINIMAL.read_text(encoding="utf-8").replace("machine: ZD6", "machine: ZD7")
    path = tmp_path / "broken.yaml"
    path.write_text(text, encoding="utf-8")
    before = text[: text.index("ZD7")]
    return path, before.count("\n") + 1, len(before) - before.rfind("\n")


def test_check_broken_file_reports_file_line_column(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path, line, column = _broken(tmp_path)
    code, out, err = run(capsys, "check", str(path))
    assert code == 3  # a bad input file
    assert out == ""
    assert f"{path}:{line}:{column}: error: " in err
    assert "'ZD6', 'ZDJ9' or 'S700K'" in err
    assert "hint:" in err
    assert "1 error; the station was not loaded" in err
    assert "Traceback" not in out + err


def test_check_broken_file_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path, line, column = _broken(tmp_path)
    code, out, _ = run(capsys, "check", str(path), "--format", "json")
    assert code == 3  # a bad input file
    report = json.loads(out)
    assert report["ok"] is False
    (error,) = report["errors"]
    assert (error["file"], error["line"], error["column"]) == (str(path), line, column)
    assert error["severity"] == "error" and error["hint"]


def test_check_yaml_syntax_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "syntax.yaml"
    path.write_text("id: x\nname: {zh: a, en: b\nends: []\n", encoding="utf-8")
    code, _, err = run(capsys, "check", str(path))
    assert code == 3  # a bad input file
    assert f"{path}:3:" in err and "YAML syntax error" in err
    assert "Traceback" not in err


def test_check_missing_file_says_so(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    missing = tmp_path / "nowhere.yaml"
    code, out, err = run(capsys, "check", str(missing))
    assert code == 3  # a bad input file
    assert f"{missing}:1:1: error: no such file" in err
    assert "liansuo stations" in err  # the hint says how to find the bundled names
    assert "Traceback" not in out + err


def test_check_unknown_station_name(capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "check", "no-such-station")
    assert code == 3  # a bad input file
    assert "no-such-station:1:1: error: no such file" in err


def _schema(capsys: pytest.CaptureFixture[str]) -> dict[str, Any]:
    code, out, _ = run(capsys, "schema")
    assert code == 0
    schema: dict[str, Any] = json.loads(out)
    return schema


def test_schema_is_a_valid_json_schema(capsys: pytest.CaptureFixture[str]) -> None:
    schema = _schema(capsys)
    Draft202012Validator.check_schema(schema)
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    assert schema["additionalProperties"] is False
    assert {"id", "name", "ends", "tracks", "sections"} <= set(schema["required"])
    assert {"from", "to"} <= set(schema["$defs"]["Track"]["properties"])


@pytest.mark.parametrize("path", [*bundled().values(), MINIMAL], ids=lambda p: p.stem)
def test_station_files_validate_against_the_schema(capsys: pytest.CaptureFixture[str], path: Path) -> None:
    validator = Draft202012Validator(_schema(capsys))
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    errors = [f"{'.'.join(map(str, e.absolute_path))}: {e.message}" for e in validator.iter_errors(data)]
    assert not errors, "\n".join(errors)


def test_schema_accepts_what_the_loader_accepts(capsys: pytest.CaptureFixture[str]) -> None:
    """Kilometre posts and unquoted turnout numbers load, so an editor must not flag them either."""
    validator = Draft202012Validator(_schema(capsys))
    text = MINIMAL.read_text(encoding="utf-8")
    text = text.replace('{id: "1", at: 250', "{id: 1, at: K0+250.0").replace("at: 600}", "at: K0+600}")
    assert not list(validator.iter_errors(yaml.safe_load(text)))


@pytest.mark.parametrize(("old", "new", "where"), [
    ("machine: ZD6", "machine: ZD7", "machine"),
    ('{id: "1", at: 250,', '{id: "1", at: 250, colour: red,', "colour"),
    ("number: 12", "number: twelve", "number"),
    ("{id: B-3, kind: buffer, at: 600}", "{id: B-3, kind: buffer, at: K0+6x0}", "at"),
    ("{id: 1DG, type: 25hz}", "{id: 1DG, type: zpw2000a, carrier: 2400-1}", "carrier"),
])
def test_schema_rejects_what_the_loader_rejects(capsys: pytest.CaptureFixture[str], old: str, new: str,
                                                where: str) -> None:
    validator = Draft202012Validator(_schema(capsys))
    text = MINIMAL.read_text(encoding="utf-8")
    assert old in text
    errors = list(validator.iter_errors(yaml.safe_load(text.replace(old, new, 1))))
    assert errors
    assert any(where in json.dumps(list(e.absolute_path)) + e.message for e in errors)
