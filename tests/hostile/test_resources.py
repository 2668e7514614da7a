"""Memory stays flat in the length of a loop, and a loop that never ends is refused at a bound."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import SHARED

ROOT = Path(__file__).resolve().parents[2]
MACHINE = SHARED / "machines/wide.toml"
# (the peak of this process's own memory: /proc's VmHWM; getrusage's maxrss keeps that of the
# process it was forked from, the test runner's, across exec)
_PEAK = """import resource, runpy, sys
sys.argv = ["ncpp", *sys.argv[1:]]
try:
    runpy.run_module("ncpp", run_name="__main__")
except SystemExit as done:
    code = done.code
try:
    with open("/proc/self/status") as status:
        peak = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
except (OSError, StopIteration):
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
print("PEAK_KB", peak, file=sys.stderr)
"""


def peak_kb(*args: str) -> int:
    """The peak resident memory of `ncpp ARGS` (its own process)."""
    done = subprocess.run(
        [sys.executable, "-c", _PEAK, *args],
        capture_output=True,
        text=True,
        timeout=300,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )
    assert "Traceback" not in done.stderr, done.stderr
    return int(done.stderr.rsplit("PEAK_KB", 1)[1])


@pytest.mark.skipif(not MACHINE.exists(), reason="no shared machine file")
@pytest.mark.parametrize("verify", [(), ("--no-verify",)], ids=["verified", "unverified"])
@pytest.mark.parametrize(
    "body, times",
    [
        ("G83 X10 Y10 Z-20 R2 Q0.01\nG80\n", 40),  # a canned cycle of 2000 pecks a pass
        ("G1 X1 Y1\nG1 X0 Y0\n", 40_000),
    ],
)
def test_compensating_a_loop_takes_the_same_memory_however_often_it_runs(tmp_path, body, times, verify):
    def program(times: int) -> str:
        path = tmp_path / f"loop{times}.ngc"
        path.write_text(f"G21 G17 G90 F200\nG0 X0 Y0 Z5\no100 repeat [{times}]\n{body}o100 endrepeat\nM2\n")
        return str(path)

    few, many = (
        peak_kb("compensate", "--machine", str(MACHINE), program(n), "-o", str(tmp_path / "out.nc"), *verify)
        for n in (2, times)
    )
    assert many - few < 12_000, (few, many)  # (each pass kept: 1.7 MB more a pass of the cycle)


@pytest.mark.skipif(not MACHINE.exists(), reason="no shared machine file")
def test_a_loop_run_once_around_one_run_often_takes_bounded_memory(tmp_path):
    """The first pass of the outer loop is held until the program goes on past its end
    (`Interpreter.run`, ONCE): the inner loop's passes in it are held up to a bound, not all."""

    def program(times: int) -> str:
        path = tmp_path / f"loop{times}.ngc"
        path.write_text(f"G21 G17 G90 F200\nG0 X0 Y0 Z5\no1 repeat [1]\nG0 X5\no100 repeat [{times}]\n"
                        "G1 X1 Y1\nG1 X0 Y0\no100 endrepeat\no1 endrepeat\nM2\n")  # fmt: skip
        return str(path)

    few, many = (
        peak_kb("compensate", "--machine", str(MACHINE), program(n), "-o", str(tmp_path / "out.nc"))
        for n in (2, 40_000)
    )
    assert many - few < 12_000, (few, many)
