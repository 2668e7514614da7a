"""LinuxCNC's rs274 as the oracle for the shop tests: accepted or not, and the end points it moves to."""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

import pytest

from ncpp.motion.segments import PLANE_AXES
from tests.conftest import RS274

CALL = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|SELECT_PLANE)\((.*)\)")
PLANE_NAMES = {"CANON_PLANE_XY": 17, "CANON_PLANE_XZ": 18, "CANON_PLANE_YZ": 19}


def run_rs274(path: Path) -> str:
    """rs274's canonical calls for a program; fails the test on any rs274 error."""
    if not RS274.exists():
        pytest.skip("rs274 oracle not available")
    proc = subprocess.run(
        [str(RS274), str(path)],
        capture_output=True,
        text=True,
        errors="replace",
        timeout=300,
        stdin=subprocess.DEVNULL,
    )
    if "executing" not in proc.stderr:
        pytest.skip(f"rs274 oracle did not run: {proc.stderr.strip()[:200]}")
    messages = [line for line in proc.stderr.splitlines() if line.strip() and line.strip() != "executing"]
    assert proc.returncode == 0 and not messages, f"rs274 refused {path.name}: {messages[:3]}"
    return proc.stdout


def linuxcnc_root(scratch: Path) -> Path:
    """Where the tools/rs274 wrapper unpacked Debian's linuxcnc-uspace (rs274, AXIS, QtVCP):
    it downloads the package on its first run (or the test is skipped)."""
    empty = scratch / "empty.ngc"
    empty.write_text("M2\n")
    run_rs274(empty)
    return Path(os.environ.get("RS274_HOME") or Path.home() / ".cache/ncpp-rs274") / "root"


def run_rs274_from(var_file: Path, program: Path, tool_table: str = "T1 P1 D6.0 Z0\n") -> str:
    """rs274's canonical calls, started from `var_file` and this tool table (the tools/rs274
    wrapper fixes its own).  The stand-alone rs274 reads both in inches."""
    home = linuxcnc_root(var_file.parent)
    env = {**os.environ, "LD_LIBRARY_PATH": f"{home}/usr/lib:{home}/usr/lib/x86_64-linux-gnu"}
    table = var_file.with_suffix(".tbl")
    table.write_text(tool_table)
    proc = subprocess.run([str(home / "usr/bin/rs274"), "-t", str(table), "-v", str(var_file), "-g", str(program)],
                          capture_output=True, text=True, env=env, stdin=subprocess.DEVNULL, timeout=60)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return proc.stdout


def end_points(canon: str) -> list[tuple[float, float, float]]:
    """XYZ end point of every move rs274 reports, in program coordinates."""
    plane = 17
    ends = []
    for name, args in CALL.findall(canon):
        if name == "SELECT_PLANE":
            plane = PLANE_NAMES[args.strip()]
            continue
        values = [float(v) for v in re.split(r"[,\s]+", args.strip()) if v]
        if name == "ARC_FEED":
            i, j, n = PLANE_AXES[plane]
            point = [0.0, 0.0, 0.0]
            point[i], point[j], point[n] = values[0], values[1], values[5]
            ends.append((point[0], point[1], point[2]))
        else:
            ends.append((values[0], values[1], values[2]))
    return ends
