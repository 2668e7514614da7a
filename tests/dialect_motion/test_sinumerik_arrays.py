"""Sinumerik array variables (Job Planning manual, "Definition and initialization of array
variables (DEF, SET, REP)"): indices from 0, up to two dimensions, elements in row order;
`SET(a, b, ...)` assigns from the element named on, `REP(v)` every element from it to the end."""

from __future__ import annotations

import pytest

from ncpp.errors import NcppError
from tests.dialect_motion.test_sinumerik_flow import _run, _xs


def test_an_array_set_and_read_moves_where_its_elements_say():
    events, warned = _run(
        "DEF REAL A[3]=SET(1,2,3)\nDEF REAL B[2,3]=REP(4)\nG1 F100\nA[1]=A[0]+5\nX=A[1]\n"
        "B[1,2]=7\nX=B[1,2]\nX=B[0,0]\nA[1]=SET(8,9)\nX=A[2]\nM30\n"
    )
    assert warned == ""
    assert _xs(events) == [6.0, 7.0, 4.0, 9.0]


def test_an_int_array_rounds_and_a_loop_fills_it():
    events, warned = _run(
        "DEF INT P[4]\nDEF INT I\nG1 F100\nFOR I=0 TO 3\nP[I]=I*2.6\nENDFOR\nX=P[3]\nX=P[1]\nM30\n"
    )
    assert warned == ""
    assert _xs(events) == [8.0, 3.0]


@pytest.mark.parametrize(
    "program, said",
    [("DEF REAL A[3]\nX=A[3]\n", "outside the array A[3]"),
     ("DEF REAL A[2]=SET(1,2,3)\n", "more values than it holds"),
     ("DEF REAL A[2,2]\nX=A[1]\n", "outside the array")],
)  # fmt: skip
def test_an_index_outside_the_array_is_an_error_at_its_line(program, said):
    with pytest.raises(NcppError) as caught:
        _run("G1 F100\n" + program + "M30\n")
    assert said in str(caught.value) and "flow.mpf:" in str(caught.value)


def test_an_array_not_defined_here_ends_interpretation_with_a_warning():
    events, warned = _run("G1 F100 X1\nX=_P[1]\nX2\nM30\n")
    assert "the array _P (not defined in the program)" in warned and _xs(events) == [1.0]


def test_a_procedure_opening_the_program_is_followed_until_a_parameter_is_read():
    events, warned = _run(
        "PROC PART(VAR REAL _P[3], INT _N) SAVE\nDEF REAL A[2]=SET(3,4)\nG1 F100 X=A[1]\nX=_N\nX5\nM17\n"
    )
    assert _xs(events) == [4.0] and "the parameter _N (its value comes from the caller)" in warned


def test_the_header_goes_below_the_procedure_line(tmp_path):
    """The Job Planning manual has the PROC statement as the program's first block."""
    from tests.writeback.conftest import SQUARE, compensate_file

    program = tmp_path / "part.spf"
    program.write_text("PROC PART(REAL _D) SAVE\nG1 F100 X10 Y10\nX50\nM17\n")
    lines = compensate_file(program, SQUARE, tmp_path).read_text().splitlines()
    assert lines[0] == "PROC PART(REAL _D) SAVE" and lines[1].startswith("; ncpp compensated for")
