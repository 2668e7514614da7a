"""A file whose last line has no newline (UGS's editor template ends so): when ncpp writes that block
as several lines (a correction's bridge before it, a guard's line after it), each of them must end
its line, or they run into one block (`G1 X0.0004 Y0G2 X-0.5 ...`) that the control refuses (two
motion codes, a repeated X) or reads as another move.  Judged by LinuxCNC's rs274 through pathcheck
on the input and the output, not by ncpp's reading of its own output."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT, RS274, SHARED

PATHCHECK = SHARED / "tools" / "pathcheck"
WIDE = SHARED / "machines" / "wide.toml"

# (dialect, program): the last move written in pieces on wide.toml, the last line without a newline
PROGRAMS = {
    "iso": "G21 G90 G17\nG0 X0 Y0 Z1\nG1 Z0 F100\nG1 X10 Y0",
    # UGS's GcodeTemplate.gcode (winder/Universal-G-Code-Sender), as written: inch, 270-degree arcs
    "grbl": "; Gcode for a circle\nG17 G20 G90 G94 G54 M0 M5 M9 ; Setup\nG0 Z0.25 F5\nX-0.5 Y0.\nG1 Z0.\n"
    "(arcs...)\nG2 X0. Y-0.5 I0.5 J0.\nG2 X-0.5 Y0. I0. J0.5",
}
MOTION = re.compile(r"G0*[0-3](?![0-9.])", re.IGNORECASE)


def compensate(program: Path, dialect: str, out: Path) -> str:
    command = ["compensate", "--machine", str(WIDE), "--dialect", dialect, str(program), "-o", str(out)]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    return out.read_text()


@pytest.mark.parametrize("dialect", sorted(PROGRAMS))
def test_the_lines_written_for_an_unended_last_line_each_end(tmp_path, dialect):
    if not WIDE.exists():
        pytest.skip("the shared machine file is not available")
    program = tmp_path / "p.nc"
    program.write_text(PROGRAMS[dialect])
    written = compensate(program, dialect, tmp_path / "out.nc")
    assert not written.endswith("\n")  # the last line stays as unended as it came
    for line in written.splitlines():
        code = line.split(";")[0].split("(")[0]
        assert len(MOTION.findall(code)) <= 1 and code.upper().count("X") <= 1, line


@pytest.mark.parametrize("dialect", sorted(PROGRAMS))
def test_rs274_reads_the_output_as_the_input_within_20_um(tmp_path, dialect):
    if not (RS274.exists() and PATHCHECK.exists() and WIDE.exists()):
        pytest.skip("rs274, pathcheck or the shared machine file not available")
    program = tmp_path / "p.ngc"
    program.write_text(PROGRAMS[dialect])
    out = tmp_path / "out.ngc"
    compensate(program, dialect, out)
    check = subprocess.run([sys.executable, str(PATHCHECK), str(program), str(out), "--tol-mm", "0.02"],
                           capture_output=True, text=True, timeout=600)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr
