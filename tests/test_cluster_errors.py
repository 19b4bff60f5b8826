"""A Dask cluster that fails is one line and exit status 2, not a traceback with status 1 ("checks failed") (issue
44, item 4): a scheduler with no worker, no scheduler at the address, the last worker killed mid-run; with
``--format json`` the same as a JSON error object. And the local cluster opens no port beyond this machine.

Each test runs ``liansuo`` in a process of its own against a real ``dask scheduler`` (and ``dask worker``) started
here on 127.0.0.1, with ``--cluster-wait 1`` so that a missing worker is reported in about a second."""

from __future__ import annotations

import contextlib
import json
import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import psutil
import pytest

SRC = str(Path(__file__).resolve().parent.parent / "src")


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def liansuo(*argv: str, timeout: float = 120) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "liansuo", *argv], capture_output=True, text=True, timeout=timeout,
                          env=env(), check=False)


def env() -> dict[str, str]:
    return {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in (SRC, os.environ.get("PYTHONPATH")) if p)}


def dask(*argv: str) -> subprocess.Popen[bytes]:
    """``dask scheduler`` or ``dask worker`` in a process of its own (its chatter thrown away)."""
    return subprocess.Popen([sys.executable, "-m", "dask", *argv], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=env())


def stop(proc: subprocess.Popen[bytes]) -> None:
    if proc.poll() is None:
        proc.terminate()
        try:
            proc.wait(timeout=20)
        except subprocess.TimeoutExpired:
            proc.kill()
            proc.wait()


@pytest.fixture
def scheduler() -> Iterator[str]:
    """The address of a real Dask scheduler with no worker, on this machine."""
    port = free_port()
    proc = dask("scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard")
    deadline = time.monotonic() + 60
    while True:
        try:
            socket.create_connection(("127.0.0.1", port), timeout=1).close()
            break
        except OSError:
            assert proc.poll() is None and time.monotonic() < deadline, "the dask scheduler did not start"
            time.sleep(0.2)
    try:
        yield f"tcp://127.0.0.1:{port}"
    finally:
        stop(proc)


def one_line(done: subprocess.CompletedProcess[str], command: str, *words: str) -> str:
    """Exit status 2 and one line on stderr, ``liansuo COMMAND: ...`` with each of ``words``; no traceback."""
    assert done.returncode == 2, done.stderr
    assert "Traceback" not in done.stderr + done.stdout
    [line] = done.stderr.splitlines()
    assert line.startswith(f"liansuo {command}: ")
    for w in words:
        assert w in line, line
    return line


def json_error(done: subprocess.CompletedProcess[str], command: str, *words: str) -> None:
    assert done.returncode == 2, done.stderr
    report = json.loads(done.stdout)
    assert report["ok"] is False and report["error"]["status"] == 2
    assert report["error"]["file"] is None and report["errors"] == []
    for w in words:
        assert w in report["error"]["message"]
    assert one_line(done, command, *words).endswith(report["error"]["message"])


COMMANDS = {"verify": ["verify", "jiaopei", "--no-pairs"], "soak": ["soak", "jiaopei", "--steps", "20"]}


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_a_scheduler_without_workers_is_one_line_and_status_2(scheduler: str, command: str) -> None:
    start = time.monotonic()
    done = liansuo(*COMMANDS[command], "--scheduler", scheduler, "--cluster-wait", "1")
    assert time.monotonic() - start < 30  # no longer Dask's own 22 s wait for a worker, then a traceback
    one_line(done, command, f"the Dask scheduler at {scheduler} has no worker", f"'dask worker {scheduler}'",
             "leave out --scheduler")
    done = liansuo(*COMMANDS[command], "--scheduler", scheduler, "--cluster-wait", "1", "--format", "json")
    json_error(done, command, "has no worker")


def test_no_scheduler_at_the_address_is_one_line_and_status_2() -> None:
    address = f"tcp://127.0.0.1:{free_port()}"  # nothing listens there
    done = liansuo(*COMMANDS["verify"], "--scheduler", address, "--cluster-wait", "1")
    one_line(done, "verify", f"no Dask scheduler answers at {address}", "'dask scheduler'")
    json_error(liansuo(*COMMANDS["soak"], "--scheduler", address, "--cluster-wait", "1", "--format", "json"), "soak",
               "no Dask scheduler answers")
    one_line(liansuo(*COMMANDS["soak"], "--scheduler", "udp://x", "--cluster-wait", "1"), "soak",
             "is not the address of a Dask scheduler")


def test_the_cluster_wait_must_be_positive() -> None:
    done = liansuo(*COMMANDS["soak"], "--scheduler", "tcp://127.0.0.1:1", "--cluster-wait", "0")
    assert done.returncode == 2 and "--cluster-wait" in done.stderr and "Traceback" not in done.stderr


def test_the_last_worker_killed_mid_run_is_one_line_and_status_2(scheduler: str) -> None:
    from distributed import Client

    worker = dask("worker", scheduler, "--no-nanny", "--nthreads", "1")
    try:
        with Client(scheduler, timeout=30) as watch:  # to see the run start on the worker; it runs nothing itself
            watch.wait_for_workers(1, timeout=60)
            run = subprocess.Popen([sys.executable, "-m", "liansuo", "soak", "jiaopei", "--steps", "10000000",
                                    "--scheduler", scheduler, "--format", "json"], stdout=subprocess.PIPE,
                                   stderr=subprocess.PIPE, text=True, env=env())
            try:
                deadline = time.monotonic() + 60
                while not any(watch.processing().values()):
                    assert run.poll() is None and time.monotonic() < deadline, "the run did not start on the worker"
                    time.sleep(0.1)
                worker.send_signal(signal.SIGKILL)
                out, err = run.communicate(timeout=60)
            finally:
                if run.poll() is None:
                    run.kill()
                    run.communicate()
    finally:
        stop(worker)
    done = subprocess.CompletedProcess(run.args, run.returncode, out, err)
    json_error(done, "soak", f"the cluster at {scheduler} lost its last worker", f"'dask worker {scheduler}'")


def test_the_local_cluster_listens_on_this_machine_only() -> None:
    """``--workers N``: the scheduler, its HTTP server (the dashboard) and the workers on 127.0.0.1 (the dashboard
    was on 0.0.0.0)."""
    run = subprocess.Popen([sys.executable, "-m", "liansuo", "soak", "jiaopei", "--steps", "10000000", "--workers",
                            "1"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env())
    me = psutil.Process(run.pid)
    try:
        deadline = time.monotonic() + 90
        listening: set[tuple[str, int]] = set()
        while len(listening) < 2:  # the scheduler's port and the worker's at least
            assert run.poll() is None and time.monotonic() < deadline, f"the cluster did not start: {listening}"
            for p in [me, *me.children(recursive=True)]:
                try:
                    listening |= {(c.laddr.ip, c.laddr.port) for c in p.net_connections("inet")
                                  if c.status == psutil.CONN_LISTEN}
                except (psutil.NoSuchProcess, psutil.AccessDenied):
                    continue
            time.sleep(0.2)
        time.sleep(1)  # everything the cluster opens is open once its worker runs
        for p in [me, *me.children(recursive=True)]:
            listening |= {(c.laddr.ip, c.laddr.port) for c in p.net_connections("inet")
                          if c.status == psutil.CONN_LISTEN}
    finally:
        tree = [me, *me.children(recursive=True)]  # the command and the cluster it started, to end them by id
        for p in tree:
            with contextlib.suppress(psutil.NoSuchProcess):
                p.kill()
        run.wait()
        psutil.wait_procs(tree, timeout=20)
    assert listening and all(ip == "127.0.0.1" for ip, _ in listening), listening
