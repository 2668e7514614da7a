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
