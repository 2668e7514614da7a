"""A Haas NGC program's own variables past #1000 (#10000-#10999, general purpose, kept at power off) and
values ncpp cannot know (a timer's): `#10002= #3020 - #10000`, the cycle timer a Haas shop's programs
start with, is no refusal; only a block that later reads #10002 is out of scope, where it reads it.
The programs are the shape of a real one's (a shop's `O00080 (VERTIKAL PLOSKOST)`); rs274, which
numbers its parameters to #5601, runs them without the timer line as the oracle."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT, SHARED
from tests.rs274 import pathcheck

WIDE = SHARED / "machines" / "wide.toml"
TIMER = "#10002= #3020 - #10000 \n"
HEAD = "%\nO00080 (VERTIKAL PLOSKOST)\n" + TIMER + "G00 G17 G40 G49 G80 G90\nG54 \n"
MOVES = "G00 X-170. Y-20. Z50.\nG01 Z-1. F2000.\nG01 X170.\nG01 Y-40.\nG00 Z150.\n"

pytestmark = pytest.mark.skipif(not WIDE.exists(), reason="the shared machine files are not here")


def compensate(tmp_path: Path, text: str) -> tuple[subprocess.CompletedProcess[str], Path, Path]:
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(text)
    command = ["compensate", "--machine", str(WIDE), "--dialect", "haas", "--no-guard", str(program)]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command, "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    return proc, program, out


def test_a_timer_kept_in_a_variable_leaves_the_moves_compensated(tmp_path):
    proc, program, out = compensate(tmp_path, HEAD + MOVES + "M30\n%\n")
    assert proc.returncode == 0, proc.stderr  # (refused: "Parameter number out of range")
    assert "left as programmed: nothing" in proc.stderr, proc.stderr
    written = out.read_text()
    assert TIMER in written
    twin, twin_out = tmp_path / "twin.nc", tmp_path / "twin-out.nc"  # (rs274 reads no #10002)
    twin.write_text(program.read_text().replace(TIMER, ""))
    twin_out.write_text(written.replace(TIMER, ""))
    pathcheck(twin, twin_out, "--tol-mm", "0.02")


def test_a_block_that_reads_the_unknown_value_is_out_of_scope_from_there(tmp_path):
    text = HEAD + MOVES + "#1= #10002 / 1000. \nG00 X[#1] Y0.\nG00 X0.\nM30\n%\n"
    proc, _, _ = compensate(tmp_path, text)
    assert proc.returncode == 0, proc.stderr
    # (#1, set from #10002, is as unknown: the move that reads it is where interpretation ends)
    whence = "#1, which line 11 set from #10002, which line 3 set from the control's system variable #3020"
    assert f"p.nc:12:5: warning: {whence}" in proc.stderr, proc.stderr
    assert "everything from line 12 on" in proc.stderr, proc.stderr


@pytest.mark.parametrize(
    ("assignment", "left"),
    [("", "everything from line 11 on"), ("#10005= -40. \n", "left as programmed: nothing")],
)
def test_a_kept_variable_reads_only_what_the_program_set(tmp_path, assignment, left):
    """#10005 holds what an earlier run left there, which ncpp is not told: not read as 0."""
    proc, _, _ = compensate(tmp_path, HEAD + assignment + MOVES + "G01 Y#10005 F2000.\nM30\n%\n")
    assert proc.returncode == 0, proc.stderr
    assert left in proc.stderr, proc.stderr
    if not assignment:
        kept = "#10005, a variable the control keeps from before the program"
        assert f"p.nc:11:5: warning: {kept}" in proc.stderr, proc.stderr


def test_expand_refuses_to_write_a_number_for_an_unknown_value(tmp_path):
    """Written out, a loop's assignments go: the written program would set #5 to a number after the
    loop, where the control reads its timer: refused, located, not a guessed 0."""
    loop = "#1= 0.\nWHILE [ #1 LT 2. ] DO1\n#1= #1 + 1.\n#5= #3020\nG01 X[#1 * 10.] F500.\nEND1\n"
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(HEAD + "G00 X0. Y0. Z10.\n" + loop + "G00 Z50.\nM30\n%\n")
    command = ["compensate", "--machine", str(WIDE), "--dialect", "haas", "--no-guard", "--expand"]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command, str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 2 and not out.exists()
    assert (
        "p.nc:13:1: --expand: #5, which line 10 set from the control's system variable #3020" in proc.stderr
    )


def test_expand_writes_a_loop_out_after_the_timer(tmp_path):
    """The timer set before the loop keeps its line; the loop's moves are written out, compensated."""
    loop = "#1= 0.\nWHILE [ #1 LT 2. ] DO1\n#1= #1 + 1.\nG01 X[#1 * 10.] F500.\nEND1\n"
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(HEAD + "G00 X0. Y0. Z10.\n" + loop + "G00 Z50.\nM30\n%\n")
    command = ["compensate", "--machine", str(WIDE), "--dialect", "haas", "--no-guard", "--expand"]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command, str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0 and "left as programmed: nothing" in proc.stderr, proc.stderr
    written = out.read_text()
    assert TIMER in written and "#10002=" not in written.replace(TIMER, "")
