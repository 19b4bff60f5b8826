"""The command line (cli/): one parser from the rooms' own register functions; the console (Textual) loads only for
``liansuo tui`` and ``liansuo replay``."""

from __future__ import annotations

import argparse
import subprocess
import sys

from liansuo.cli.main import build_parser

SUBCOMMANDS = {"stations", "check", "schema", "generate", "table", "zpw", "run", "test", "verify", "soak", "mutate",
               "bench", "tui", "replay"}


def test_every_subcommand_is_registered() -> None:
    sub = next(a for a in build_parser()._actions if isinstance(a, argparse._SubParsersAction))
    assert set(sub.choices) == SUBCOMMANDS


def test_other_subcommands_do_not_load_the_console() -> None:
    code = ("import sys; from liansuo.cli.main import main; main(['check', 'jiaopei']); "
            "print(sorted(m for m in sys.modules if m == 'textual' or m.startswith('liansuo.tui.') "
            "and m != 'liansuo.tui.cli'))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.splitlines()[-1] == "[]"
