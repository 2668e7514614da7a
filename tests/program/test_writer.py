"""Editing a block keeps everything but the words it sets."""

from __future__ import annotations

import pytest

from ncpp.program.numbers import NumberStyle
from ncpp.program.parser import parse_text
from ncpp.program.writer import edit_words


def edit(text: str, values: dict, drop=(), motion=None, style: str = "1.000") -> str:
    block = parse_text(text + "\n")[0]
    return edit_words(block, values, {k: NumberStyle.of(style) for k in values}, drop=drop, motion=motion)


@pytest.mark.parametrize(
    "text, values, drop, motion, expected",
    [
        ("N10 G02 X10. Y-2.500 I5 J0 (cut) F100", {"X": 10.0012, "Y": -2.4}, "IJ", 3, "N10 G03 X10.001 Y-2.400 (cut) F100"),
        ("g1x.5y2i3", {"X": 0.25, "Z": 3.0}, ("Y", "I"), None, "g1x0.250z3.000"),
        ("N10 X1", {"X": 1.0, "Y": 2.0}, (), 1, "N10 G1 X1.000 Y2.000"),  # the inserted G is not a separator
        ("M3 S100 ; spindle", {"X": 1.0}, (), None, "M3 S100 X1.000 ; spindle"),
        ("G1  X1   Y2", {"Y": 3.0}, (), None, "G1  X1   Y3.000"),
    ],
)
def test_edit_words(text, values, drop, motion, expected):
    assert edit(text, values, drop, motion) == expected


PROGRAM = """%
G21 G90 G17 (setup)
G0 X0 Y0 Z5.
G1 Z-1. F300
X10.5 Y-2.25 (cut)
x-3.125y.5
G2 X1 Y.5 I2.0625 J0
G1 X0 Y0 Z[-2.5]
,R1 X4
N20 G01 X5.00 Y6.0
%
"""


def _written(blocks) -> list[str]:
    """The program written with the segments of every other block moved a little."""
    from dataclasses import replace

    from ncpp.motion.interpreter import interpret
    from ncpp.motion.segments import Arc, Line
    from ncpp.program.dialects.iso import IsoWriter

    def moved(event):
        if (type(event) is Line or type(event) is Arc) and event.block.line % 2:
            return replace(event, end=tuple(v + 0.01 for v in event.end), changed=True)
        return event

    return list(IsoWriter().write(moved(e) for e in interpret(blocks)))


def test_block_signature_is_what_its_words_say():
    """The writer reads a parsed block's facts from its signature: the same output as from its items."""
    blocks = parse_text(PROGRAM)
    assert {b.signature for b in blocks} >= {"G21G90G17", "XY", "G1ZF"}
    unsigned = [replace_signature(b) for b in blocks]
    assert _written(blocks) == _written(unsigned)


def replace_signature(block):
    from dataclasses import replace

    return replace(block, signature=None)
