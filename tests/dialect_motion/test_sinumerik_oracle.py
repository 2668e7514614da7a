"""The Sinumerik interpreter against the CEAD nc-gcode-interpreter's expected outputs.

Every `.mpf` of the corpus folder has a `.csv` beside it: one row per block
with the axis positions the CEAD interpreter reached (machine coordinates,
TRANS included; the oracle runs `defaults.mpf` first, which sets X1600 Y900 Z0
and a few variables).  ncpp's positions after each move must agree with the
rows wherever the program stays in ncpp's scope; a program that leaves it
is listed in OUT_OF_SCOPE with the reason, and must still agree up to that
point.  A file neither agreeing nor listed fails.
"""

from __future__ import annotations

import csv
import io
import itertools
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import Arc, Line
from ncpp.motion.sinumerik import interpret
from ncpp.program.dialects import parse_program
from tests.conftest import CORPUS

FOLDER = CORPUS / "sinumerik" / "CEAD_nc-gcode-interpreter"
PRELUDE = "defaults.mpf"

OUT_OF_SCOPE = {
    "actual_position.mpf": "UNTIL on $AA_IW[Z] (the system variable of an axis position)",
    "axis_index_assignment.mpf": "ACC[E] array-style machine data",
    "edge_cases.mpf": "the assignment to ELX, an address the program does not define",
    "flattening__flatten_demo.mpf": "BSPLINE spline interpolation",
    "function_calls.mpf": "SETAL alarm call",
    "simple.mpf": "G2/G3 with neither I/J/K nor CR= (the oracle records modes; ncpp refuses a centreless arc) and G341",
    "spline.mpf": "BSPLINE/ASPLINE spline interpolation",
}
TOLERANCE = 0.0006  # the oracle writes 3 decimals
AXES = "XYZABC"  # the oracle's columns ncpp's moves are compared in (A B C: `Line.extra`)


def _programs() -> list[Path]:
    return sorted(p for p in FOLDER.glob("*.mpf") if p.name != PRELUDE)


def _oracle(program: Path) -> list[dict[str, float]]:
    path = program.with_suffix(".csv")
    if not path.exists():
        path = program.with_name(program.stem + "_raw.csv")
    rows = []
    with open(path, newline="", encoding="utf-8") as f:
        for row in csv.DictReader(f):
            state = {axis: float(row[axis]) for axis in AXES if row.get(axis)}
            if state and (not rows or state != rows[-1]):
                rows.append(state)
    return rows


def _ncpp(program: Path) -> tuple[list[tuple[float, ...]], str | None]:
    """Machine positions after each move of the program (prelude excluded) and why it stopped, if it did."""
    warnings = io.StringIO()
    _, prelude = parse_program(open(FOLDER / PRELUDE, "rb"), PRELUDE, "sinumerik")
    _, blocks = parse_program(open(program, "rb"), program.name, "sinumerik")
    tagged = itertools.chain(((False, b) for b in prelude), ((True, b) for b in blocks))
    own: set[int] = set()

    def feed():
        for mine, block in tagged:
            if mine:
                own.add(id(block))
            yield block

    positions: list[tuple[float, ...]] = []
    stopped = None
    try:
        for event in interpret(feed(), file=program.name, warnings=Warnings(stream=warnings)):
            if type(event) in (Line, Arc) and id(event.block) in own:
                point = tuple(round(e + o, 6) for e, o in zip(event.end, event.context.offset))
                point += tuple(event.extra[:3]) if event.extra else (0.0, 0.0, 0.0)
                if not positions or point != positions[-1]:
                    positions.append(point)
    except NcppError as err:
        stopped = str(err)
    return positions, stopped or (warnings.getvalue() or None)


@pytest.mark.parametrize("program", _programs(), ids=lambda p: p.name)
def test_agrees_with_cead_oracle(program: Path) -> None:
    expected = _oracle(program)
    positions, stopped = _ncpp(program)
    if program.name in OUT_OF_SCOPE:
        assert stopped, (
            f"{program.name} is listed out of scope but ncpp interpreted all of it: remove it from the list"
        )
        expected = expected[: len(positions)]
    else:
        assert stopped is None, stopped
        assert len(positions) == len(expected), (positions, expected)
    for n, (mine, row) in enumerate(zip(positions, expected)):
        for axis, value in row.items():
            assert abs(mine[AXES.index(axis)] - value) < TOLERANCE, (n, axis, mine, row)


def test_every_listed_file_exists(corpus) -> None:
    names = {p.name for p in _programs()}
    assert set(OUT_OF_SCOPE) <= names
    assert len(names) - len(OUT_OF_SCOPE) >= 10  # the in-scope share is real
