"""LinuxCNC's rs274, the tests' oracle, run one way: `../shared/tools/rs274` (tests/conftest.py
RS274, which unpacks Debian's linuxcnc-uspace once under $RS274_HOME) on a program's file or text,
started from a parameter file and a tool table, with 4 or 7 decimals; and what it prints read.

rs274 keeps its tool data in $HOME/.tool.mmap: the test run has a $HOME of its own
(tests/conftest.py), and `home` gives a run one of its own besides."""

from __future__ import annotations

import functools
import os
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import pytest

from ncpp.motion.segments import PLANE_AXES
from tests.conftest import RS274, SHARED

PATHCHECK = SHARED / "tools" / "pathcheck"

EXECUTING = "executing"  # what rs274 says on stderr as it starts the program
# rs274's note on a program without `%` or M2 at its end: a warning, not a refusal
EOF_NOTE = "File ended with no percent sign or program end"
CALL = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|SELECT_PLANE)\((.*)\)")
PLANE_NAMES = {"CANON_PLANE_XY": 17, "CANON_PLANE_XZ": 18, "CANON_PLANE_YZ": 19}


def run(
    program: Path | str,
    *,
    var_file: Path | None = None,
    tool_table: Path | None = None,
    digits: int = 4,
    ini: Path | None = None,
    home: Path | None = None,
    cwd: Path | None = None,
    timeout: float = 120,
    retries: int = 0,
) -> subprocess.CompletedProcess[str]:
    """rs274's run of `program` (a file, or a program's text, run from a file of a folder of its
    own): stdout the canonical calls, stderr `EXECUTING` and its messages.  It starts from
    `var_file` and `tool_table` (None: the wrapper's own, G54 selected and T1 6 across), prints
    `digits` (4 or 7) decimals, reads `ini` (its SUBROUTINE_PATH), keeps its tool data under
    `home`; a run that dies of a bus error is run again up to `retries` times.  The test is
    skipped where rs274 is not there."""
    if not RS274.exists():
        pytest.skip("rs274 oracle not available")
    if isinstance(program, str):
        folder = Path(tempfile.mkdtemp(prefix="ncpp-rs274-"))
        try:
            (folder / "program.ngc").write_text(program)
            return run(folder / "program.ngc", var_file=var_file, tool_table=tool_table, digits=digits,
                       ini=ini, home=home, cwd=cwd, timeout=timeout, retries=retries)  # fmt: skip
        finally:
            shutil.rmtree(folder, ignore_errors=True)
    env = dict(os.environ, RS274_DIGITS=str(digits))
    for name, value in (("RS274_VAR_FILE", var_file), ("RS274_TOOL_TABLE", tool_table), ("HOME", home)):
        if value is not None:
            env[name] = str(value)
    command = [str(RS274), *(("-i", str(ini)) if ini is not None else ()), str(program)]
    for _ in range(retries + 1):
        done = subprocess.run(command, capture_output=True, text=True, errors="replace", env=env, cwd=cwd,
                              timeout=timeout, stdin=subprocess.DEVNULL)  # fmt: skip
        if "Bus error" not in done.stderr:
            break
    return done


def ran(done: subprocess.CompletedProcess[str]) -> bool:
    """Whether rs274 started the program (it did not where it could not be unpacked or loaded)."""
    return EXECUTING in done.stderr


def messages(done: subprocess.CompletedProcess[str]) -> list[str]:
    """rs274's messages: the lines of its stderr but `EXECUTING`."""
    return [line for line in done.stderr.splitlines() if line.strip() and line.strip() != EXECUTING]


def error(stderr: str) -> tuple[str, str] | None:
    """(message, source text) of the error rs274 stopped at, if any (rs274 prints both on stderr)."""
    lines = [line for line in stderr.splitlines() if line.strip() and line != EXECUTING]
    if len(lines) < 2 or lines[0] == EOF_NOTE:
        return None
    return lines[0], lines[1]


def canon(program: Path | str, **options) -> str:
    """The canonical calls of a program rs274 must accept (`run`'s options): the test is skipped
    where rs274 did not run, and fails on any message of rs274's."""
    done = run(program, **options)
    if not ran(done):
        pytest.skip(f"rs274 oracle did not run: {done.stderr.strip()[:200]}")
    said = messages(done)
    name = program.name if isinstance(program, Path) else "the program"
    assert done.returncode == 0 and not said, f"rs274 refused {name}: {said[:3]}"
    return done.stdout


@functools.cache
def many_tools() -> Path:
    """A tool table of tools 1-99 (0.01 across, in the stand-alone rs274's inches; length 0):
    programs changing tools, and the entry moves of cutter compensation, which rs274 refuses where
    they are not longer than the radius.  Written once per test session."""
    path = Path(tempfile.mkdtemp(prefix="ncpp-oracle-")) / "tools.tbl"
    path.write_text("".join(f"T{n} P{n} D0.01 Z0\n" for n in range(1, 100)))
    return path


def linuxcnc_root(scratch: Path) -> Path:
    """Where the tools/rs274 wrapper unpacked Debian's linuxcnc-uspace (rs274, AXIS, QtVCP): it
    downloads the package on its first run (or the test is skipped)."""
    empty = scratch / "empty.ngc"
    empty.write_text("M2\n")
    canon(empty)
    return Path(os.environ.get("RS274_HOME") or Path.home() / ".cache/ncpp-rs274") / "root"


def end_points(calls: str) -> list[tuple[float, float, float]]:
    """XYZ end point of every move rs274 reports (its canonical calls), in program coordinates."""
    plane = 17
    ends = []
    for name, args in CALL.findall(calls):
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


def calls_from(var_file: Path, program: Path, tool_table: str = "T1 P1 D6.0 Z0\n") -> str:
    """rs274's canonical calls of `program`, started from `var_file` and this tool table's text
    (written beside the var file); the stand-alone rs274 reads both in inches.  Fails the test where
    rs274 fails."""
    table = var_file.with_suffix(".tbl")
    table.write_text(tool_table)
    done = run(program, var_file=var_file, tool_table=table, timeout=60)
    if not ran(done):
        pytest.skip(f"rs274 oracle did not run: {done.stderr.strip()[:200]}")
    assert done.returncode == 0, done.stderr
    return done.stdout


def pathcheck(original: Path, rewritten: Path, *options: str) -> None:
    """`../shared/tools/pathcheck` on the two programs (rs274 runs both): the test fails where it
    finds the rewritten one doing other actions or leaving the path; skipped without the tools."""
    if not (RS274.exists() and PATHCHECK.exists()):
        pytest.skip("rs274 or pathcheck not available")
    import sys

    check = subprocess.run([sys.executable, str(PATHCHECK), str(original), str(rewritten), *options],
                           capture_output=True, text=True, timeout=600)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr
