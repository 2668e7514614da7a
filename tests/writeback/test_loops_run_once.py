"""Without --expand, the body of a loop that runs once where it stands (a `while` whose test fails
the second time, `repeat [1]`, a `do` that does not go back, a Fanuc `WHILE ... DO1` of one pass,
Sinumerik's FOR, WHILE and REPEAT ... UNTIL of one pass) is compensated in place: its text runs once, so it can carry that run's corrections.  A body whose
text runs again stays as programmed, with the warning.

Judged by oracles ncpp did not write: LinuxCNC's rs274 runs the written program, its feed moves'
end points are mapped through the machine the test writes by hand (`square`: scale errors and
squareness), and every programmed point must be reached within 0.5 µm; pathcheck checks the
same actions and path.  The Fanuc program, which rs274 does not read, is judged by its o-word
twin; the Sinumerik ones by the closed form of `closed_form.py` (the written numbers mapped through
a machine whose errors are linear in position)."""

from __future__ import annotations

import io

import numpy as np
import pytest

import ncpp.motion.once as once_module
from ncpp.errors import Warnings
from ncpp.pipeline import ErrorSource, process
from tests.compensation.test_dialect_cutter_comp import compensated as sinumerik_compensated
from tests.conftest import READING
from tests.writeback.closed_form import landed
from tests.writeback.conftest import compensate_file
from tests.writeback.test_compensated_holes import MACHINE, square
from tests.writeback.test_expand_flow import _compensated, _feed_ends, _pathcheck, _worst_point_um
from tests.writeback.test_sinumerik_expand import points as sinumerik_points

HEAD = "G21 G90 G17\nG0 X0 Y0 Z10\nM3 S1200\n"
ONCE = {
    "while that runs once": HEAD
    + """#<n> = 0
o1 while [#<n> LT 1]
  G0 X-150 Y-100 Z2
  G1 Z-2 F150
  G1 X160 Y120 F500
  #<n> = [#<n> + 1]
o1 endwhile
G0 Z10
M2
""",
    "repeat once, do once, a break": HEAD
    + """o1 repeat [1]
  G0 X120 Y-140 Z2
  G1 Z-1 F150
  G2 X180 Y-80 I0 J60 F400
o1 endrepeat
o2 do
  G1 X-170 Y90 F500
o2 while [0]
o3 while [1]
  G1 X-60 Y170
  o3 break
  G1 X0 Y0
o3 endwhile
G0 Z10
M2
""",
    "loops one after another, one in another": HEAD
    + """#<k> = 0
o1 repeat [1]
  G0 X-100 Y-100 Z2
  G1 Z-1 F150
  o2 repeat [1]
    G1 X150 Y-120 F500
  o2 endrepeat
  G1 X140 Y160
o1 endrepeat
o3 repeat [1]
  G1 X-130 Y150
o3 endrepeat
G0 Z10
M2
""",
}
# A loop run twice inside one of one pass: the inner body stays as programmed, the rest is compensated
TWICE_INSIDE = (
    HEAD
    + """o1 repeat [1]
  G0 X-100 Y-100 Z2
  G1 Z-1 F150
  o2 repeat [2]
    G1 X150 Y-120 F500
  o2 endrepeat
  G1 X140 Y160
o1 endrepeat
G0 Z10
M2
"""
)


def _misses_um(original, output) -> np.ndarray:
    """µm each of the original's feed end points is from the nearest point `output` feeds to on `square`."""
    wanted = _feed_ends(original)
    reached = square(_feed_ends(output), np.ones(3))
    return np.linalg.norm(wanted[:, None, :] - reached[None, :, :], axis=2).min(axis=1) * 1000


@pytest.mark.parametrize("name", ONCE)
def test_a_body_that_runs_once_is_compensated_in_place(tmp_path, name):
    warned = io.StringIO()
    original, output = _compensated(tmp_path, ONCE[name], warnings=Warnings(stream=warned))
    assert _worst_point_um(original, output) <= 0.5
    assert "loop or subroutine" not in warned.getvalue()
    check = _pathcheck(original, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


def test_a_loop_that_runs_twice_stays_as_programmed_inside_one_that_runs_once(tmp_path):
    warned = io.StringIO()
    original, output = _compensated(tmp_path, TWICE_INSIDE, warnings=Warnings(stream=warned))
    misses = _misses_um(original, output)
    twice = np.all(np.isclose(_feed_ends(original), [150, -120, -1]), axis=1)
    assert misses[twice].min() > 2.0  # (its text runs twice: the machine's error stays)
    assert misses[~twice].max() <= 0.5
    assert "p.ngc:8:1: warning: loop or subroutine" in warned.getvalue()
    check = _pathcheck(original, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


def test_a_fanuc_while_of_one_pass_is_compensated_as_its_o_word_twin(tmp_path):
    fanuc = """%
O1000
G21 G90 G17
G0 X0 Y0 Z10
#1 = 0
WHILE [#1 LT 1] DO1
G0 X-150 Y-100 Z2
G1 Z-2 F150
G1 X160 Y120 F500
#1 = #1 + 1
END1
G0 Z10
M30
%
"""
    twin = ONCE["while that runs once"].replace("M3 S1200\n", "")
    original, output = _compensated(tmp_path, twin)
    fanuc_original = tmp_path / "O1000.nc"
    fanuc_original.write_text(fanuc)
    written = compensate_file(fanuc_original, MACHINE, tmp_path).read_text()
    moves = [line for line in written.splitlines() if line.startswith(("G0 X", "G1 ", "X", "Y", "Z"))]
    twins = [
        line for line in output.read_text().splitlines() if line.strip().startswith(("G0 X", "G1 ", "X"))
    ]
    assert moves == [line.strip() for line in twins]  # the same corrected words, line for line
    assert _worst_point_um(original, output) <= 0.5


def test_a_first_pass_longer_than_the_bound_stays_as_programmed(monkeypatch):
    monkeypatch.setattr(once_module, "MAX_ONCE", 3)
    warned, out = io.StringIO(), io.BytesIO()
    machine = ErrorSource.from_machine_file(str(READING))
    process(io.BytesIO(ONCE["while that runs once"].encode()), out, file="t.ngc", source=machine,
            warnings=Warnings(stream=warned))  # fmt: skip
    assert "t.ngc:6:1: warning: loop or subroutine" in warned.getvalue()
    assert "G1 X160 Y120 F500" in out.getvalue().decode()  # (left as programmed)


def test_a_backward_goto_over_a_loop_run_once_in_place_is_not_followed(tmp_path):
    """The loop's text may be rewritten for its one run, and the jump could run it again: the
    jump leaves the scope (as one over any move that ran in its place), and the loop, whose
    pass the program has not gone on from when it leaves, stays as programmed."""
    program = tmp_path / "O1002.nc"
    program.write_text("%\nO1002\nG21 G90 G17\nG0 X0 Y0 Z10\n#1 = 0\n#2 = 0\n#3 = 10\nN10 #2 = #2 + 1\n"
                       "WHILE [#1 LT #2] DO1\nG91 G1 X10 F300\n#1 = #1 + 1\nEND1\nIF [#2 LT 2] GOTO#3\n"
                       "G90 G0 Z10\nM30\n%\n")  # fmt: skip
    warned = io.StringIO()
    written = compensate_file(program, MACHINE, tmp_path, warnings=Warnings(stream=warned)).read_text()
    assert "O1002.nc:13:1: warning: GOTO 10 back over moves that ran once in their place" in warned.getvalue()
    assert "\nG91 G1 X10 F300\n" in written


# Sinumerik: FOR of one pass, a REPEAT ... UNTIL whose test holds at once, a WHILE of one pass;
# the points each reaches (a square at Z-1, then three corners)
SINUMERIK_ONCE = """DEF INT I
G17 G90 G71
G0 X-5 Y-5 Z5
FOR I=1 TO 1
  G1 X0 Y0 Z-1 F300
  X40
  Y40
  X0
  Y0
ENDFOR
R1=0
REPEAT
  R1=R1+1
  G1 X60 Y-20
UNTIL R1>=1
WHILE R1<2
  R1=R1+1
  G1 X-30 Y70
ENDWHILE
G0 Z5
M30
"""
SINUMERIK_POINTS = [
    (0, 0, -1),
    (40, 0, -1),
    (40, 40, -1),
    (0, 40, -1),
    (0, 0, -1),
    (60, -20, -1),
    (-30, 70, -1),
]
# a WHILE run twice inside a FOR of one pass: its point stays as programmed, the others do not
SINUMERIK_TWICE_INSIDE = """G17 G90 G71
G0 X-5 Y-5 Z5
FOR R2=1 TO 1
  G1 X0 Y0 Z-1 F300
  R1=0
  WHILE R1<2
    R1=R1+1
    G1 X50 Y-40
  ENDWHILE
  G1 X70 Y30
ENDFOR
G0 Z5
M30
"""


def test_a_sinumerik_loop_of_one_pass_is_compensated_in_place(tmp_path):
    """Closed form (`tests/writeback/closed_form.py`): the written numbers mapped through the
    machine's formula land within 0.5 µm of every programmed point; the control lines stay."""
    written, messages = sinumerik_compensated(tmp_path, "once.mpf", SINUMERIK_ONCE)
    assert landed(sinumerik_points(written), SINUMERIK_POINTS).max() < 0.5e-3
    assert "loop or subroutine" not in messages
    assert all(line in written for line in ("FOR I=1 TO 1", "ENDFOR", "REPEAT", "UNTIL R1>=1", "ENDWHILE"))


def test_a_sinumerik_loop_run_twice_stays_as_programmed_inside_one_of_one_pass(tmp_path):
    written, messages = sinumerik_compensated(tmp_path, "twice.mpf", SINUMERIK_TWICE_INSIDE)
    misses = landed(sinumerik_points(written), [(0, 0, -1), (50, -40, -1), (70, 30, -1)])
    assert misses[1] > 2e-3 and max(misses[0], misses[2]) < 0.5e-3
    assert "twice.mpf:8:1: warning: loop or subroutine" in messages
