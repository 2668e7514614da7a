"""ncpp against pygcode: word values agree on the corpus; the adapter keeps every value."""

from __future__ import annotations

import io
from collections import Counter

import pygcode
import pytest
from pygcode.words import WORD_MAP

from ncpp.interop.pygcode import from_pygcode, to_pygcode
from ncpp.program.blocks import Block
from ncpp.program.numbers import NumberStyle
from ncpp.program.parser import LineParser, parse_stream
from tests.conftest import corpus_files

LINES_PER_FILE = 3000  # the large files add nothing new past this; keeps the test at a few seconds


def corpus_blocks() -> list[Block]:
    blocks = []
    for path in corpus_files("iso_gcode"):
        for block in parse_stream(io.BytesIO(path.read_bytes()), str(path)):
            if block.line > LINES_PER_FILE:
                break
            if not block.verbatim:
                blocks.append(block)
    return blocks


@pytest.fixture(scope="module")
def blocks(corpus) -> list[Block]:
    return corpus_blocks()


def as_pygcode_reads(block: Block) -> Counter:
    """What pygcode should read from a plain block, given two documented pygcode habits:
    it skips characters that are not one of its letters A-Z (so `$0`, `@1` vanish), and
    its integer letters (N, L) read only the digits before a point and skip the rest."""
    expected: Counter = Counter()
    for word in block.words():
        if word.letter not in WORD_MAP:
            continue
        value = float(int(word.value)) if WORD_MAP[word.letter]["class"] is int else word.value
        expected[word.letter, value] += 1
    return expected


def values(words) -> Counter:
    return Counter((w.letter, float(w.value)) for w in words)


def test_word_values_agree_with_pygcode_on_corpus(blocks):
    compared = refused = 0
    for block in blocks:
        if not block.plain:
            continue  # expressions and control statements: pygcode has no such thing
        try:
            line = pygcode.Line(block.raw)
        except Exception:  # GCodeWordStrError, AssertionError (two codes of one modal group)...
            refused += 1
            continue
        assert values(line.block.words) == as_pygcode_reads(block), (block.line, block.raw)
        # and back: pygcode's own Line through the adapter keeps pygcode's values
        assert values(from_pygcode(line).words()) == values(line.block.words), block.raw
        compared += 1
    assert compared > 30_000
    assert refused < compared / 50


def test_block_to_pygcode_and_back_keeps_every_word_value(blocks):
    converted = 0
    for block in blocks:
        line = to_pygcode(block)
        if line is None:
            continue
        pairs = [(w.letter, w.value) for w in block.words()]
        assert [(w.letter, float(w.value)) for w in line.block.words] == pairs, block.raw
        back = from_pygcode(line)
        assert [(w.letter, w.value) for w in back.words()] == pairs, (block.raw, back.raw)
        assert to_pygcode(back).block.words == line.block.words
        converted += 1
    assert converted > 35_000


@pytest.mark.parametrize(
    "text",
    [
        "X[#1+2]",
        "#1=5",
        "G1 X1 ,C2.",
        "N10.5 G1 X1",
        "M3 $1 S100",
        "G1 @1 ^90",
        "/G1 X1",
        "o100 sub",
        "OCIRCLE",
    ],
)
def test_blocks_pygcode_cannot_represent_give_none(text):
    assert to_pygcode(LineParser().parse(text)) is None


def test_comments_and_tape_marks_reach_pygcode():
    line = to_pygcode(LineParser().parse("G1 X1 (first) (second)"))
    assert line.comment.text == "first. second" and str(line) == "G01 X1 (first. second)"
    line = to_pygcode(LineParser().parse("G0 Z5 ;  retract"))
    assert str(line.comment) == "; retract"
    assert to_pygcode(LineParser().parse("%")).macro == "%"


def test_from_pygcode_writes_ncpp_number_style_and_keeps_exact_values():
    line = pygcode.Line("G01 X1.23456789 Y0.1 Z-3 S12000 F1500.5 T02")
    assert from_pygcode(line).raw == "G1 X1.23456789 Y0.1000 Z-3.0000 S12000 F1500.5 T02"
    dotted = NumberStyle.of("10.")
    assert from_pygcode(line, style=dotted).raw == "G1 X1.23456789 Y0.1 Z-3. S12000 F1500.5 T02"
    per_letter = {"X": NumberStyle.of("010.50"), "F": NumberStyle.of("100.")}
    assert from_pygcode(line, style=per_letter).raw == "G1 X001.23456789 Y0.1 Z-3 S12000 F1500.5 T02"
    assert from_pygcode(pygcode.Line("G1 X0.30000000000000004")).words()[1].value == 0.1 + 0.2


def test_from_pygcode_block_is_an_ordinary_ncpp_block():
    block = from_pygcode(pygcode.Line("G02 X10 Y5 I2.5 J0 (arc)"), eol="\r\n")
    assert block.text == "G2 X10.0000 Y5.0000 I2.5000 J0.0000 (arc)\r\n"
    assert [type(item).__name__ for item in block.items] == ["Word"] * 5 + ["Comment"]
    assert block.items[-1].text == "arc"
