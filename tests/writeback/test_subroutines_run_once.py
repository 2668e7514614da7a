"""Without --expand, a subroutine that runs once -- called once, from the main program's straight
code, and defined after the call (after M2, or a Fanuc subprogram after M30) or before it (an
o-word definition at the top, LinuxCNC's usual layout) -- is compensated where its definition
stands: its text runs once, so it can carry that run's corrections.  One that runs again, or whose
definition before the call is too far from the program's end for the lines written from it on to
be held, stays as programmed, with the warning.

Judged by oracles ncpp did not write: LinuxCNC's rs274 runs the written program, its feed moves'
end points are mapped through the machine the test writes by hand (`square`), and every programmed
point must be reached within 0.5 µm; pathcheck checks the same actions and path."""

from __future__ import annotations

import io

import numpy as np
import pytest

import ncpp.motion.once as once_module
from ncpp.errors import Warnings
from tests.writeback.test_expand_flow import _compensated, _feed_ends, _pathcheck, _worst_point_um
from tests.writeback.test_loops_run_once import _misses_um

HEAD = "G21 G90 G17\nG0 X0 Y0 Z10\nM3 S1200\nG0 X-150 Y-100 Z2\nG1 Z-2 F150\n"
BODY = "G1 X#1 Y#2 F500\nG1 X100 Y-140\nG2 X160 Y-80 I0 J60\n"
ONCE = {
    "an o-word subroutine after M2": HEAD
    + "o<body> call [160] [120]\nG1 X-100 Y150\nG0 Z10\nM2\no<body> sub\n"
    + BODY
    + "o<body> endsub\n",
    "Fanuc subprograms after M30, each called once": HEAD
    + "#1 = 160\n#2 = 120\nM98 P1001\nG1 X-100 Y150\nM98 P1002\nG0 Z10\nM30\nO1001\n"
    + BODY
    + "M99\nO1002\nG1 X-40 Y-20\nX0 Y-160\nM99\n",
}
TWICE = (
    HEAD
    + "o<body> call [160] [120]\nG1 X-100 Y150\no<body> call [160] [120]\nG0 Z10\nM2\no<body> sub\n"
    + BODY
    + "o<body> endsub\n"
)
DEFINED_BEFORE = (
    "o<body> sub\n"
    + BODY
    + "o<body> endsub\n"
    + HEAD
    + "o<body> call [160] [120]\nG1 X-100 Y150\nG0 Z10\nM2\n"
)
SIDE = "o<side> sub\n(the second one)\nG1 X-40 Y-20\nX0 Y-160\no<side> endsub\n"
BEFORE = {
    "an o-word subroutine at the top": DEFINED_BEFORE,
    "two at the top, each called once": "o<body> sub\n" + BODY + "o<body> endsub\n" + SIDE + HEAD
    + "o<side> call\no<body> call [160] [120]\nG1 X-100 Y150\nG0 Z10\nM2\n",
    "one before and one after": "o<body> sub\n" + BODY + "o<body> endsub\n" + HEAD
    + "o<body> call [160] [120]\no<side> call\nG1 X-100 Y150\nG0 Z10\nM2\n" + SIDE,
}  # fmt: skip
TWICE_BEFORE = (
    "o<body> sub\n"
    + BODY
    + "o<body> endsub\n"
    + HEAD
    + "o<body> call [160] [120]\nG1 X-100 Y150\no<body> call [160] [120]\nG0 Z10\nM2\n"
)
BODY_POINTS = [[160, 120, -2], [100, -140, -2], [160, -80, -2]]


@pytest.mark.parametrize("name", ONCE)
def test_a_subroutine_that_runs_once_is_compensated_where_it_is_defined(tmp_path, name):
    warned = io.StringIO()
    original, output = _compensated(tmp_path, ONCE[name], warnings=Warnings(stream=warned))
    assert _worst_point_um(original, output) <= 0.5
    assert "loop or subroutine" not in warned.getvalue()
    text = output.read_text()
    assert text.index("G2 X") > text.index("M30" if "M30" in text else "M2")  # (still at its definition)
    check = _pathcheck(original, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


@pytest.mark.parametrize("name", BEFORE)
def test_a_subroutine_defined_before_its_one_call_is_compensated_where_it_is_defined(tmp_path, name):
    """The lines written from the definition on are held until the run has been written: the run's
    lines stand in place of the definition's text, the program's lines after them."""
    warned = io.StringIO()
    original, output = _compensated(tmp_path, BEFORE[name], warnings=Warnings(stream=warned))
    assert _misses_um(original, output).max() <= 0.5
    assert "loop or subroutine" not in warned.getvalue()
    text = output.read_text()
    assert text.index("G2 X") < text.index("o<body> endsub") < text.index("o<body> call")
    assert text.count("o<body> call") == 1 and text.count("G21 G90 G17") == 1
    check = _pathcheck(original, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


def test_a_subroutine_run_once_in_a_program_ended_by_its_closing_percent_is_compensated(tmp_path):
    """A program between `%` lines ends at the second (LinuxCNC G-code manual, "File Requirements"),
    as at M2: nothing runs after it, so a subroutine called once there ran once."""
    warned = io.StringIO()
    program = "%\n" + DEFINED_BEFORE.replace("M2\n", "%\n")
    original, output = _compensated(tmp_path, program, warnings=Warnings(stream=warned))
    assert _misses_um(original, output).max() <= 0.5
    assert "loop or subroutine" not in warned.getvalue()
    check = _pathcheck(original, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


def test_of_two_defined_before_their_calls_the_one_called_once_is_compensated(tmp_path):
    """The lines held wait for both definitions: the one called twice is told to stay as
    programmed, the other's run is written at its definition."""
    calls = "o<side> call\no<body> call [160] [120]\no<side> call\nG1 X-100 Y150\nG0 Z10\nM2\n"
    program = "o<body> sub\n" + BODY + "o<body> endsub\n" + SIDE + HEAD + calls
    warned = io.StringIO()
    original, output = _compensated(tmp_path, program, warnings=Warnings(stream=warned))
    misses = _misses_um(original, output)
    ends = _feed_ends(original)[:, None, :]
    side = np.any(np.all(np.isclose(ends, [[-40, -20, -2], [0, -160, -2]]), axis=2), axis=1)
    assert misses[side].max() > 2.0 and misses[~side].max() <= 0.5  # (one side point is near the zero)
    assert SIDE in output.read_text() and BODY not in output.read_text()
    assert "warning: loop or subroutine" in warned.getvalue()
    check = _pathcheck(original, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


def test_a_subroutine_defined_before_and_never_called_is_written_as_it_stands(tmp_path):
    program = "o<body> sub\n" + BODY + "o<body> endsub\n" + HEAD + "G1 X-100 Y150\nG0 Z10\nM2\n"
    warned = io.StringIO()
    original, output = _compensated(tmp_path, program, warnings=Warnings(stream=warned))
    assert output.read_text().index("o<body> sub\n" + BODY + "o<body> endsub\nG21 G90 G17\n") > 0
    assert _misses_um(original, output).max() <= 0.5
    assert "loop or subroutine" not in warned.getvalue()


@pytest.mark.parametrize(
    ("name", "program"), [("called twice", TWICE), ("defined before, called twice", TWICE_BEFORE)]
)
def test_a_subroutine_called_twice_stays_as_programmed(tmp_path, name, program):
    warned = io.StringIO()
    original, output = _compensated(tmp_path, program, warnings=Warnings(stream=warned))
    misses = _misses_um(original, output)
    body = np.any(np.all(np.isclose(_feed_ends(original)[:, None, :], BODY_POINTS), axis=2), axis=1)
    assert misses[body].min() > 2.0  # (its text runs twice, or was written before the run: the error stays)
    assert misses[~body].max() <= 0.5
    assert "warning: loop or subroutine" in warned.getvalue()
    assert BODY in output.read_text()
    check = _pathcheck(original, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


@pytest.mark.parametrize(
    "program", [ONCE["an o-word subroutine after M2"], DEFINED_BEFORE], ids=["after", "before"]
)
def test_the_events_held_past_the_bound_leave_the_run_as_programmed(tmp_path, monkeypatch, program):
    monkeypatch.setattr(once_module, "MAX_ONCE", 3)
    warned = io.StringIO()
    original, output = _compensated(tmp_path, program, warnings=Warnings(stream=warned))
    assert BODY in output.read_text()
    assert "warning: loop or subroutine" in warned.getvalue()
    assert _misses_um(original, output).max() > 2.0


def test_a_definition_before_a_call_too_far_from_the_end_stays_as_programmed(tmp_path):
    """The writer holds the lines from a definition before its call to the program's end, where
    the run is told: past MAX_ONCE events the definition is written as it stands (memory stays
    flat), with the warning, and the lines after it as they come."""
    program = ("o<body> sub\n" + BODY + "o<body> endsub\n" + HEAD + _circle(12_000, 50, 100)
               + "o<body> call [160] [120]\nG1 X-100 Y150\nG0 Z10\nM2\n")  # fmt: skip
    warned = io.StringIO()
    original, output = _compensated(tmp_path, program, warnings=Warnings(stream=warned))
    assert output.read_text().startswith("(ncpp")
    assert "\no<body> sub\n" + BODY + "o<body> endsub\n" in output.read_text()
    assert "warning: loop or subroutine" in warned.getvalue()


FANUC = "%\nO1000\nG21 G90 G17\nG0 X0 Y0 Z10\nG0 X-150 Y-100 Z2\nG1 Z-2 F150\n"


def _fanuc(tmp_path, text: str) -> tuple[str, str]:
    from tests.writeback.conftest import compensate_file
    from tests.writeback.test_compensated_holes import MACHINE

    program = tmp_path / "O1000.nc"
    program.write_text(text)
    warned = io.StringIO()
    written = compensate_file(program, MACHINE, tmp_path, warnings=Warnings(stream=warned)).read_text()
    return written, warned.getvalue()


@pytest.mark.parametrize(
    "again",
    ["M98 P1001\n", "G65 P1001\n", "G66 P1001\nG1 X-60 Y150\nG67\n"],
    ids=["M98", "G65", "G66"],
)
def test_a_fanuc_subprogram_run_again_by_a_later_call_stays_as_programmed(tmp_path, again):
    text = (
        FANUC
        + "M98 P1001\nG1 X-100 Y150\n"
        + again
        + "G0 Z10\nM30\nO1001\nG1 X160 Y120 F500\nX100 Y-140\nM99\n%\n"
    )
    written, warned = _fanuc(tmp_path, text)
    assert "\nO1001\nG1 X160 Y120 F500\nX100 Y-140\nM99\n" in written
    assert "loop or subroutine" in warned


def test_a_subprogram_called_in_a_goto_loop_stays_as_programmed(tmp_path):
    """A backward GOTO over the call runs it again: the lines it goes back over run as a loop's."""
    text = (FANUC + "#1 = 0\nN10 #1 = #1 + 1\nM98 P1001\nIF [#1 LT 2] GOTO 10\nG0 Z10\nM30\n"
            "O1001\nG91 G1 X10 F500\nG90\nM99\n%\n")  # fmt: skip
    written, warned = _fanuc(tmp_path, text)
    assert "\nO1001\nG91 G1 X10 F500\nG90\nM99\n" in written
    assert "loop or subroutine" in warned


def test_a_subprogram_with_a_control_line_in_its_body_stays_as_programmed(tmp_path):
    text = (
        FANUC
        + "M98 P1001\nG0 Z10\nM30\nO1001\n#2 = 0\nWHILE [#2 LT 1] DO1\nG1 X160 Y120 F500\n#2 = #2 + 1\nEND1\nM99\n%\n"
    )
    written, warned = _fanuc(tmp_path, text)
    assert "\nG1 X160 Y120 F500\n" in written
    assert "loop or subroutine" in warned


def _circle(n: int, radius: float, centre: float) -> str:
    return "".join(
        f"X{centre + radius * np.cos(i / 50):.3f} Y{centre + radius * np.sin(i / 50):.3f}\n" for i in range(n)
    )


@pytest.mark.parametrize(
    ("before", "after", "body"),
    [(3000, 3000, 3000), (4000, 100, 8000), (100, 500, 9000), (8000, 8000, 1500)],
    ids=["even", "long body", "longest body", "long main"],
)
def test_a_long_run_is_verified_chunk_by_chunk_where_it_runs(tmp_path, before, after, body):
    """The verifier compares a long program a chunk of moves at a time, tagging each written line
    with how far the writer had read: the run's lines, written further on, are tagged as where they
    ran, and a chunk may end inside the run or after it."""
    text = (FANUC + _circle(before, 50, 100) + "M98 P1001\n" + _circle(after, 40, 150) + "G0 Z10\nM30\nO1001\n"
            + "G1 X10 Y10\n" + _circle(body, 30, -100) + "M99\n%\n")  # fmt: skip
    written, warned = _fanuc(tmp_path, text)
    assert "loop or subroutine" not in warned
    definition = written[written.index("\nO1001\n") :]
    assert definition.count("\n") > body  # (the run's lines, pieces and steps, at the definition)


@pytest.mark.parametrize(
    ("ahead", "before", "after", "body"),
    [(0, 2000, 2000, 2000), (0, 200, 300, 4400), (0, 5000, 100, 300), (0, 100, 5000, 300),
     (3000, 3000, 500, 50), (1000, 2000, 2000, 2000)],
    ids=["even", "long body", "long main before", "long main after", "defined mid-chunk", "defined mid-run"],
)  # fmt: skip
def test_a_long_run_defined_before_its_call_is_verified_chunk_by_chunk(tmp_path, ahead, before, after, body):
    """The lines held from the definition on are handed out after the run's lines, each tagged as
    where the writer wrote it: the verifier reads the written program in the same chunks (a chunk
    may end between the definition and the call, the definition's lines tagged as where the run is).
    The events from the definition to the program's end, its text and its run among them, fit
    MAX_ONCE; `ahead` moves come before the definition."""
    text = (HEAD + _circle(ahead, 50, 100) + "o<body> sub\nG1 X10 Y10 F500\n" + _circle(body, 30, -100)
            + "o<body> endsub\n" + _circle(before, 50, 100) + "o<body> call\n" + _circle(after, 40, 150)
            + "G0 Z10\nM2\n")  # fmt: skip
    warned = io.StringIO()
    original, output = _compensated(tmp_path, text, warnings=Warnings(stream=warned))
    assert "loop or subroutine" not in warned.getvalue()
    written = output.read_text()
    definition = written[written.index("o<body> sub") : written.index("o<body> endsub")]
    assert definition.count("\n") > body  # (the run's lines, pieces and steps, at the definition)


@pytest.mark.parametrize("breaking", ["a line of the run left out", "the run's lines in reverse"])
def test_the_verifier_refuses_a_run_written_wrong_at_a_definition_before_its_call(
    tmp_path, monkeypatch, breaking
):
    from ncpp.errors import NcppError
    from ncpp.program.dialects import iso

    released = iso._AtDefinition._released

    def broken(self):
        ran = {key: pieces for key, pieces in self.ran.items()}
        if breaking == "a line of the run left out":
            self.ran[next(reversed(ran))] = [([], None)]
        else:
            self.ran = dict(zip(ran, reversed(ran.values())))
        return released(self)

    monkeypatch.setattr(iso._AtDefinition, "_released", broken)
    with pytest.raises(NcppError):
        _compensated(tmp_path, DEFINED_BEFORE)


def test_a_run_held_past_the_bound_is_read_back_as_programmed(tmp_path):
    """Past MAX_ONCE events the input's run stays as programmed; the reading of the written program
    takes it so too, though its own lines would fit its larger hold."""
    text = (
        FANUC
        + "M98 P1001\nG1 X-100 Y150\nG0 Z10\nM30\nO1001\nG1 X10 Y10\n"
        + _circle(12_000, 30, -100)
        + "M99\n%\n"
    )
    written, warned = _fanuc(tmp_path, text)
    assert "loop or subroutine" in warned
    assert "\nO1001\nG1 X10 Y10\n" + _circle(12_000, 30, -100) + "M99\n" in written
