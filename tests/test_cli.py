"""The command line (cli/): one parser from the rooms' own register functions; the console (Textual) loads only for
``liansuo tui`` and ``liansuo replay``."""

from __future__ import annotations

import argparse
import re
import shlex
import shutil
import subprocess
import sys
from importlib import metadata
from pathlib import Path

import pytest

from liansuo.cli.main import build_parser

SUBCOMMANDS = {"stations", "check", "schema", "generate", "table", "zpw", "25hz", "run", "test", "verify", "soak",
               "explore", "mutate", "fuzz", "bench", "tui", "replay", "serve", "completion", "exercise", "field-sim",
               "field-map", "docs"}


def test_every_subcommand_is_registered() -> None:
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    assert set(sub.choices) == SUBCOMMANDS


def test_other_subcommands_do_not_load_the_console() -> None:
    code = ("import sys; from liansuo.cli.main import main; main(['check', 'jiaopei']); "
            "print(sorted(m for m in sys.modules if m == 'textual' or m.startswith('liansuo.tui.') "
            "and m != 'liansuo.tui.cli'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.splitlines()[-1] == "[]"


def liansuo(*argv: str) -> subprocess.CompletedProcess[str]:
    """The command line as a user runs it, in a process of its own."""
    return subprocess.run([sys.executable, "-c", "import sys; from liansuo.cli.main import main; sys.exit(main())",
                           *argv], capture_output=True, text=True, check=False)


def test_version_prints_the_installed_version() -> None:
    proc = liansuo("--version")
    assert (proc.returncode, proc.stderr) == (0, "")
    assert proc.stdout == f"liansuo {metadata.version('liansuo')}\n"
    assert re.fullmatch(r"liansuo \d+\.\d+\.\d+\S*\n", proc.stdout)


@pytest.mark.parametrize("shell", ["bash", "zsh", "fish"])
def test_completion_names_every_subcommand_and_option(shell: str) -> None:
    proc = liansuo("completion", shell)
    assert (proc.returncode, proc.stderr) == (0, "")
    script = proc.stdout
    for name in SUBCOMMANDS:
        assert re.search(rf"(?<![\w-]){name}(?![\w-])", script), f"{shell}: no subcommand {name}"
    for option in ("--version", "--format", "--junit-xml", "--until", "--exercise", "--scheduler", "--strict"):
        assert option.lstrip("-") in script, f"{shell}: no option {option}"
    for choice in ("xlsx", "station", "exercise"):  # the choices of table --format and of schema KIND
        assert choice in script, f"{shell}: no choice {choice}"


def test_completion_of_an_unknown_shell_is_a_usage_error() -> None:
    proc = liansuo("completion", "powershell")
    assert proc.returncode == 2 and "invalid choice" in proc.stderr and proc.stdout == ""


@pytest.mark.skipif(shutil.which("bash") is None, reason="bash is not installed")
def test_bash_completion_completes_subcommands_options_and_choices(tmp_path: Path) -> None:
    """The bash script sourced as a user's ~/.bashrc would, then asked what completes three command lines."""
    script = tmp_path / "liansuo.bash"
    script.write_text(liansuo("completion", "bash").stdout, encoding="utf-8")

    def complete(*words: str) -> str:
        return f"COMP_WORDS=({' '.join(shlex.quote(w) for w in words)}); COMP_CWORD={len(words) - 1}; " \
               'COMPREPLY=(); "$f" liansuo; echo "${COMPREPLY[*]}"'

    program = (f"source {shlex.quote(str(script))}; complete -p liansuo; "
               "f=$(complete -p liansuo | sed -E 's/.* -F ([^ ]+) .*/\\1/'); "
               + "; ".join(complete(*words) for words in (("liansuo", "sch"), ("liansuo", "completion", ""),
                                                           ("liansuo", "table", "jiaopei", "--format", ""))))
    proc = subprocess.run(["bash", "--norc", "--noprofile", "-c", program], capture_output=True, text=True,
                          check=False)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("complete ") and lines[0].endswith(" liansuo"), lines
    assert lines[1:] == ["schema", "bash zsh fish", "text csv json xlsx"]


def test_docs_lists_the_pages_and_prints_one(capsys: pytest.CaptureFixture[str]) -> None:
    from liansuo.cli.main import main

    assert main(["docs"]) == 0
    listed = capsys.readouterr().out
    assert "verify " in listed and "station-format " in listed and "pypi" not in listed
    assert main(["docs", "verify"]) == 0
    assert capsys.readouterr().out.startswith("# `liansuo verify`: the automatic interlocking test")
    assert main(["docs", "verif"]) == 2
    assert "no page 'verif'; did you mean verify?" in capsys.readouterr().err


def test_help_names_pages_that_liansuo_docs_finds(capsys: pytest.CaptureFixture[str]) -> None:
    """Every page a command's help names as 'liansuo docs TOPIC' exists: the help never points at a page an
    installed liansuo lacks."""
    import re

    from liansuo.cli.docs import pages

    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    helps = [" ".join(p.format_help().split()) for p in sub.choices.values()]  # across wrapped lines
    named = {t for h in helps for t in re.findall(r"liansuo docs ([a-z0-9-]+)", h)}
    assert named and named <= set(pages()), named - set(pages())
