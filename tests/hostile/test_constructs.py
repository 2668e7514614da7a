"""The minimal programs the construct fuzzer (`tests/hostile/constructs.py`, run by
`test_fuzz.py`) reduced its faults to: each is refused at its place or followed, in bounded time
and memory, never a traceback."""

from __future__ import annotations

import re

import pytest

from ncpp.verify import MAX_CHORDS
from tests import rs274
from tests.conftest import RS274, SHARED

MACHINE = SHARED / "machines/wide.toml"
needs_machine = pytest.mark.skipif(not MACHINE.exists(), reason="shared machine file not found")


MODAL_TAP = "S300 M3\nG0 X0 Y0 Z5\nG33.1 Z-4 K1\nX1\nM2\n"  # (line 4: G33.1 again, without its K)


@pytest.mark.skipif(not RS274.exists(), reason="rs274 not available")
def test_rs274_refuses_a_modal_rigid_tap_block_without_its_k(tmp_path):
    program = tmp_path / "tap.ngc"
    program.write_text(MODAL_TAP)
    done = rs274.run(program, timeout=30)
    assert "K word missing with g33/g33.1" in done.stdout + done.stderr


def test_a_modal_rigid_tap_block_without_its_k_is_refused_as_rs274ngc_refuses_it(ncpp, tmp_path):
    program = tmp_path / "tap.ngc"
    program.write_text(MODAL_TAP)
    done = ncpp("motion", str(program), timeout=30)
    assert done.returncode == 2 and b"Traceback" not in done.stderr
    assert done.stderr.decode().endswith(f"{program}:4:1: K word missing with g33/g33.1\n")


def test_a_modal_rigid_tap_block_with_its_k_taps_again(ncpp, tmp_path):
    program = tmp_path / "tap.ngc"
    program.write_text("S300 M3\nG0 X0 Y0 Z5\nG33.1 Z-4 K1\nX1 K1\nM2\n")
    done = ncpp("motion", str(program), timeout=30)
    assert done.returncode == 0, done.stderr
    taps = [line for line in done.stdout.decode().splitlines() if line.startswith("RIGID_TAP")]
    assert taps == ["RIGID_TAP(0.0000, 0.0000, -4.0000)", "RIGID_TAP(1.0000, 0.0000, 5.0000)"]


@needs_machine
@pytest.mark.parametrize("depth", ["1" + "0" * 300, "1" + "0" * 8])
def test_a_cycle_left_as_programmed_far_past_any_travel_is_verified_in_bounded_memory(ncpp, tmp_path, depth):
    """A Sinumerik drilling cycle to 1e300 mm (or 1e8: a hundred million lookup points at 1 mm) is
    written as programmed; the verifier refuses the first at its line and reads the second
    along lookup points spaced wider, within 800 MB of address space."""
    program = tmp_path / "deep.mpf"
    program.write_text(f"G0 X10 Y20 Z50\nG1 F100\nCYCLE81(10, 0, 2, -{depth})\nM30\n")
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), "-o", str(tmp_path / "out.mpf"),
                memory_mb=800, timeout=30)  # fmt: skip
    assert b"Traceback" not in done.stderr and b"MemoryError" not in done.stderr
    if len(depth) > 100:
        assert done.returncode == 2
        assert done.stderr.decode().endswith(f"{program}:3:1: verification: a move too long to verify\n")
    else:
        assert done.returncode == 0, done.stderr


@needs_machine
def test_holes_of_a_modal_cycle_far_past_any_travel_are_refused_in_bounded_memory(ncpp, tmp_path):
    """Incremental MCALL CYCLE81 holes a thousand kilometres apart: moves the verifier cannot
    prove from their ends, whose points a quarter of the bound apart would number billions."""
    program = tmp_path / "far.mpf"
    program.write_text("G17 G90 G71 G94\nT1 D1\nM6\nG0 X10 Y20 Z50\nG1 F200 S500 M3\nG91\n"
                       "MCALL CYCLE81(-1000000000, 1000000000, 0, 7)\nHOLES1(-5, -5, , 0.0001, -20, 12)\n"
                       "MCALL\nM30\n")  # fmt: skip
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), "-o", str(tmp_path / "out.mpf"),
                memory_mb=800, timeout=30)  # fmt: skip
    said = done.stderr.decode()
    assert done.returncode == 2 and "Traceback" not in said, said
    assert f"{program}:8:1: verification: a move of 1,000,000,007 mm, too long to verify" in said, said


@needs_machine
def test_an_arc_round_a_centre_far_past_any_travel_is_refused_in_bounded_memory(ncpp, tmp_path):
    """A Klartext circle round a centre 1e300 mm away: its points lie far past the travel, and sampling it
    along chords within the tolerance would take 6 million; it is refused at its line (by the check of
    the commands or by the verifier, whichever meets it first), its position in powers of ten, no
    overflow warned."""
    program = tmp_path / "far.h"
    centre = "1" + "0" * 300
    program.write_text(f"0 BEGIN PGM M MM\n1 L X+0 Y+0 Z+50 R0 FMAX\n2 CC X+{centre} Y-5\n"
                       "3 C X+5 Y+4 DR+ F100\n4 END PGM M MM\n")  # fmt: skip
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), "-o", str(tmp_path / "out.h"),
                memory_mb=600, timeout=30)  # fmt: skip
    assert done.returncode == 2 and b"Traceback" not in done.stderr and b"Warning" not in done.stderr
    said = done.stderr.decode().splitlines()[-1]
    assert said == (
        f"{program}:4:1: verification: an arc of 6,283,186 chords within the tolerance is more than ncpp "
        f"verifies at once ({MAX_CHORDS:,}): split it, or give a wider --tolerance"
    ) or re.fullmatch(rf"{re.escape(str(program))}:4:5: command X[0-9.]+e\+2[0-9]{{2}} mm is outside the X travel "
                      r"\[-40000, 40000\] mm", said), said  # fmt: skip


def test_a_parameter_file_giving_an_additional_offset_twice_differently_is_refused_at_its_line(
    ncpp, tmp_path
):
    """#7001 (Fanuc's G54.1 P1) and #14001 (Haas's G154 P1) name one offset: told differently, the
    refusal names the line that completes the second."""
    var = tmp_path / "control.var"
    var.write_text("14001 7\n5221 0\n7003 1\n7001 7\n")
    program = tmp_path / "p.ngc"
    program.write_text("G0 X1\nM2\n")
    done = ncpp("motion", "--var-file", str(var), str(program), timeout=30)
    assert done.returncode == 2
    assert (
        done.stderr.decode()
        == f"{var}:4:1: parameters #7001 and #14001 both give additional work offset P1, and differ\n"
    )


@needs_machine
@pytest.mark.parametrize("after", ["G40\n", "G3 X-5 Y0 R5\nG40\n"])
def test_arcs_alone_under_cutter_compensation_are_compensated_without_a_traceback(ncpp, tmp_path, after):
    """The moves under G41 of a program (or of a batch of the passes) are arcs only: no line takes its
    tool-centre shift, and the arcs are compensated as any other."""
    program = tmp_path / "arcs.ngc"
    program.write_text("G21 G90 G17\nF100\nG41 D1\nG2 X0 Y5 R3\n" + after + "M2\n")
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), timeout=60)
    assert done.returncode == 0 and b"Traceback" not in done.stderr, done.stderr
    assert b"compensated 1 moves" in done.stderr or b"compensated 2 moves" in done.stderr, done.stderr
