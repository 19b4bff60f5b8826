"""What every plotting command shares (``--plot FILE``, ``--plot-csv FILE``): matplotlib loaded only when a plot is
asked for (the optional ``plot`` extra), the one-line message without it, the checks of the two file names before
any work starts, and writing the figure and its data.

The commands: ``liansuo zpw --plot`` (:mod:`liansuo.circuits.zpw.plot`), ``liansuo 25hz --plot``
(:mod:`liansuo.circuits.phase25.sweep`) and ``liansuo run --plot`` (:mod:`liansuo.proving.trainplot`); docs/commands.md.
"""

from __future__ import annotations

import argparse
import csv
from collections.abc import Iterable, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from liansuo.kit.arguments import unwritable

if TYPE_CHECKING:
    from matplotlib.figure import Figure

NEED_MATPLOTLIB = "the plots need matplotlib: pip install 'liansuo[plot]'"
FIGURE_SUFFIXES = (".png", ".svg", ".pdf")
FIGURE_SIZE_IN = (9.0, 5.0)  # 900 x 500 pixels at FIGURE_DPI
FIGURE_DPI = 100


class PlotUnavailable(RuntimeError):
    """matplotlib (the ``plot`` extra) is not installed here."""


def add_plot_options(sp: argparse.ArgumentParser, what: str) -> None:
    """``--plot FILE`` and ``--plot-csv FILE`` on a subcommand; ``what`` says what the figure shows."""
    sp.add_argument("--plot", metavar="FILE", help=f"also draw {what} into FILE (.png, .svg or .pdf; needs "
                    "matplotlib: pip install 'liansuo[plot]')")
    sp.add_argument("--plot-csv", metavar="FILE", help="also write the data of that plot as CSV (no matplotlib needed)")


def plot_problem(args: argparse.Namespace) -> str:
    """Why the ``--plot`` / ``--plot-csv`` files cannot be written, or matplotlib is missing; '' when all is well.
    Loads matplotlib only when ``--plot`` is given."""
    for option, value in (("--plot", args.plot), ("--plot-csv", args.plot_csv)):
        if value and (why := unwritable(Path(value), option)):
            return why
    if args.plot:
        if Path(args.plot).suffix.lower() not in FIGURE_SUFFIXES:
            return f"cannot draw {args.plot}: give --plot a file ending in .png, .svg or .pdf"
        try:
            pyplot()
        except PlotUnavailable as exc:
            return str(exc)
    return ""


def pyplot() -> Any:
    """matplotlib's pyplot on the file-only Agg backend (no display needed); :class:`PlotUnavailable` without it."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise PlotUnavailable(NEED_MATPLOTLIB) from None
    return plt


def new_figure(rows: int = 1, columns: int = 1, *, sharex: bool = False) -> tuple[Figure, Any]:
    """A figure of :data:`FIGURE_SIZE_IN` with ``rows`` x ``columns`` axes (an array of them unless 1 x 1)."""
    plt = pyplot()
    fig, axes = plt.subplots(rows, columns, figsize=FIGURE_SIZE_IN, dpi=FIGURE_DPI, sharex=sharex)
    return fig, axes


def save_figure(fig: Figure, path: str) -> str:
    """Write the figure (format from the suffix) and close it; '' or why it could not be written."""
    plt = pyplot()
    try:
        fig.tight_layout()
        fig.savefig(path, dpi=FIGURE_DPI, metadata=_metadata(path))
    except OSError as exc:
        return f"cannot write {path}: {exc.strerror or exc}; give --plot a file in a folder you can write to"
    finally:
        plt.close(fig)
    return ""


def _metadata(path: str) -> dict[str, Any] | None:
    """No timestamp or software version in a PNG or PDF, so the same command draws the same bytes."""
    suffix = Path(path).suffix.lower()
    if suffix == ".png":
        return {"Software": None}
    if suffix == ".pdf":
        return {"Producer": None, "Creator": None, "CreationDate": None}
    if suffix == ".svg":
        return {"Date": None, "Creator": None}
    return None


def write_rows(path: str, columns: Sequence[str], rows: Iterable[Mapping[str, object]]) -> str:
    """The rows as CSV with a header of ``columns``; '' or why the file could not be written."""
    try:
        with open(path, "w", encoding="utf-8", newline="") as out:
            writer = csv.DictWriter(out, fieldnames=list(columns), extrasaction="ignore")
            writer.writeheader()
            writer.writerows(rows)
    except OSError as exc:
        return f"cannot write {path}: {exc.strerror or exc}; give --plot-csv a file in a folder you can write to"
    return ""
