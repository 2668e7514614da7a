"""LinuxCNC's rigid tap G33.1 compensated, judged by oracles ncpp did not write: rs274 prints each
tap (RIGID_TAP, from where the tool stands to the block's point, then back), a machine whose errors
are written here in closed form runs the rewritten program's taps, and they must lie on the
original's; pathcheck must accept the program."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.compensation.test_cutter_comp_accuracy import (
    MMOUNT,
    MMOUNT_TOOLS,
    MMOUNT_VAR,
    PATHCHECK,
    needs_oracles,
)
from tests.compensation.tool_centre import deviation, feed_moves
from tests.conftest import ROOT
from tests.writeback.conftest import linear_errors, machine_file

# X runs 100 µm/m long, Y 80 µm/m short, Z 50 µm/m long, and Z travels off straight in X and Y
# (docs/machine-file.md: EXZ, EYZ are the straightness of Z in X and Y)
TAPPING = machine_file("tapping", linear_errors(EXX=0.1, EYY=-0.08, EZZ=0.05, EXZ=0.1, EYZ=-0.06))


def closed_form(command: np.ndarray) -> np.ndarray:
    """Where TAPPING's machine puts the tool for axis commands (n,3), mm."""
    x, y, z = command[:, 0], command[:, 1], command[:, 2]
    return command + np.column_stack([1e-4 * x + 1e-4 * z, -0.8e-4 * y - 0.6e-4 * z, 0.5e-4 * z])


# M6 taps at the top of a plate, in G90 and G91, one with the return's speed factor I, one in inches
TAPS = """G21 G90 G17 G94
T1 M6 G43
S300 M3
G0 X120 Y-80 Z40
G0 Z5
G33.1 Z-20 K1
G0 X-150 Y160
G33.1 Z-20 K1 I2
G0 X200 Y200
G91 G33.1 Z-25 K1
G90 G0 Z40
G20
G0 X-4 Y-4 Z0.2
G33.1 Z-0.8 K0.05
G0 Z2
M5
M2
"""
TOOLS = "T1 P1 Z2.0 D0.2362 ;M6 tap, 60 mm long\n"  # (inches: the stand-alone rs274 reads its table so)


def _written(tmp_path: Path, text: str, machine: str = TAPPING, *options: str) -> tuple[Path, Path, Path]:
    (tmp_path / "machine.toml").write_text(machine)
    program, out, tools = tmp_path / "taps.ngc", tmp_path / "taps.out.ngc", tmp_path / "tool.tbl"
    program.write_text(text)
    tools.write_text(TOOLS)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "machine.toml"),
                           "--tool-table", str(tools), "--var-units", "inch", *options, str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=300, stdin=subprocess.DEVNULL)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return program, out, tools


@needs_oracles
def test_each_tap_runs_on_the_programmed_line_within_half_a_micron(tmp_path):
    """Each tap's top and bottom (rs274's RIGID_TAP, from where the tool stands), run on the
    machine, on the original's tap: within 0.5 µm, from several µm as programmed."""
    program, out, tools = _written(tmp_path, TAPS)
    before, after = (feed_moves(p, tools, home=tmp_path) for p in (program, out))
    assert len(after) == len(before) == 4  # every tap stays one G33.1 block
    assert deviation(before, before, closed_form).max() > 0.004
    assert deviation(before, after, closed_form).max() < 0.0005
    for mine, theirs in zip(after, before):  # the tool reaches the programmed bottom
        assert np.linalg.norm(closed_form(mine.end[None])[0] - theirs.end) < 0.0005
    check = subprocess.run([sys.executable, str(PATHCHECK), str(program), str(out), "--tool-table", str(tools)],
                           capture_output=True, text=True, timeout=300)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


@needs_oracles
def test_a_machine_with_reversal_errors_gets_no_step_inside_a_tap(tmp_path):
    """HR5B's tables have reversal errors: ncpp puts a step where an axis reverses, but a tap's way
    down and back are one block, the control's: each G33.1 stays one block, with its K and I."""
    machine = (ROOT / "samples/machines/hr5b.toml").read_text()
    text = TAPS.replace("G0 X120 Y-80 Z40", "G0 X120 Y-80 Z40\nG1 Z45 F500")
    program, out, _ = _written(tmp_path, text, machine, "--work-offset", "400,350,300")
    lines = out.read_text().splitlines()
    taps = [line for line in lines if "G33.1" in line]
    assert len(taps) == 4 and all(" K" in line for line in taps) and " I2" in taps[1]
    for k, line in enumerate(lines):  # the block before each tap is the positioning the program wrote
        if "G33.1" in line:
            assert lines[k - 1].startswith(("G0", "G20")), lines[k - 2 : k + 1]


def test_ncpp_motion_prints_the_taps_as_rs274_does(tmp_path):
    """`ncpp motion` prints RIGID_TAP where rs274 does, with nothing for the return."""
    program = tmp_path / "taps.ngc"
    program.write_text(TAPS)
    done = subprocess.run([sys.executable, "-m", "ncpp", "motion", str(program)],
                          capture_output=True, text=True, cwd=ROOT, timeout=60)  # fmt: skip
    assert done.returncode == 0, done.stderr
    calls = done.stdout.splitlines()
    taps = [c for c in calls if c.startswith("RIGID_TAP")]
    assert taps == [
        "RIGID_TAP(120.0000, -80.0000, -20.0000)",
        "RIGID_TAP(-150.0000, 160.0000, -20.0000)",
        "RIGID_TAP(200.0000, 200.0000, -20.0000)",  # (G91: 25 mm down from Z5)
        "RIGID_TAP(-4.0000, -4.0000, -0.8000)",
    ]
    after = calls[calls.index(taps[2]) + 1]  # G91's tap returns to Z5, where G90 Z40 goes from
    assert after == "STRAIGHT_TRAVERSE(200.0000, 200.0000, 40.0000, 0.0000, 0.0000, 0.0000)"


@pytest.mark.parametrize(
    "line, message",
    [
        ("G33.1 Z-20", "K word missing with g33/g33.1"),
        ("G33.1 Z-20 K1 F100", "F word used with a g33/g33.1"),
        ("M5\nG33.1 Z-20 K1", "Spindle not turning in G33.1"),
        ("G33.1 Z-20 K1 J1", "J word with no G2"),
    ],
)
def test_a_tap_rs274_refuses_is_refused(tmp_path, line, message):
    """The messages are rs274ngc's."""
    program = tmp_path / "bad.ngc"
    program.write_text(f"G21 G90\nS300 M3\nG0 X10 Y10 Z5\n{line}\nM2\n")
    done = subprocess.run([sys.executable, "-m", "ncpp", "motion", str(program)],
                          capture_output=True, text=True, cwd=ROOT, timeout=60)  # fmt: skip
    assert done.returncode != 0 and message in done.stderr, done.stderr


@pytest.mark.parametrize(
    "dialect, text",
    [
        ("fanuc", "%\nO1000\nG21 G90\nS300 M3\nG0 X10 Y10 Z5\nG33.1 Z-20 K1\nG0 X20\nM30\n%\n"),
        ("iso", "G21 G90\nT1 M6\nS300 M3\nG0 X10 Y10 Z5\nG41 D1 G1 X20 F100\nG33.1 Z-20 K1\nG40\nM2\n"),
        ("iso", "G21 G90\nS300 M3\nG0 X10 Y10 Z5 A0\nG33.1 Z-20 K1 A10\nG0 X20\nM2\n"),
    ],
    ids=["fanuc-has-none", "under-cutter-compensation", "turning-a"],
)
def test_a_tap_ncpp_cannot_follow_passes_through(tmp_path, dialect, text):
    """Fanuc taps rigidly with M29 and G84, rs274ngc offsets no tap under cutter compensation and
    drops a rotary axis word from one: from there the program passes through, with a warning."""
    program, out = tmp_path / "taps.nc", tmp_path / "taps.out.nc"
    program.write_text(text)
    (tmp_path / "machine.toml").write_text(TAPPING)
    tools = tmp_path / "tool.tbl"
    tools.write_text("T1 P1 Z0 D0.2\n")
    done = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "machine.toml"),
                           "--dialect", dialect, "--tool-table", str(tools), str(program), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=60)  # fmt: skip
    assert done.returncode == 0, done.stderr
    tail = text[text.index("G33.1") :]
    assert out.read_text().endswith(tail) and "G33.1" in done.stderr


@needs_oracles
@pytest.mark.skipif(not MMOUNT.exists(), reason="corpus not available")
def test_the_motor_mount_written_out_cuts_twenty_times_closer(tmp_path):
    """LinuxCNC's mmount.ngc with --expand (its subroutine's helical holes written where they run),
    three work offsets and six tools: every feed move (contours under G41, helices, drilled and
    tapped holes) of the tool centre, run on the machine, at least 20 times closer to the
    original's path than the original's own, and all its feed path compensated."""
    var, tools = tmp_path / "mmount.var", tmp_path / "mmount.tbl"
    var.write_text(MMOUNT_VAR)
    tools.write_text(MMOUNT_TOOLS)
    (tmp_path / "machine.toml").write_text(TAPPING)
    original, out, report = tmp_path / "mmount.ngc", tmp_path / "mmount.out.ngc", tmp_path / "report.json"
    original.write_text(MMOUNT.read_text())
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "machine.toml"),
                           "--var-file", str(var), "--tool-table", str(tools), "--var-units", "inch", "--expand",
                           "--report", str(report), str(original), "-o", str(out)],
                          capture_output=True, text=True, cwd=ROOT, timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "left as programmed: nothing" in proc.stderr
    before, after = (feed_moves(p, tools, var, home=tmp_path) for p in (original, out))
    programmed, compensated = (deviation(before, moves, closed_form).max() for moves in (before, after))
    assert programmed > 0.04 and compensated * 20 < programmed, (programmed, compensated)


def test_the_summary_measures_a_taps_correction_at_its_bottom(tmp_path):
    """The tap's block ends at its bottom as the control runs it (its return is the control's):
    the summary's largest correction is there, where Z's straightness moves it most."""
    (tmp_path / "machine.toml").write_text(TAPPING)
    program, report = tmp_path / "deep.ngc", tmp_path / "report.json"
    program.write_text("G21 G90\nS300 M3\nG0 X0 Y0 Z5\nG33.1 Z-200 K1\nG0 Z50\nM2\n")
    done = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(tmp_path / "machine.toml"),
                           "--report", str(report), str(program), "-o", str(tmp_path / "out.ngc")],
                          capture_output=True, text=True, cwd=ROOT, timeout=60)  # fmt: skip
    assert done.returncode == 0, done.stderr
    said = json.loads(report.read_text())
    bottom = closed_form(np.array([[0.0, 0.0, -200.0]]))[0] - np.array([0.0, 0.0, -200.0])
    assert said["largest_correction_line"] == 4
    assert abs(said["largest_correction_um"] - np.linalg.norm(bottom) * 1000) < 0.5
