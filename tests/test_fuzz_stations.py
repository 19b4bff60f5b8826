"""The fuzz kind ``stations`` in the suite: mutants of the example stations through check, table and verify, each
answered with a station or a FILE:LINE:COLUMN refusal (exit status 3) within seconds (docs/robustness.md)."""

from __future__ import annotations

import time
from pathlib import Path

import pytest
from hypothesis import given, settings

from liansuo.cli.main import main
from liansuo.proving.fuzz.stations import EXAMPLES, NAME, StationSample, attempt, run, strategy

SECONDS = 10  # per sample: check, table and verify of a small station take well under one


@settings(derandomize=True, max_examples=60, deadline=None, database=None)
@given(strategy())
def test_station_mutants_are_answered_not_crashed(sample: StationSample) -> None:
    start = time.monotonic()
    assert attempt(sample) in ("accepted", "refused")
    assert time.monotonic() - start < SECONDS, f"{sample.changes} took {time.monotonic() - start:.1f} s"


def test_the_kind_is_named_for_the_fuzz_command() -> None:
    assert NAME == "stations"


# ---- what a long run found (liansuo fuzz stations --budget 10000 --seed 1), each now answered at check -----------
def _minimal(text_change: tuple[str, str]) -> StationSample:
    text = (EXAMPLES / "minimal.yaml").read_text(encoding="utf-8")
    assert text_change[0] in text
    return StationSample(seed="minimal", changes=(), content=text.replace(*text_change).encode("utf-8"))


def test_an_automatic_block_line_without_sections_is_refused_by_check(tmp_path: Path,
                                                                        capsys: pytest.CaptureFixture[str]) -> None:
    """It passed check and crashed verify (IndexError) when a departing route looked for its departure section."""
    sample = _minimal(("sections: [1LQG]}", "sections: []}"))
    assert attempt(sample) == "refused"
    file = tmp_path / "s.yaml"
    file.write_bytes(sample.content)
    assert main(["check", str(file)]) == 3
    assert "automatic block line SL names no sections" in capsys.readouterr().err


def test_check_refuses_an_added_enemy_naming_no_route_as_table_does(tmp_path: Path) -> None:
    """The fuzzer ran check with a parser of its own that lacked the table's errors, so check and table seemed to
    disagree; it now runs the installed command line, and what table refuses, check refuses with the same words."""
    text = (EXAMPLES / "shuangxian.yaml").read_text(encoding="utf-8")
    file = tmp_path / "shuangxian.yaml"
    file.write_text(text.replace("{route: X-X3, enemy: XI-XFCK", "{route: X-NOSUCH, enemy: XI-XFCK"),
                    encoding="utf-8")
    said = "added enemy names route 'X-NOSUCH', which does not exist"
    for command in ("check", "table"):
        code, _, err = run(command, str(file))
        assert code == 3 and said in err, command


@pytest.mark.parametrize("argv", [("check", "gaotie"), ("check", "jiaopei", "--format", "json"),
                                  ("table", "jiaopei"), ("verify", str(EXAMPLES / "minimal.yaml"))])
def test_the_fuzzers_commands_are_the_command_lines(argv: tuple[str, ...], capsys: pytest.CaptureFixture[str]) -> None:
    """The fuzzer registers check, table and verify from their rooms as cli/main.py does: the same answers."""
    code = main(list(argv))
    out, err = capsys.readouterr()
    fuzzed = run(*argv)
    if argv[0] == "verify":  # its last line times the run
        assert (fuzzed[0], fuzzed[1].splitlines()[:-1], fuzzed[2]) == (code, out.splitlines()[:-1], err)
    else:
        assert fuzzed == (code, out, err)
