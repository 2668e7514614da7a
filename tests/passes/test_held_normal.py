"""replace_arcs compensates an arc's normal axis for the direction it last moved in
(`replace_arcs.Motion`), and apply_error_map shifts only the pieces the machine holds the
other way."""

from __future__ import annotations

import io
import re

import pytest

from ncpp.motion.segments import Arc, Context, Line
from ncpp.passes.replace_arcs import HELD_LINES, Motion
from ncpp.pipeline import ErrorSource, process
from ncpp.program.blocks import Block
from tests.conftest import ROOT


def _line(start, end, line):
    return Line(start, end, False, 500.0, Block("G1", "\n", (), line), Context())


def _arc(start, end, centre, line, plane=17):
    return Arc(start, end, centre, -1, 500.0, Block("G2", "\n", (), line), Context(plane=plane))


def _arcs(batch):
    return [e for e in batch if type(e) is Arc]


def test_an_arc_takes_the_direction_its_normal_axis_last_moved_in():
    motion = Motion()
    batch = [
        _arc((10.0, 0.0, 0.0), (0.0, 10.0, 0.0), (0.0, 0.0, 0.0), 1),  # Z never moved: the mean
        _line((0.0, 10.0, 0.0), (0.0, 10.0, -2.0), 2),  # Z down
        _arc((0.0, 10.0, -2.0), (10.0, 0.0, -2.0), (0.0, 0.0, -2.0), 3),
        _line((10.0, 0.0, -2.0), (20.0, 0.0, -2.0), 4),  # X only: Z still held down
        _arc((20.0, 0.0, -2.0), (30.0, 0.0, -1.0), (25.0, 0.0, -2.0), 5),  # a helix rising: up
        _arc((30.0, 0.0, -1.0), (40.0, 0.0, -1.0), (35.0, 0.0, -1.0), 6),  # after it Z is held up
        _arc(
            (40.0, 0.0, -1.0), (40.0, 0.0, -1.0), (40.0, 5.0, -1.0), 7, plane=18
        ),  # XZ: Y's, down in line 3's arc
    ]
    assert motion.normals(batch, _arcs(batch)) == [0, -1, 1, 1, -1]
    # a batch later, the state goes on; a move older than HELD_LINES lines is not used
    later = _arc(
        (40.0, 0.0, -1.0), (50.0, 0.0, -1.0), (45.0, 0.0, -1.0), 5 + HELD_LINES
    )  # Z last moved in line 5
    assert Motion(motion.state).normals([later], [later]) == [1]
    stale = _arc((40.0, 0.0, -1.0), (50.0, 0.0, -1.0), (45.0, 0.0, -1.0), 6 + HELD_LINES)
    assert motion.normals([stale], [stale]) == [0]


@pytest.fixture(scope="module")
def source():
    return ErrorSource.from_machine_file(str(ROOT / "samples/machines/hr5b.toml"))


def test_pieces_of_arcs_after_a_plunge_are_shifted_less_often(source, monkeypatch):
    """Circles at depths reached by moves down: their pieces are compensated for Z held down.
    apply_error_map still shifts those whose own compensated Z creeps up a digit (the machine
    then holds Z up), but compensated for the mean, as before, every piece was shifted."""
    from ncpp.passes import apply_error_map, replace_arcs

    program = "G21 G90 G17 G0 X400 Y350 Z400\nG1 Z380 F300\n" + "".join(
        f"G1 X{420 + k % 5} Y350 Z{380 - k * 0.5:.1f}\nG2 X{420 + k % 5} Y350 I-20 J0\n" for k in range(20)
    )
    shift = apply_error_map._shift_arcs

    def shifted_pieces() -> tuple[int, int]:
        shifted: list[int] = []
        monkeypatch.setattr(
            apply_error_map, "_shift_arcs", lambda at, *rest: shifted.append(len(at)) or shift(at, *rest)
        )
        out = io.BytesIO()
        process(io.BytesIO(program.encode()), out, file="p.ngc", source=source, tolerance=0.001)
        return sum(shifted), len(re.findall(r"\bG2(?![\d.])", out.getvalue().decode()))

    guessed, pieces = shifted_pieces()
    monkeypatch.setattr(replace_arcs.Motion, "normals", lambda self, batch, arcs: [0] * len(arcs))
    mean, _ = shifted_pieces()
    assert pieces >= 80  # four quadrants a circle
    assert mean == pieces
    assert guessed < 0.6 * pieces
