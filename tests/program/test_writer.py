"""Editing a block keeps everything but the words it sets."""

from __future__ import annotations

import io

import pytest

from ncpp.program.numbers import NumberStyle
from ncpp.program.parser import parse_text
from ncpp.program.writer import EditPlan, edit_words, spelling


def edit(text: str, values: dict, drop=(), motion=None, style: str = "1.000") -> str:
    block = parse_text(text + "\n")[0]
    return edit_words(block, values, {k: NumberStyle.of(style) for k in values}, drop=drop, motion=motion)


@pytest.mark.parametrize(
    "text, values, drop, motion, expected",
    [
        (
            "N10 G02 X10. Y-2.500 I5 J0 (cut) F100",
            {"X": 10.0012, "Y": -2.4},
            "IJ",
            3,
            "N10 G03 X10.001 Y-2.400 (cut) F100",
        ),
        ("g1x.5y2i3", {"X": 0.25, "Z": 3.0}, ("Y", "I"), None, "g1x0.250z3.000"),
        ("N10 X1", {"X": 1.0, "Y": 2.0}, (), 1, "N10 G1 X1.000 Y2.000"),  # the inserted G is not a separator
        ("M3 S100 ; spindle", {"X": 1.0}, (), None, "M3 S100 X1.000 ; spindle"),
        ("G1  X1   Y2", {"Y": 3.0}, (), None, "G1  X1   Y3.000"),
    ],
)
def test_edit_words(text, values, drop, motion, expected):
    assert edit(text, values, drop, motion) == expected


@pytest.mark.parametrize(
    "text, values, drop, expected",
    [
        (",R1 X10", {"X": 7.25}, (",R",), "X7.250"),
        ("N10 ,R1 X10", {"X": 7.25}, (",R",), "N10 X7.250"),
        ("P2 X1", {"X": 3.0}, ("P",), "X3.000"),
        ("R5\tX1 Y2", {"X": 2.0}, ("R",), "X2.000 Y2"),
        ("  I5 J0 X10 (cut)", {"X": 1.0}, "IJ", "  X1.000 (cut)"),  # the indent stays
        ("(c) I5 X1", {"X": 2.0}, "I", "(c) X2.000"),
        ("/ I5 X1", {"X": 3.0}, "I", "/ X3.000"),
        ("I5 J0 F100", {"X": 1.0, "Y": 2.0}, "IJ", "X1.000 Y2.000 F100"),  # in the place of the words dropped
        ("i5j0f100", {"X": 1.0, "Y": 2.0}, "IJ", "x1.000y2.000f100"),
        ("I5 J0 ; arc", {"X": 1.0, "Y": 2.0}, "IJ", "X1.000 Y2.000 ; arc"),
        ("I5 J0", {"X": 1.0, "Y": 2.0}, "IJ", "X1.000 Y2.000"),
    ],
)
def test_a_dropped_leading_word_takes_the_separator_after_it(text, values, drop, expected):
    """A word dropped at the start of a block leaves no blank where it was: the blank
    after it goes instead of the (absent) one before it; so does a compiled edit."""
    assert edit(text, values, drop) == expected
    block = parse_text(text + "\n")[0]
    if block.signature is not None:
        words = block.words()
        fields = {letter: f"{{{n}:.3f}}" for n, letter in enumerate(values)}
        plan = EditPlan.compile([w.letter for w in words], fields, len(values), drop, spelled=spelling(block))
        assert plan is None or plan.apply(block.raw, words, list(values.values())) == expected


def _compensated_lines(program: bytes, name: str) -> list[str]:
    import io
    from pathlib import Path

    from ncpp.motion.offsets import WorkOffsets
    from ncpp.pipeline import ErrorSource, process
    from tests.compensation.conftest import program_lines

    machine = Path(__file__).resolve().parents[2] / "samples/machines/hr5b.toml"
    source = ErrorSource.from_machine_file(str(machine))
    out = io.BytesIO()
    process(io.BytesIO(program), out, file=name, source=source, offsets=WorkOffsets.at((400.0, 350.0, 300.0)))
    return program_lines(out.getvalue().decode())


def test_a_compensated_corner_block_starts_with_its_first_word():
    """`,R1 X10`: compensation writes the corner out and drops `,R`; the line keeps no blank for it."""
    lines = _compensated_lines(b"G21 G90\nG1 X0 Y0 F100\n,R1 X10\nN20 ,R1 X4 Y5\nX0\nM2\n", "t.ngc")
    assert not [line for line in lines if line[:1].isspace() or "  " in line or ",R" in line]
    assert lines[3].startswith("X") and any(
        line.startswith("N20 G1 X") for line in lines
    )  # G1: after the corner arc


def test_sinumerik_blocks_losing_their_leading_word_start_with_the_next():
    """`CIP` / `CR=` / `CT` leading a block are removed (G2/G3 and I/J/K say the arc) with the blank after them."""
    program = b"G71 G90\nG1 X0 Y0 F100\nCIP X10 Y0 I1=5 J1=5\nG1 X20\nCR=5 X25 Y5 G2\nCT X30 Y10\nM30\n"
    lines = _compensated_lines(program, "t.mpf")
    assert not [line for line in lines if line[:1].isspace() or "  " in line]
    assert any(line.startswith("G2 X") for line in lines[3:5]) and lines[-2].startswith("G3 X")


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


# -- compiled edits and lines: the same text as the general path ----------------------

from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

from ncpp.program.writer import edit_texts  # noqa: E402

PLAN_EXAMPLES = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
_NUMBERS = ["1", "-2.5", "10.", ".5", "+3", "007.25", "0"]
_word = st.tuples(st.sampled_from("GXYZIJKRPFNMS"), st.sampled_from(_NUMBERS + ["0", "1", "2", "3", "01"]))
_gap = st.sampled_from(["", " ", "  ", "\t", " (c) ", " (c{}) "])


@st.composite
def _blocks(draw) -> str:
    """A line of plain words and comments, some of them lower case."""
    words = draw(st.lists(_word, min_size=1, max_size=7))
    lower = draw(st.booleans())
    text = draw(st.sampled_from(["", "  "]))
    for letter, number in words:
        text += (letter.lower() if lower else letter) + number + draw(_gap)
    return text + draw(st.sampled_from(["", "(end)", " ; tail"]))


def _other_digits(text: str, seed: int) -> str:
    """The text with other digits (the same layout)."""
    return "".join(str((int(c) * 7 + seed) % 10) if c.isdigit() else c for c in text)


@PLAN_EXAMPLES
@given(
    _blocks(),
    st.integers(0, 9),
    st.lists(st.sampled_from("XYZIJK"), unique=True),
    st.sets(st.sampled_from("IJKRPX")),
    st.sampled_from([None, 0, 1, 2, 3]),
)
def test_edit_plan_writes_what_edit_texts_writes(text, seed, letters, drop, motion):
    """A compiled edit gives the general edit's text; so does its template for a block's layout,
    for every block of that layout and G words, when it keeps no other numbers and comments."""
    block = parse_text(text + "\n")[0]
    words = block.words()
    first_g = next(
        ((n, w.number) for n, w in enumerate(words) if w.letter == "G" and w.value in (0, 1, 2, 3)), None
    )
    if motion is not None and first_g is not None and motion == int(words[first_g[0]].value):
        motion = None  # `_with_motion` leaves the word: the plan is compiled without it
    fields = {letter: f"{{{n}}}" for n, letter in enumerate(letters)}
    plan = EditPlan.compile(
        [w.letter for w in words], fields, len(letters), drop, motion, first_g, spelling(block)
    )
    if plan is None:
        return
    texts = {letter: f"{n}.5" for n, letter in enumerate(letters)}
    assert plan.apply(block.raw, words, list(texts.values())) == edit_texts(block, texts, drop, motion)
    sibling = parse_text(_other_digits(text, seed) + "\n")[0]
    same_g = [w.number for w in sibling.words() if w.letter == "G"] == [
        w.number for w in words if w.letter == "G"
    ]
    if same_g and not plan.keeps_numbers and len(words) == len(block.items):
        template = plan.template_for(block.raw, words)
        assert template.format(*texts.values()) == edit_texts(sibling, texts, drop, motion)


PLANNED_PROGRAM = """G20 G90 G18
G0 X0 Y0 Z0
G1 X1.2345 Z-0.5
x1.3z-.5
X1.4 (c) Z-0.45 F10.
G3 X1.5 Z-0.45 I0.05 K0
G2 X1.6 Y0.1 Z-0.3 R0.2
R0.25 X1.6 Z-0.1
R0.25 X1.6 Z-0.3
G17 G91 G1 X0.1 Y0.1
G90.1 G90 G3 X2 Y0.5 I1.7 J0.5
I2 J0.75 X2.25 Y0.75
I2 J0.75 X2 Y0.5
G21
G19 G91.1 G2 Y14.7 Z-7.62 J1 K0
N10 G01 X5.000 Y6.000 Z-1.000
X+5.5 Y-2.
G17 G2 X5.5 Y-1. I0 J0.5 P2
"""


def _unplanned_writer():
    """The writer with every line by its general path (no compiled plans)."""
    from ncpp.program.dialects.iso import IsoWriter

    class Unplanned(IsoWriter):
        def _units(self, inch):
            units = super()._units(inch)
            units.plain = False
            return units

    return Unplanned()


@PLAN_EXAMPLES
@given(st.lists(st.tuples(st.integers(0, 2), st.floats(-0.01, 0.01)), min_size=1, max_size=40))
def test_planned_lines_are_the_general_lines(moves):
    """Edits and new blocks written by compiled plans equal those of the general path."""
    from dataclasses import replace

    from ncpp.motion.interpreter import interpret
    from ncpp.motion.segments import Arc, Line
    from ncpp.program.dialects.iso import IsoWriter

    events = list(interpret(parse_text(PLANNED_PROGRAM)))
    moved = []
    for n, event in enumerate(events):
        pieces, shift = moves[n % len(moves)]
        if type(event) is Line or type(event) is Arc:
            end = tuple(v + shift for v in event.end)
            steps = [
                Line(
                    event.start,
                    tuple(v - shift for v in end),
                    False,
                    1.0,
                    event.block,
                    event.context,
                    changed=True,
                )
            ]
            moved += (
                steps[:pieces]
                + [replace(event, end=end, changed=bool(shift) or pieces > 0)]
                + steps[: pieces // 2]
            )
        else:
            moved.append(event)
    assert list(IsoWriter().write(moved)) == list(_unplanned_writer().write(moved))


_digits = st.text("0123456789", max_size=3)
_number = st.builds(
    lambda sign, whole, dot, frac: sign + whole + dot + frac,
    st.sampled_from(["", "-", "+"]),
    _digits,
    st.sampled_from(["", "."]),
    _digits,
)


@PLAN_EXAMPLES
@given(st.lists(_number.filter(lambda n: any(c.isdigit() for c in n) and ("." in n or not n.endswith(".")))))
def test_a_letter_is_written_in_the_style_of_its_last_number(numbers):
    """The styles learnt once per layout of a block (`X1.1`) are those read from each number (`X010.5`)."""
    from ncpp.program.dialects.iso import IsoWriter

    writer = IsoWriter()
    for number in numbers:
        block = parse_text(f"G1 X{number} Y{number}\n")[0]
        writer._read_block(block)
        assert writer.styles["X"] == writer.styles["Y"] == NumberStyle.of(number)


@PLAN_EXAMPLES
@given(
    st.lists(
        _number.filter(lambda n: any(c.isdigit() for c in n) and ("." in n or not n.endswith("."))),
        min_size=1,
    )
)
def test_the_styles_kept_resolved_are_those_the_styles_learnt_resolve_to(numbers):
    """A new style that writes alike (`X1.125` then `X0.`) keeps what was resolved:
    it is what the styles learnt so far resolve to, in mm and in inch."""
    from ncpp.program.dialects.iso import IsoWriter

    writer = IsoWriter()
    for number in numbers:
        writer._read_block(parse_text(f"G1 X{number} Y{number}\n")[0])
        for inch in (False, True):
            fresh = IsoWriter()
            fresh.styles = dict(writer.styles)
            assert writer._units(inch).styles == fresh._units(inch).styles


def test_numbers_without_trailing_zeros_keep_the_resolved_styles():
    from ncpp.program.dialects.iso import IsoWriter

    writer = IsoWriter()
    writer._read_block(parse_text("N1 X1.125 Z-4.52\n")[0])
    units = writer._units(False)
    for text in ("N2 X0. Z-4.473\n", "N3 X75. Z-6.\n", "N4 X-0.375 Z-4.5\n"):
        writer._read_block(parse_text(text)[0])
        assert writer._resolved.get(False) is units  # not worked out again
    writer._read_block(parse_text("N5 X1.12345\n")[0])  # five places: written with five now
    assert writer._units(False) is not units and writer._units(False).styles["X"].decimals == 5


SINUMERIK_PROGRAM = """\
N10 G17 G90 G71
N20 G0 X0 Y0 Z5
N30 G1 Z-1 F300
X10.5 Y2.25
N40 G2 X20 Y2.25 I4.75 J0
G3 X30 Y2.25 CR=5
G1\tX40\tY10 Z-2
N50 G91 X1 Y1
G90 X0 Y0 Z5 ; back
G01 X1.5 F200
N60 G0 Z10
X2 Y3
g1 x4 y5
G2 X8 Y5 I2 J0 ; arc
"""


def _sinumerik_writers():
    """The Sinumerik writer, and one writing every line by its general path."""
    from ncpp.pipeline import dialect_tools

    writer = dialect_tools("sinumerik")[1]

    class General(writer):  # type: ignore[misc, valid-type]
        _edit_block = writer._edit_in_general

        def _units(self, inch):
            units = super()._units(inch)
            units.plain = False
            return units

    return writer(), General()


def _sinumerik_moved(moves) -> list:
    """SINUMERIK_PROGRAM's events with their ends shifted and steps before and after them."""
    from dataclasses import replace

    from ncpp.motion.segments import Arc, Line
    from ncpp.pipeline import dialect_tools
    from ncpp.program.dialects import parse_program

    _, blocks = parse_program(io.BytesIO(SINUMERIK_PROGRAM.encode()), "t.mpf", "sinumerik")
    moved = []
    for n, event in enumerate(dialect_tools("sinumerik")[0](blocks, file="t.mpf")):
        pieces, shift = moves[n % len(moves)]
        if type(event) is Line or type(event) is Arc:
            end = tuple(v + shift for v in event.end)
            steps = [
                Line(
                    event.start,
                    tuple(v - shift for v in end),
                    n % 3 == 0,
                    1.0,
                    event.block,
                    event.context,
                    changed=True,
                )
            ]
            moved += (
                steps[:pieces]
                + [replace(event, end=end, changed=bool(shift) or pieces > 0)]
                + steps[: pieces // 2]
            )
        else:
            moved.append(event)
    return moved


@PLAN_EXAMPLES
@given(st.lists(st.tuples(st.integers(0, 2), st.floats(-0.01, 0.01)), min_size=1, max_size=40))
def test_sinumerik_lines_by_plans_and_templates_are_the_general_ones(moves):
    """The Sinumerik writer's plain blocks edited by ISO's compiled plans and its new blocks
    by templates equal those its general path writes."""
    moved = _sinumerik_moved(moves)
    fast, general = _sinumerik_writers()
    assert list(fast.write(moved)) == list(general.write(moved))
