"""A second part leaves runs of plain lines unread before its window (`ncpp/motion/skim.py`):
the interpreter and the writer reach the state a full read reaches, and a state that
differs is caught at the cut."""

import io

import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

import ncpp.parts as parts
import ncpp.pipeline as pipeline
from ncpp.errors import NcppError, Warnings
from ncpp.motion.interpreter import Interpreter
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.skim import _CODE, _NUMBERS, PLAIN_LINE, _Shapes
from ncpp.passes.context import CutLine
from ncpp.passes.geometry import LINE_CHUNK
from ncpp.pipeline import ErrorSource, Part, process

from .test_kernels import OFFSET, ROOT

HEAD = "%\n(skim test)\nG21 G90 G17 G94\nF500\nG0 X0 Y0 Z5\n" + "(the first 30 blocks are read: an earlier ncpp header is looked for there)\n" * 26


@pytest.fixture(scope="module")
def source():
    return ErrorSource.from_machine_file(str(ROOT / "samples/machines/hr5b.toml"))


def _number(value: float, decimals: int) -> str:
    return f"{value:.{decimals}f}"


_coordinate = st.builds(_number, st.floats(-20, 20), st.integers(0, 4))  # any two points: a chord R50 spans
_plain = st.one_of(
    st.builds(lambda g, x, y: f"{g}X{x} Y{y}", st.sampled_from(["", "G1 ", "G01 ", "G0 ", "g1 ", "N10 G1 "]), _coordinate, _coordinate),
    st.builds(lambda z, f: f"Z{z}" + f, _coordinate, st.sampled_from(["", " F800", " F1200."])),
    # arcs (and a modal one) end with a G1 line: the bare lines after them are lines
    st.builds(lambda g, x, y, r, more, x1: f"G{g} X{x} Y{y} R{r}\n" + more + f"G1 X{x1}", st.sampled_from(["2", "3", "02"]), _coordinate, _coordinate,
              st.sampled_from(["50", "-50.0", "60.00"]), st.sampled_from(["", "X5 Y5 R40\n"]), _coordinate),  # fmt: skip
    st.builds(lambda g, x, y, z: f"G{g}X{x}Y{y}Z{z}R55\nG0 X1", st.sampled_from(["2", "3"]), _coordinate, _coordinate, _coordinate),
    st.sampled_from(["F300", "(a comment)", "", "  X1.5 (at the end)"]),
)
_other = st.sampled_from(["M8", "G64", "S800 M3", "G17", "G91 G1 X1\nG90", "G4 P0.1", "G61\nG64", "G1 X2 F100 Y3"])
_programs = st.lists(st.one_of(_plain, _plain, _plain, _other), min_size=40, max_size=160)


def _run(program: bytes, source: ErrorSource, part: Part) -> Part:
    process(io.BytesIO(program), io.BytesIO(), file="t.ngc", source=source, warnings=Warnings(stream=io.StringIO()), offsets=WorkOffsets.at(OFFSET), part=part)
    return part


def _second_part(program: bytes, source: ErrorSource, cut: int, window: int) -> tuple[Part, str | None]:
    """A second part's run, and the error it stops at (None: none)."""
    part = Part(CutLine(cut), second=True, window=window)
    try:
        _run(program, source, part)
    except NcppError as error:
        return part, str(error)
    return part, None


class _NoSkim(pipeline.Skim):
    def __init__(self, part, first):
        super().__init__(part, first=10**9)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(before=_programs, after=_programs, window=st.integers(1, 12))
def test_a_skimmed_second_part_reaches_the_state_a_full_read_does(source, before, after, window):
    """Random lines before the cut (some of which the skim cannot tell), the last few of them
    the second part's window; the cut at a chunk's start, as the parts cut."""
    body = "\n".join(before).split("\n")
    pad = ["(pad)"] * (LINE_CHUNK - 1 - HEAD.count("\n") - len(body))
    program = (HEAD + "\n".join(pad + body + after) + "\nM2\n").encode()
    cut = LINE_CHUNK
    try:
        first = _run(program, source, Part(CutLine(cut)))
    except NcppError:  # an R arc from a point to itself before the cut
        assume(False)
    skimmed, refused = _second_part(program, source, cut, window)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(pipeline, "Skim", _NoSkim)
        read, read_refused = _second_part(program, source, cut, window)
    assert refused == read_refused  # (one past the cut: the second part's to refuse, skimmed or not)
    assert read.skipped == 0
    assert skimmed.interpreted is not None and skimmed.interpreted == first.interpreted == read.interpreted
    assert skimmed.reached == read.reached  # the passes' and the writer's state: as after reading every line


def test_plain_lines_are_those_the_skim_can_tell():
    plain = [b"G1 X1 Y2\n", b"N20 G03 X1.5 Y-2 R5 F200.\n", b"x1y2z3\n", b"  Z-0.25 (down)\r\n", b"F1200.\n", b"\n", b"(pass 2)\n", b"G2 X1 Y1 Z-1 I0.5 J0\n"]
    other = [b"G1 Y2 X1\n", b"G10 L2 P1 X0\n", b"G1.1 X1\n", b"M3\n", b"G1 X#1\n", b"X1 X2 Y2\n", b"o100 sub\n", b"G1 X1 ; note\n", b"G0 G90 X1\n", b"G1 X[1+2]\n"]
    assert all(PLAIN_LINE.fullmatch(line) for line in plain)
    assert not any(PLAIN_LINE.fullmatch(line) for line in other)


def test_a_lines_shape_says_what_the_expression_says_of_it():
    """The verdict is kept per shape (digits alike); G's digits are checked line by line:
    G01 and G21, G03 and G13, G2 and G5 share a shape.  A shape first seen not plain stays so (safe:
    its lines are read)."""
    shapes = _Shapes()
    lines = [b"G01 X1.5 Y-2\n", b"G21 X1.5 Y-2\n", b"G03 X7.5 Y-9\n", b"G13 X7.5 Y-9\n", b"G2 X1 R5\n", b"G5 X1 R5\n",
             b"X12.25 Y3.5 (pass 7)\n", b"X98.75 Y0.5 (pass 3)\n", b"N20 G00 Z5\n", b"N31 G80 Z5\n"]  # fmt: skip
    for line in lines:
        found, plain = PLAIN_LINE.fullmatch(line), shapes.plain(line)
        assert (plain is None) == (found is None), line
        if plain is not None:
            assert [None if at is None else line[at[0] : at[1]] for at in plain.at] == [found.group(g) for g in (_CODE, *_NUMBERS)]
    assert shapes.plain(b"G10 X1\n") is None and shapes.plain(b"G01 X1\n") is None  # the shape learnt from G10


def _plain_program(lines: int) -> bytes:
    """A CAM-like program: a header, then plain G1 lines and R arcs (and M8 now and then)."""
    body = []
    for k in range(lines):
        x, y = (k * 37) % 200 / 10, (k * 53) % 170 / 10
        if k % 997 == 0:
            body.append("M8")
        if k % 7 == 3:
            body.append(f"G{2 + k % 2} X{x:.3f} Y{y:.3f} R30.")
        else:
            body.append(f"G1 X{x:.3f} Y{y:.3f} Z{-(k % 5) / 10:.1f}" if k % 7 in (0, 4) else f"X{x:.3f} Y{y:.3f}")
    return (HEAD + "\n".join(body) + "\nM9\nM2\n").encode()


@pytest.fixture(scope="module")
def plain_program(tmp_path_factory):
    path = tmp_path_factory.mktemp("skim") / "plain.ngc"
    path.write_bytes(_plain_program(2 * parts.MIN_LINES))
    return path


def _compensated(path, source, jobs: int) -> tuple[bytes, str, object]:
    out, said = io.BytesIO(), io.StringIO()
    with open(path, "rb") as stream:
        stats = process(stream, out, file="plain.ngc", source=source, jobs=jobs, warnings=Warnings(stream=said), offsets=WorkOffsets.at(OFFSET))
    return out.getvalue(), said.getvalue(), (stats.lines_in, stats.lines_out)


def test_two_parts_of_plain_lines_write_what_one_run_writes(plain_program, source, monkeypatch):
    """The second process leaves the lines before its window unread (but for the header
    and the M8s), and its part is taken."""
    replies, taken, same = [], [], parts._same
    monkeypatch.setattr(parts, "_same", lambda first, reply: replies.append(reply) or taken.append(same(first, reply)) or taken[-1])
    assert _compensated(plain_program, source, jobs=2) == _compensated(plain_program, source, jobs=1)
    assert taken == [True]
    cut = parts._rounded(2 * parts.MIN_LINES, parts.FIRST_SHARE)
    assert cut - parts.WINDOW - 50 < replies[0]["skipped"] < cut - parts.WINDOW - len(HEAD.splitlines())


def test_a_skim_that_tells_a_wrong_state_is_not_taken(plain_program, source):
    """Left-out lines whose effect the skim told wrong: the interpreter's state at the cut
    differs, so the first process does not take the second's part (it writes the rest itself)."""
    program = plain_program.read_bytes()
    cut = parts._rounded(2 * parts.MIN_LINES, parts.FIRST_SHARE)
    first = _run(program, source, Part(CutLine(cut)))
    told = Interpreter.skipped
    for feed in (0.0, 1.0):
        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(Interpreter, "skipped", lambda self, lines, ends, motion, f: told(self, lines, ends, motion, f + feed))
            second = _run(program, source, Part(CutLine(cut), second=True, window=parts.WINDOW))
        reply = {"reached": second.reached, "interpreted": second.interpreted, "skipped": second.skipped}
        assert second.skipped > 0 and second.reached == first.reached  # (the feed is not the passes' or the writer's)
        assert parts._same(first, reply) == (feed == 0.0)
