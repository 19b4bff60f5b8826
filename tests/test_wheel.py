"""The wheel as a user gets it: built from the checkout, installed with its dependencies into a fresh virtual
environment outside the checkout, and run from another folder with no PYTHONPATH.

The rest of the suite runs against the editable install, where the checkout itself is on ``sys.path``: a data file
missing from ``[tool.setuptools.package-data]``, a layer folder without ``__init__.py`` or a top-level package that
should not be installed would all pass there and break ``pip install liansuo``. Here the installed ``liansuo`` runs
``verify`` (also on Dask workers), a route-test script, ``table``, the Python API, a bundled exercise, the console
headless, ``serve --web`` (a trainee, the instructor and a browser's console), the pytest plugin, ``--version``,
``completion``, the shipped JSON Schemas and ``--plot`` without the ``plot`` extra; a failure names the command that
failed, its folder, exit status, stdout and stderr.

pip installs the newest dependencies. With ``LIANSUO_WHEEL_RESOLUTION=lowest-direct`` (``make test-lowest``) uv
installs each at the floor pyproject.toml gives it, on the oldest Python it allows, and a test checks that every
floor is what got installed; with ``highest`` (``make test-newest``) uv installs the newest.

One build and one virtual environment serve every test of a run (a session fixture; some 25 s of CPU in all). Select
with ``pytest -m wheel``, leave out with ``-m 'not wheel'``. The skips: no package index is reachable and pip's cache
lacks a requirement, so the wheel can be neither built nor installed; the floors' test but under lowest-direct.
"""

from __future__ import annotations

import importlib.util
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import tomllib
import zipfile
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import pytest

pytestmark = pytest.mark.wheel

ROOT = Path(__file__).resolve().parents[1]
BIN = "Scripts" if os.name == "nt" else "bin"
# folders of the checkout the build does not read (the wheel is built from a copy, never from the checkout itself,
# so no build/ folder is left behind and no stale build/lib can hide a file the package data misses)
NOT_COPIED_AT_TOP = {".venv", ".git", "build", "dist", "tests"}
NOT_COPIED = {"__pycache__", ".pytest_cache", ".mypy_cache", ".ruff_cache", ".hypothesis"}
# environment variables that would let the installed package see the checkout or another environment
DROPPED_ENV = {"PYTHONPATH", "PYTHONHOME", "PYTHONSTARTUP", "VIRTUAL_ENV", "PYTHONUSERBASE"}
TAIL = 60  # lines of stdout and stderr shown when a command fails
# `lowest-direct` or `highest`: install with uv (python -m uv) at that resolution of the dependencies pyproject.toml
# declares, instead of with pip (make test-lowest, make test-newest); lowest-direct puts each at its floor
RESOLUTION = os.environ.get("LIANSUO_WHEEL_RESOLUTION", "")
FLOORS_SKIPPED = ("checks that each dependency is installed at its floor (the lowest version pyproject.toml allows), "
                  "which only 'make test-lowest' installs; this run installs the newest versions, so there is "
                  "nothing to check: not a failure, and 'make test-lowest' runs it")

ROUTE_SCRIPT = """\
station: jiaopei
tests:
  - name: receiving route opens and the home signal shows yellow
    steps:
      - route X XI
      - run 2s
      - expect route X XI open
      - expect signal X U
      - expect section IG locked
  - name: a conflicting route is refused
    steps:
      - route X XI
      - route S SI
      - expect refused conflicting
"""

API_CHECK = """\
import liansuo

print("package", liansuo.__file__)
sim = liansuo.Simulation("jiaopei")
r = sim.command("route X XI")
assert r.ok, r
sim.run(2)
print("route X-XI", sim.route_state("X-XI"), "signal X", sim.aspect("X"))
assert not sim.command("route X XY"), "a refused Result is false"
try:
    sim.aspect("NOSUCH")
except liansuo.UnknownId as exc:
    print("unknown", exc.kind, exc.id)
from importlib.resources import files

print("typed", files("liansuo").joinpath("py.typed").is_file())  # the marker type checkers look for
table = liansuo.build_table(liansuo.load_station("jiaopei"))
print("table", len(table.routes), "routes, X-XI conflicts with", ", ".join(sorted(table.routes["X-XI"].conflicts)[:3]))
from liansuo.proving.mutation.cli import default_stations  # the example stations install too: mutate runs on them

print("mutate stations", " ".join(s.rsplit("/", 1)[-1] for s in default_stations()))
"""

EXERCISE_CHECK = """\
from liansuo.classroom.exercise import bundled_exercises, check_goal, parse_exercise
from liansuo.simulation.sim import Simulation

print("bundled", " ".join(p.stem for p in bundled_exercises()))
ex = parse_exercise("jiaopei-broken-rail-IG")  # by name, as 'liansuo tui --exercise NAME' loads it
sim = Simulation(ex.station_ref())
for line in ex.setup:
    assert sim.command(line).ok, line
print("before", check_goal(sim, ex).reached)
assert sim.command("route X X3").ok
sim.run(15)
print("after", check_goal(sim, ex).reached, ex.title)
"""

# The console as tests/test_tui.py drives it: the operator clicks the X and XI train buttons on the diagram, time moves
# by cycles, and the lamp drawn next to signal X is read from the screen model.
CONSOLE_CHECK = """\
import asyncio

from liansuo.tui.app import ConsoleApp
from liansuo.tui.diagram import Diagram
from liansuo.tui.layout import Ref
from liansuo.tui.paint import LAMP_COLOUR, glyph


def lamp(app, signal):
    d = app.diagram
    d.update_view()
    for x, y in d.layout_.lamp_slots[signal]:
        g = d.layout_.at(x, y)
        if g is not None and g.slot == 0:
            ch, style = glyph(d.frame(), g, set())
            return ch, str(style.color.name if style.color else "")
    raise AssertionError(f"no lamp drawn for signal {signal}")


async def main():
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=(120, 36)) as pilot:
        await pilot.pause()  # the diagram centres itself after its first refresh
        print("lamp X before", *lamp(app, "X"), "red" if lamp(app, "X")[1] == LAMP_COLOUR["red"] else "not red")
        for button in ("X", "XI"):
            await pilot.click(Diagram, offset=app.diagram.offset_of(Ref("button", button, "train")))
            await pilot.pause()
        app.advance(8)
        app.refresh_views()
        print("answer", app.message_line.content)
        print("route X-XI", app.sim.route_state("X-XI"))
        after = lamp(app, "X")
        print("lamp X after", *after, "yellow" if after[1] == LAMP_COLOUR["yellow"] else "not yellow")


asyncio.run(main())
"""

# The classroom as tests/test_classroom_server.py serves it, with the browsers' console (textual-serve): a trainee and
# the instructor over websockets, then a browser's terminal, whose console must draw its login dialog.
SERVE_CHECK = """\
import os
import re
import subprocess
import sys
import time

import http.client as http_client
from urllib.parse import urlencode, urlsplit

from websockets.exceptions import InvalidStatus
from websockets.sync.client import connect

from liansuo.server.client import ClassroomClient

env = dict(os.environ, LIANSUO_INSTRUCTOR_PASSWORD="correct horse")
proc = subprocess.Popen([sys.argv[1], "serve", "--port", "0", "--web", "--web-port", "0"], stdout=subprocess.PIPE,
                        stdin=subprocess.DEVNULL, text=True, env=env)
try:
    first = proc.stdout.readline()
    print(first.strip())
    ws = first.split(" on ")[1].split(",")[0]
    http = first.split("browsers on ")[1].split()[0]
    with ClassroomClient.trainee(ws, seat=1, name="Li") as li:
        print("trainee", li.command("route X XI")["message"])
    with ClassroomClient.instructor(ws, "correct horse") as teacher:
        print("instructor", teacher.command("fault broken-rail IG", seat=2)["message"])
    base = http.replace("http:", "ws:") + "/ws?width=100&height=30"
    deadline = time.monotonic() + 60
    while True:  # the browsers' server starts a moment after the classroom's
        try:  # and a browser's console starts only after a login on the page
            with connect(base, open_timeout=10):
                print("browser console without a login")
            break
        except InvalidStatus as exc:
            print("browser refused before a login: HTTP", exc.response.status_code)
            break
        except OSError:
            if time.monotonic() > deadline:
                raise
            time.sleep(0.3)
    where = urlsplit(http)
    page = http_client.HTTPConnection(where.hostname, where.port, timeout=30)
    page.request("POST", "/login", body=urlencode({"role": "trainee", "seat": "2", "name": "Wang"}),
                 headers={"Content-Type": "application/x-www-form-urlencoded"})
    answer = page.getresponse()
    cookie = (answer.getheader("Set-Cookie") or "").split(";")[0]
    print("login", answer.status, "cookie" if cookie.startswith("liansuo_session=") else "no cookie")
    screen = ""
    deadline = time.monotonic() + 60
    with connect(base, additional_headers={"Cookie": cookie}, open_timeout=10) as browser:
        while "seat 2 of the classroom" not in screen and time.monotonic() < deadline:
            try:
                data = browser.recv(timeout=1)
            except TimeoutError:
                continue
            screen += data if isinstance(data, str) else data.decode("utf-8", "replace")
    text = re.sub(r"\\x1b\\[[0-9;?]*[A-Za-z]", "", screen)
    print("browser", "seat 2 console" if "seat 2 of the classroom" in text else "no console in:\\n" + text[-3000:])
finally:
    proc.terminate()
    proc.wait(10)
"""

PLUGIN_MODULES_CHECK = """\
import sys


def test_the_liansuo_plugin_is_loaded_and_light():
    loaded = sorted(m for m in sys.modules if m.startswith(("liansuo", "numpy", "textual", "pydantic", "networkx")))
    print("LOADED", " ".join(loaded))
"""


@dataclass
class Installed:
    """The fresh environment with the wheel installed, and a working folder outside the checkout."""

    wheel: Path
    source: Path  # the copy of the checkout the wheel was built from
    venv: Path
    work: Path
    env: dict[str, str] = field(repr=False)
    build_output: str = field(repr=False, default="")  # what 'pip wheel' printed
    core: dict[str, subprocess.CompletedProcess[str]] = field(repr=False, default_factory=dict)  # see CORE_RUNS

    @property
    def python(self) -> str:
        return str(self.venv / BIN / "python")

    @property
    def pip(self) -> list[str]:
        return [sys.executable, "-m", "pip", "--python", self.python]

    @property
    def liansuo(self) -> str:
        return str(self.venv / BIN / "liansuo")


def clean_env(venv: Path | None = None) -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in DROPPED_ENV and not k.startswith("PYTEST_")}
    if venv is not None:
        env["PATH"] = f"{venv / BIN}{os.pathsep}{env.get('PATH', '')}"
        env["VIRTUAL_ENV"] = str(venv)
        env.pop("PYTHONDONTWRITEBYTECODE", None)  # installed with --no-compile: let the first import write it
    return env


def describe(proc: subprocess.CompletedProcess[str], cwd: Path) -> str:
    def tail(text: str) -> str:
        lines = text.rstrip().splitlines()
        cut = [f"... ({len(lines) - TAIL} lines before)"] if len(lines) > TAIL else []
        return "\n".join(cut + lines[-TAIL:]) or "(empty)"

    return (f"$ {shlex.join(str(a) for a in proc.args)}\n  (in {cwd}, exit status {proc.returncode})\n"
            f"--- stdout ---\n{tail(proc.stdout)}\n--- stderr ---\n{tail(proc.stderr)}")


def run(args: Sequence[str | Path], cwd: Path, env: dict[str, str]) -> subprocess.CompletedProcess[str]:
    return subprocess.run([str(a) for a in args], cwd=cwd, env=env, capture_output=True, text=True, timeout=600,
                          check=False, stdin=subprocess.DEVNULL)


def must(what: str, args: Sequence[str | Path], cwd: Path, env: dict[str, str]) -> str:
    """Run a command that must exit 0; its stdout, or a failure that shows the command, stdout and stderr."""
    proc = run(args, cwd, env)
    if proc.returncode != 0:
        pytest.fail(f"wheel check: {what} failed\n{describe(proc, cwd)}", pytrace=False)
    return proc.stdout


def copy_source(dest: Path) -> Path:
    def ignore(folder: str, names: list[str]) -> set[str]:
        top = Path(folder).resolve() == ROOT
        return {n for n in names if n in NOT_COPIED or n.endswith(".egg-info") or (top and n in NOT_COPIED_AT_TOP)}

    shutil.copytree(ROOT, dest, symlinks=True, ignore=ignore)
    return dest


def unreachable(requirements: list[str], tmp: Path, *options: str) -> str:
    """Why pip cannot get these requirements from the index or its cache, or '' when it can."""
    pip: list[str | Path] = [sys.executable, "-m", "pip", "download", "--no-deps", *options, "--dest", tmp / "probe"]
    probe = run([*pip, *requirements], tmp, clean_env())
    return "" if probe.returncode == 0 else describe(probe, tmp)


def build_or_skip(what: str, args: Sequence[str | Path], cwd: Path, env: dict[str, str], requirements: list[str],
                  tmp: Path) -> subprocess.CompletedProcess[str]:
    """Run a step that needs the package index and return what it printed; skip only when pip can neither reach an
    index nor find the requirements in its cache, fail on anything else."""
    proc = run(args, cwd, env)
    if proc.returncode == 0:
        return proc
    why = unreachable(requirements, tmp)
    if not why:
        pytest.fail(f"wheel check: {what} failed (pip can get {', '.join(requirements)}, so the failure is the "
                    f"project's)\n{describe(proc, cwd)}", pytrace=False)
    if not unreachable(["pip"], tmp, "--no-cache-dir"):
        pytest.fail(f"wheel check: {what} failed: pip reaches a package index (it gets pip without its cache) but not "
                    f"{', '.join(requirements)}: is a requirement misspelt or pinned to no existing version?\n{why}\n"
                    f"{describe(proc, cwd)}", pytrace=False)
    pytest.skip(f"wheel check impossible here: no package index is reachable and pip's cache lacks some of "
                f"{', '.join(requirements)}, so the wheel cannot be {what}:\n{why}")


@pytest.fixture(scope="session")
def installed(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Installed]:
    tmp = tmp_path_factory.mktemp("wheel")
    assert not tmp.resolve().is_relative_to(ROOT), f"the temporary folder {tmp} is inside the checkout"
    try:
        yield install(tmp)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)  # the environment takes some 150 MB


def install(tmp: Path) -> Installed:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))
    source = copy_source(tmp / "source")
    dist = tmp / "dist"
    built = build_or_skip("built", [sys.executable, "-m", "pip", "wheel", "--no-deps", "--wheel-dir", dist, source],
                          tmp, clean_env(), list(project["build-system"]["requires"]), tmp)
    wheels = sorted(dist.glob("liansuo-*.whl"))
    assert len(wheels) == 1, f"pip wheel left {[w.name for w in dist.iterdir()]} in {dist}, expected one liansuo wheel"
    venv = tmp / "venv"
    # pytest too, for the wheel's pytest11 entry point (at the test extra's floor under lowest-direct)
    pytest_req = next(r for r in project["project"]["optional-dependencies"]["test"] if r.startswith("pytest>"))
    args: list[str | Path]
    if RESOLUTION:
        uv = [sys.executable, "-m", "uv"] if importlib.util.find_spec("uv") else [shutil.which("uv") or ""]
        if not uv[-1]:
            pytest.fail(f"LIANSUO_WHEEL_RESOLUTION={RESOLUTION} installs with uv: pip install uv", pytrace=False)
        # the lowest on the oldest Python requires-python allows, where every floor has wheels (uv finds that Python or
        # fetches it); the newest on this one
        python = project["project"]["requires-python"].removeprefix(">=") if RESOLUTION == "lowest-direct" \
            else sys.executable
        must(f"creating a fresh virtual environment (Python {python})", [*uv, "venv", "-q", "-p", python, venv], tmp,
             clean_env())
        # the dependencies named on the command line (-r pyproject.toml), so that lowest-direct resolves them to their
        # floors: as the wheel's own dependencies they would be transitive, at their newest
        args = [*uv, "pip", "install", "-q", "--python", venv / BIN / "python", "--resolution", RESOLUTION,
                "-r", source / "pyproject.toml", wheels[0], pytest_req]
    else:
        # without pip of its own: this pip installs into it (--python), which saves seconds and changes nothing
        # installed; bytecode is written as modules are first imported
        must("creating a fresh virtual environment", [sys.executable, "-m", "venv", "--without-pip", venv], tmp,
             clean_env())
        args = [sys.executable, "-m", "pip", "--python", venv / BIN / "python", "install", "--no-compile",
                "--no-warn-script-location", wheels[0], pytest_req]
    inst = Installed(wheels[0], source, venv, tmp / "work", clean_env(venv), built.stdout + built.stderr)
    inst.work.mkdir()
    build_or_skip("installed", args, tmp, inst.env, [*project["project"]["dependencies"], pytest_req], tmp)
    # what the core install alone does, before the extras join it for the console's, the classroom's and Dask's tests
    inst.core = {name: run(command(inst), inst.work, inst.env) for name, command in CORE_RUNS.items()}
    wanted = [f"{inst.wheel}[{','.join(EXTRAS)}]"]
    if RESOLUTION:  # named on the command line, so that lowest-direct takes the extras' floors too
        extra = [*uv, "pip", "install", "-q", "--python", venv / BIN / "python", "--resolution", RESOLUTION,
                 "-r", source / "pyproject.toml", *(f"--extra={e}" for e in EXTRAS), *wanted]
    else:
        extra = [*inst.pip, "install", "--no-compile", "--no-warn-script-location", *wanted]
    build_or_skip(f"installed the extras {', '.join(EXTRAS)}", extra, tmp, inst.env,
                  [r for e in EXTRAS for r in project["project"]["optional-dependencies"][e]], tmp)
    return inst


# the extras installed after the core's own runs, for the tests of the console, the classroom and Dask
EXTRAS = ("console", "serve", "cluster")
# commands run on the core install (no extra), by name: what is installed, and what needs an extra
CORE_RUNS: dict[str, Callable[[Installed], list[str]]] = {
    "pip list": lambda i: [*i.pip, "list", "--format", "json"],
    "tui": lambda i: [i.liansuo, "tui", "jiaopei"],
    "serve": lambda i: [i.liansuo, "serve", "jiaopei"],
    "verify --workers 2": lambda i: [i.liansuo, "verify", "jiaopei", "--workers", "2"],
    "soak": lambda i: [i.liansuo, "soak", "jiaopei", "--steps", "200"],
}


def test_the_wheel_holds_the_package_liansuo_only_and_every_file_of_it(installed: Installed) -> None:
    names = set(zipfile.ZipFile(installed.wheel).namelist())
    expected = set()
    for folder, dirs, files in os.walk(installed.source / "liansuo", followlinks=True):
        dirs[:] = [d for d in dirs if d not in NOT_COPIED]
        expected |= {(Path(folder) / f).relative_to(installed.source).as_posix() for f in files}
    missing = sorted(expected - names)
    assert not missing, ("files of the package are missing from the wheel (a data file needs a line in "
                         "[tool.setuptools.package-data] of pyproject.toml, a folder of modules an __init__.py):\n  "
                         + "\n  ".join(missing))
    out = must("pip show -f liansuo", [*installed.pip, "show", "-f", "liansuo"], installed.work,
               installed.env)
    files = [line.strip() for line in out.split("Files:", 1)[-1].splitlines() if line.strip()]
    roots = {f.split("/")[0] for f in files if not f.startswith("..") and ".dist-info/" not in f}
    assert roots == {"liansuo"}, f"pip show -f liansuo: the install adds the top-level names {sorted(roots)}, " \
                                 f"expected only liansuo/:\n{out}"
    assert any(f.endswith(f"{BIN}/liansuo") for f in files), f"no liansuo console script installed:\n{out}"


def test_the_build_prints_no_warning(installed: Installed) -> None:
    """Setuptools' deprecation warnings (a license given as a table, say) are printed by 'pip wheel' and by the first
    'make test'; the project's metadata must give none."""
    warnings = [line for line in installed.build_output.splitlines() if re.search(r"warning|deprecat", line, re.I)]
    assert not warnings, "pip wheel printed warnings:\n" + installed.build_output


@pytest.mark.skipif(RESOLUTION != "lowest-direct", reason=FLOORS_SKIPPED)
def test_each_dependency_is_at_its_floor_under_the_lowest_resolution(installed: Installed) -> None:
    """Under lowest-direct every dependency of pyproject.toml is installed at exactly the version its ``>=`` names: a
    floor that another dependency's own floor lifts (textual needing a newer rich, say) is one no run ever tests."""
    from packaging.requirements import Requirement
    from packaging.utils import canonicalize_name
    from packaging.version import Version

    out = must("pip list", [*installed.pip, "list", "--format", "json"], installed.work, installed.env)
    versions = {canonicalize_name(p["name"]): Version(p["version"]) for p in json.loads(out)}
    project = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))
    wrong = []
    declared = project["project"]["dependencies"] + [r for e in EXTRAS for r in project["project"][
        "optional-dependencies"][e]]
    for line in declared:
        req = Requirement(line)
        floors = [Version(s.version) for s in req.specifier if s.operator == ">="]
        got = versions.get(canonicalize_name(req.name))
        if floors and got != floors[0]:
            wrong.append(f"{line}: {req.name} {got} installed")
    assert not wrong, "the lowest resolution did not install these floors:\n  " + "\n  ".join(wrong)


def test_verify_passes_on_the_bundled_station(installed: Installed) -> None:
    for workers in ([], ["--workers", "2"]):  # here, and fanned out on Dask's local worker processes
        out = must(f"liansuo verify jiaopei {' '.join(workers)}", [installed.liansuo, "verify", "jiaopei", *workers],
                   installed.work, installed.env)
        last = out.strip().splitlines()[-1]
        assert last.startswith("PASS:") and " 0 failures" in last, f"liansuo verify jiaopei ended with: {last}"


def test_a_route_test_script_runs(installed: Installed) -> None:
    (installed.work / "route_test.yaml").write_text(ROUTE_SCRIPT, encoding="utf-8")
    out = must("liansuo test route_test.yaml", [installed.liansuo, "test", "route_test.yaml"], installed.work,
               installed.env)
    assert out.strip().splitlines()[-1] == "2 passed, 0 failed", f"liansuo test route_test.yaml:\n{out}"


def test_the_command_line_lists_stations_and_prints_the_table(installed: Installed) -> None:
    out = must("liansuo stations", [installed.liansuo, "stations"], installed.work, installed.env)
    assert all(name in out for name in ("jiaopei", "gaotie", "depot")), f"liansuo stations:\n{out}"
    out = must("liansuo table jiaopei", [installed.liansuo, "table", "jiaopei"], installed.work, installed.env)
    assert "联锁表" in out and "下行接车" in out and "至 IG" in out, f"liansuo table jiaopei:\n{out}"
    xlsx = installed.work / "jiaopei.xlsx"  # openpyxl, a dependency, installed from the registry
    must("liansuo table jiaopei --format xlsx", [installed.liansuo, "table", "jiaopei", "--format", "xlsx", "-o", xlsx],
         installed.work, installed.env)
    assert xlsx.stat().st_size > 0
    out = must("liansuo tui --help", [installed.liansuo, "tui", "--help"], installed.work, installed.env)
    assert "--exercise" in out, f"liansuo tui --help:\n{out}"


def test_the_public_api_runs_from_the_installed_package(installed: Installed) -> None:
    out = must("the public API (python -c ...)", [installed.python, "-c", API_CHECK], installed.work, installed.env)
    package = Path(out.split("package ", 1)[1].splitlines()[0]).resolve()
    assert package.is_relative_to(installed.venv.resolve()), f"liansuo was imported from {package}, not the venv"
    assert "route X-XI open signal X U" in out, f"the public API:\n{out}"
    assert "table 25 routes" in out, f"the public API:\n{out}"
    assert "unknown signal NOSUCH" in out and "typed True" in out, f"the public API:\n{out}"
    assert "danxian.yaml" in out and "shuangxian.yaml" in out, f"the example stations are not installed:\n{out}"


def test_a_bundled_exercise_loads_by_name_and_its_goal_is_reached(installed: Installed) -> None:
    out = must("a bundled exercise (python -c ...)", [installed.python, "-c", EXERCISE_CHECK], installed.work,
               installed.env)
    assert "jiaopei-broken-rail-IG" in out.splitlines()[0], f"the bundled exercises:\n{out}"
    assert "before False" in out and "after True A broken rail in IG" in out, f"the bundled exercise:\n{out}"


def test_the_console_sets_a_route_headless(installed: Installed) -> None:
    script = installed.work / "console_check.py"
    script.write_text(CONSOLE_CHECK, encoding="utf-8")
    out = must("the console headless (App.run_test)", [installed.python, script], installed.work, installed.env)
    for line in ("lamp X before ● #ff2020 red", "answer ✓ route X-XI selected", "route X-XI open",
                 "lamp X after ● #ffd700 yellow"):
        assert line in out, f"the console headless: no line {line!r} in\n{out}"


def test_the_classroom_serves_trainees_the_instructor_and_browsers(installed: Installed) -> None:
    script = installed.work / "serve_check.py"
    script.write_text(SERVE_CHECK, encoding="utf-8")
    out = must("liansuo serve --web (python serve_check.py)", [installed.python, script, installed.liansuo],
               installed.work, installed.env)
    for line in ("trainee route X-XI selected", "instructor fault injected: broken-rail IG",
                 "browser refused before a login: HTTP 403", "login 303 cookie", "browser seat 2 console"):
        assert line in out, f"liansuo serve --web: no line {line!r} in\n{out}"


def test_the_pytest_plugin_loads_light_and_runs_scripts(installed: Installed) -> None:
    (installed.work / "test_plain.py").write_text(PLUGIN_MODULES_CHECK, encoding="utf-8")
    out = must("pytest on a plain test", [installed.python, "-m", "pytest", "-s", "-p", "no:cacheprovider",
                                          "test_plain.py"], installed.work, installed.env)
    loaded = next((line.split("LOADED", 1)[1].split() for line in out.splitlines() if "LOADED" in line), None)
    assert loaded is not None, f"pytest on a plain test printed no LOADED line:\n{out}"
    assert "liansuo.proving.pytest_plugin" in loaded, f"the pytest11 entry point did not load the plugin: {loaded}"
    heavy = set(loaded) - {"liansuo", "liansuo.proving", "liansuo.proving.pytest_plugin",
                           "liansuo.kit", "liansuo.kit.native"}  # the pure switch (LIANSUO_PURE=1 in the suite)
    top = sorted({".".join(m.split(".")[:2]) if m.startswith("liansuo.") else m.split(".")[0] for m in heavy})
    assert not heavy, f"a pytest run that collects no script imports {top} ({len(heavy)} modules)"
    (installed.work / "test_routes.yaml").write_text(ROUTE_SCRIPT, encoding="utf-8")
    out = must("pytest on a route-test script", [installed.python, "-m", "pytest", "-p", "no:cacheprovider",
                                                 "test_routes.yaml"], installed.work, installed.env)
    assert "2 passed" in out.strip().splitlines()[-1], f"pytest test_routes.yaml:\n{out}"


SCHEMA_FILES_CHECK = """\
import json
from importlib.resources import files
from pathlib import Path

root = Path(str(files("liansuo")))
for kind in ("station", "script", "scenario", "exercise", "points"):
    path = root / "schemas" / f"{kind}-1.json"
    print(kind, json.loads(path.read_text(encoding="utf-8"))["$id"], path)
example = root / "examples" / "stations" / "minimal.yaml"
modeline = example.read_text(encoding="utf-8").splitlines()[0].split("$schema=", 1)[1]
print("modeline", (example.parent / modeline).resolve() == (root / "schemas" / "station-1.json").resolve())
"""


def test_version_completion_and_the_shipped_schemas(installed: Installed) -> None:
    project = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))
    out = must("liansuo --version", [installed.liansuo, "--version"], installed.work, installed.env)
    assert out == f"liansuo {project['project']['version']}\n", f"liansuo --version: {out!r}"
    out = must("liansuo completion bash", [installed.liansuo, "completion", "bash"], installed.work, installed.env)
    assert "complete " in out and "liansuo" in out, f"liansuo completion bash:\n{out}"
    out = must("the shipped schemas (python -c ...)", [installed.python, "-c", SCHEMA_FILES_CHECK], installed.work,
               installed.env)
    lines = dict(line.split(" ", 1) for line in out.splitlines())
    assert lines["modeline"] == "True", f"the example's modeline does not name the installed schema:\n{out}"
    for kind in ("station", "script", "scenario", "exercise", "points"):
        schema_id, path = lines[kind].split(" ", 1)
        assert schema_id == f"https://liansuo.dev/schema/{kind}-1.json", out
        assert Path(path).resolve().is_relative_to(installed.venv.resolve()), f"{kind} schema not installed: {path}"
        printed = must(f"liansuo schema {kind}", [installed.liansuo, "schema", kind], installed.work, installed.env)
        assert printed == Path(path).read_text(encoding="utf-8"), f"liansuo schema {kind} differs from {path}"


def test_the_documentation_pages_are_installed(installed: Installed) -> None:
    """The help names pages as 'liansuo docs TOPIC': the wheel carries them, away from any checkout."""
    listed = must("liansuo docs", [installed.liansuo, "docs"], installed.work, installed.env)
    assert "station-format" in listed and "verify" in listed, listed
    page = must("liansuo docs cluster", [installed.liansuo, "docs", "cluster"], installed.work, installed.env)
    assert page.startswith("# Running verify and soak on many processes"), page[:200]


def test_a_plot_without_the_plot_extra_says_how_to_get_it(installed: Installed) -> None:
    """The wheel's own dependencies leave matplotlib out: --plot then stops with one line and exit status 2, while
    --plot-csv, which needs nothing more, is written."""
    proc = run([installed.liansuo, "zpw", "gaotie", "--plot", "x2jg.png"], installed.work, installed.env)
    assert proc.returncode == 2, describe(proc, installed.work)
    assert proc.stderr == "liansuo zpw: the plots need matplotlib: pip install 'liansuo[plot]'\n", proc.stderr
    assert not (installed.work / "x2jg.png").exists()
    must("liansuo zpw gaotie --plot-csv x2jg.csv",
         [installed.liansuo, "zpw", "gaotie", "--section", "X2JG", "--plot-csv", "x2jg.csv"], installed.work,
         installed.env)
    assert (installed.work / "x2jg.csv").read_text(encoding="utf-8").startswith("section,case,position_m,")


def test_the_core_install_is_small_and_each_extra_is_named_where_it_is_needed(installed: Installed) -> None:
    """The core (no extra) loads, verifies and soaks stations; the console, the classroom server and the cluster
    are extras, and a command that needs one says which in one line with exit status 2."""
    listed = installed.core["pip list"]
    assert listed.returncode == 0, describe(listed, installed.work)
    names = {d["name"].lower().replace("_", "-") for d in json.loads(listed.stdout)}
    heavy = names & {"textual", "textual-serve", "websockets", "dask", "distributed", "aiohttp", "tornado"}
    assert not heavy, f"the core install pulls in {sorted(heavy)}"
    assert len(names) <= 25, f"the core install is {len(names)} packages: {sorted(names)}"
    soak = installed.core["soak"]
    assert soak.returncode == 0 and "0 violations" in soak.stdout, describe(soak, installed.work)
    for name, extra, what in (("tui", "console", "the operator console"), ("serve", "serve", "the classroom server"),
                              ("verify --workers 2", "cluster", "work on several processes")):
        proc = installed.core[name]
        assert proc.returncode == 2, describe(proc, installed.work)
        command = name.split()[0]
        assert proc.stderr.startswith(f"liansuo {command}: {what} needs the {extra} extra: "
                                      f"pip install 'liansuo[{extra}]' ("), proc.stderr
        assert proc.stderr.count("\n") == 1, proc.stderr


def test_field_mode_without_the_field_extra_says_how_to_get_it(installed: Installed) -> None:
    """pymodbus is the field extra: field-sim and the console's --field stop with one line and exit status 2, while
    field-map and check --points, which need nothing more, work from the installed package."""
    proc = run([installed.liansuo, "field-sim", "jiaopei", "--modbus", "127.0.0.1:5020"], installed.work,
               installed.env)
    assert proc.returncode == 2, describe(proc, installed.work)
    assert proc.stderr == "liansuo field-sim: field mode needs the field extra: pip install 'liansuo[field]' " \
                          "(pymodbus)\n", proc.stderr
    must("liansuo field-map jiaopei -o map.yaml", [installed.liansuo, "field-map", "jiaopei", "-o", "map.yaml"],
         installed.work, installed.env)
    out = must("liansuo check jiaopei --points map.yaml",
               [installed.liansuo, "check", "jiaopei", "--points", "map.yaml"], installed.work, installed.env)
    assert "field control of 16 sections, 7 turnouts, 11 signals" in out, out


def test_a_tree_that_lost_a_layer_or_a_needed_file_does_not_build(installed: Installed,
                                                                   tmp_path: Path) -> None:
    """A checkout that turned a folder into a file (links checked out as text) or lost the licence fails to build
    with a message, where setuptools alone would build a wheel without that layer and say nothing."""
    source = copy_source(tmp_path / "source")
    shutil.rmtree(source / "src" / "liansuo" / "tui")
    (source / "src" / "liansuo" / "tui").write_text("../tui", encoding="utf-8")
    (source / "LICENSE").unlink()
    proc = run([sys.executable, "-m", "pip", "wheel", "--no-deps", "--wheel-dir", tmp_path / "dist", source], tmp_path,
               clean_env())
    assert proc.returncode != 0, describe(proc, tmp_path)
    assert "liansuo cannot be built from this tree: LICENSE is missing; src/liansuo/tui is a file, not a folder of " \
           "the package" in proc.stdout + proc.stderr, describe(proc, tmp_path)
    assert not any((tmp_path / "dist").glob("*.whl")), "a wheel was left in dist"


def test_a_run_that_is_not_make_test_lowest_skips_the_floors_saying_why() -> None:
    """``make test`` reports one skipped test, the floors' (issue 46, item 10): its reason, printed by ``-rs``, says
    why, and the skip comes before any wheel is built."""
    env = {**clean_env(), "LIANSUO_WHEEL_RESOLUTION": "", "PYTHONPATH": os.environ.get("PYTHONPATH", "")}
    done = subprocess.run([sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-rs", "-m", "wheel",
                           f"{__file__}::test_each_dependency_is_at_its_floor_under_the_lowest_resolution"],
                          capture_output=True, text=True, env=env, cwd=ROOT, timeout=120)
    out = " ".join(done.stdout.split())
    assert done.returncode == 0 and "1 skipped" in out, out
    assert "SKIPPED [1] tests/test_wheel.py:" in out and FLOORS_SKIPPED in out, out
