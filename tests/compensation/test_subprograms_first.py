"""A Fanuc file that holds its subprograms before its main program: a control stores each O program of
a file as its own, the operator runs the main one (which ends with M30), and M98 runs a subprogram
(which ends with M99) where it is called (Fanuc Series 0i-MC operator's manual, B-64124EN,
"Subprogram (M98, M99)").  A subprogram the main program calls once is compensated where its text
stands, for the place that call puts it; one called twice stays as programmed.

Judged by oracles ncpp did not write: LinuxCNC's rs274 runs the twins of the input and of the output
with the subprogram moved after M30 (a string edit here; rs274 finds a Fanuc-style `O2000 ... M99`
there), their feed moves' end points mapped through the machine `square` writes by hand: every
programmed point is reached within 0.2 µm, where the uncompensated program misses by microns;
pathcheck runs the twins along the same path with the same actions."""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np

from ncpp.errors import Warnings
from tests.writeback.conftest import compensate_file
from tests.writeback.test_compensated_holes import MACHINE
from tests.writeback.test_expand_flow import _feed_ends, _pathcheck
from tests.writeback.test_loops_run_once import _misses_um

SUB = "O2000 (SIDE)\nG91 G1 X120 F300\nG3 X40 Y40 I0 J40\nG1 Y80\nG90\nM99\n"
HEAD = "O1000 (MAIN)\nG21 G90 G54 G17\nG0 X-150 Y-100 Z5\nG1 Z-2 F200\n"
ONCE = "%\n" + SUB + HEAD + "M98 P2000\nG1 X-100 Y150\nG0 Z5\nM30\n%\n"
TWICE = "%\n" + SUB + HEAD + "M98 P2000\nG1 X-100 Y150\nM98 P2000\nG0 Z5\nM30\n%\n"
LIMIT_UM = 0.2
MAIN_POINTS = [[-150, -100, -2], [-100, 150, -2]]  # the main program's own feed moves' ends


def twin(path: Path) -> Path:
    """The file with its first program, `O2000` to its M99, moved after M30, where rs274 runs it."""
    text = path.read_text()
    sub = re.search(r"^O2000.*?^M99\n", text, re.M | re.S)[0]  # type: ignore[index]
    moved = path.with_name(path.stem + "-twin.ngc")
    moved.write_text(text.replace(sub, "", 1).replace("M30\n", "M30\n" + sub, 1))
    return moved


def compensated(tmp_path: Path, program: str, **options) -> tuple[Path, Path, str]:
    original = tmp_path / "p.nc"
    original.write_text(program)
    warned = io.StringIO()
    output = compensate_file(original, MACHINE, tmp_path, warnings=Warnings(stream=warned), dialect="fanuc",
                             **options)  # fmt: skip
    return original, output, warned.getvalue()


def test_a_subprogram_called_once_is_compensated_where_it_stands_for_where_the_call_runs_it(tmp_path):
    original, output, warned = compensated(tmp_path, ONCE)
    assert "ncpp runs O1000 (MAIN) as the main program" not in warned  # (the name as written, no comment)
    assert "ncpp runs O1000 as the main program; O2000 is a subprogram" in warned
    assert "loop or subroutine" not in warned and "outside" not in warned, warned
    text = output.read_text()
    assert text.index("G3 X") < text.index("O1000") and SUB not in text  # (its text rewritten in place)
    assert _misses_um(twin(original), twin(original)).max() > 2.0  # (the measure finds the machine's error)
    assert _misses_um(twin(original), twin(output)).max() < LIMIT_UM
    check = _pathcheck(twin(original), twin(output), "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


def test_expanded_the_call_is_written_out_and_lands_on_the_path(tmp_path):
    original, output, warned = compensated(tmp_path, TWICE, expand=True)
    text = output.read_text()
    assert "M98" not in text and text.index(SUB) < text.index("O1000")  # (stored as it stands, not run)
    assert _misses_um(twin(original), twin(output)).max() < LIMIT_UM


def test_a_subprogram_called_twice_stays_as_programmed_and_the_rest_is_compensated(tmp_path):
    original, output, warned = compensated(tmp_path, TWICE)
    assert SUB in output.read_text() and "warning: loop or subroutine" in warned
    misses = _misses_um(twin(original), twin(output))
    ends = _feed_ends(twin(original))
    main = np.any(np.all(np.isclose(ends[:, None, :], MAIN_POINTS), axis=2), axis=1)
    assert len(misses) == 8 and main.sum() == 2
    assert misses[~main].min() > 2.0 and misses[main].max() < LIMIT_UM, (ends, misses)
