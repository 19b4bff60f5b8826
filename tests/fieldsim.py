"""``liansuo field-sim`` run as a second process for the field-mode tests (docs/field-mode.md)."""

from __future__ import annotations

import socket
import subprocess
import sys
import threading
import time

STATION = "jiaopei"


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


class FieldSim:
    """``liansuo field-sim`` in its own process: its stdin takes the instructor's commands, its stdout is read
    line by line in a thread."""

    def __init__(self, port: int, *extra: str) -> None:
        self.port = port
        self.proc = subprocess.Popen([sys.executable, "-m", "liansuo", "field-sim", STATION, "--modbus",
                                      f"127.0.0.1:{port}", *extra], stdin=subprocess.PIPE,
                                     stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.lines: list[str] = []
        first = self.proc.stdout.readline() if self.proc.stdout else ""
        assert first.startswith(f"field-sim {STATION}: modbus 127.0.0.1:{port}"), \
            first + (self.proc.stderr.read() if self.proc.stderr else "")
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.append(line.rstrip("\n"))

    def send(self, line: str, answer: str = "", timeout: float = 10.0) -> str:
        """Send an instructor's line; wait for a reply line containing ``answer``."""
        assert self.proc.stdin is not None
        seen = len(self.lines)
        self.proc.stdin.write(line + "\n")
        self.proc.stdin.flush()
        return self.wait_for(answer, seen, timeout)

    def wait_for(self, text: str, since: int = 0, timeout: float = 10.0) -> str:
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            for line in self.lines[since:]:
                if text in line:
                    return line
            time.sleep(0.02)
        raise AssertionError(f"no line with {text!r} from field-sim: {self.lines[-10:]}")

    def kill(self) -> None:
        self.proc.kill()
        self.proc.wait()

    def stop(self) -> None:
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(5)
            except subprocess.TimeoutExpired:
                self.kill()
