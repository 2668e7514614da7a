"""The interpreter's direct path for `G0`-`G3` blocks must do exactly what the full checks do."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion import interpret
from ncpp.motion.interpreter import Interpreter
from ncpp.program.parser import parse_text

PROGRAM = """G21 G17 G90 F500
G0 X-0.0 Y0
G1 X10 Y0
G3 X20 Y10 I10 J0
G2 X30 Y0 R-12
G3 X30 Y0 I-5 J0 P2
G2 X40 Y10 Z-2 I5 J5 F800
G1 X40
G91 G1 X1 Y1
G2 X2 Y0 I1 J0
G3 X1 Y1 R1
G90 G18
G0 X50 Y0 Z-5
G2 X50 Z5 I0 K5
G19 G0 Y0 Z0
G3 Y2 Z2 J1 K1
G17 G0 X50 Y0
G90.1 G2 X60 Y0 I55 J0
G91.1 G93 G1 X61 F10
G2 X62 Y1 I1 J0 F10
G94 G20 G0 X1 Y1
G3 X1.1 Y1.1 R0.1 F20
G1 Y2 A10
"""


def _signature(text: str) -> list:
    events = interpret(parse_text(text), file="t.nc", warnings=Warnings(stream=io.StringIO()))
    names = ("start", "end", "center", "turn", "feed", "rapid", "extra", "context")
    return [(type(e).__name__, e.block.line, *(repr(getattr(e, n, None)) for n in names)) for e in events]


def _outcome(text: str):
    try:
        return _signature(text)
    except NcppError as err:
        return str(err)


def _through_execute(monkeypatch):
    def execute(self, block, words, motion, motion_item):
        return self._execute(block, words, {1: (motion, motion_item)}, {})

    monkeypatch.setattr(Interpreter, "_motion_move", execute)


def test_direct_motion_path_agrees_with_execute(monkeypatch):
    direct = _outcome(PROGRAM)
    assert isinstance(direct, list) and len(direct) == PROGRAM.count("\n")
    _through_execute(monkeypatch)
    assert _outcome(PROGRAM) == direct


@pytest.mark.parametrize(
    "bad",
    [
        "G2 X1 Y1",
        "G2 X1 Y1 R1 I1",
        "G18 G2 X1 Z1 J1 I1",
        "G93 G1 X1",
        "G3 X5 Y0 I1 J0",
        "G2 X0 Y0 R1",
        "G2 X9 Y0 R1",
    ],  # fmt: skip
)
def test_direct_motion_path_fails_like_execute(monkeypatch, bad):
    text = "G21 G90 F100\nG0 X0 Y0\n" + bad + "\n"
    direct = _outcome(text)
    assert isinstance(direct, str)  # an error message with file:line:col
    _through_execute(monkeypatch)
    assert _outcome(text) == direct


SIGNED = (
    PROGRAM
    + """G90 G17 G0 X0 Y0
N10 G01 X1 Y2 F300
N11 X2 Y3
G2 X3 Y4 I1 J0
X4 Y3 I0 J-1
X5 Y4 R1 (a comment keeps the checks)
G1.0 Z-1
G0 Z2
F200
G3 X5 Y4 I1 J0 P2 F100
"""
)
FAILING = ["G0 Z1 Z2", "G1 X1 Y1 K1", "G3 X5 Y0 I1 J0", "G2 X1 Y1", "G0 X1 R2"]


@pytest.mark.parametrize(
    "program", [PROGRAM, SIGNED] + [f"G21 G90 F100\nG0 X0 Y0\n{bad}\n" for bad in FAILING]
)
def test_signature_path_agrees_with_the_checks(monkeypatch, program):
    """Blocks the interpreter reads from their signature give what the full checks give."""
    import ncpp.motion.interpreter as interpreter

    fast = _outcome(program)
    assert isinstance(fast, list) or program not in (PROGRAM, SIGNED)  # these run to the end
    monkeypatch.setattr(interpreter, "_PLAIN_MOVES", {})
    monkeypatch.setattr(interpreter, "_plain_move", lambda signature: None)
    assert _outcome(program) == fast
