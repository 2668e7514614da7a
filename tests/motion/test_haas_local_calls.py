"""Haas's local subprogram call, `M97 P<n> L<runs>` (`ncpp/motion/flow.py`, `Flow._m97`).

Haas Mill Operator's Manual 96-8000, M-codes, "M97 Local Sub-Program Call" (the search tool's pages
corpus: easymanua.ls/haas/96-8000/manual?p=217), and its NGC edition (2017, "M97 Local Subprogram
Call"): M97 calls "a subroutine referenced by a line number (N) within the same program"; the P
"must match a line number within the same program"; "the subprogram must end with an M99"; "an
Lnn code in the M97 block will repeat the subroutine call that nn times" (NGC: L "1-99"); "the
subprogram is within the body of the main program, placed after the M30".  Fanuc's and LinuxCNC's
codes have no M97: there ncpp refuses the line's P word (rs274 the M97 itself, "Unknown m code used").

Judged move by move by LinuxCNC's rs274 on the same programs written out by hand, each call
replaced by the lines it runs (`BY_HAND`): the moves ncpp's interpretation prints are rs274's."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.canon import canon_call, read_canon
from ncpp.motion.segments import Line, Pass
from ncpp.pipeline import ErrorSource, process
from tests.conftest import READING, RS274
from tests.motion.test_fanuc_flavours import events
from tests.motion.test_oracle import rs274, same_calls

# The manual's example (O00011), its numbers as written (no unit code: mm here)
MANUAL = """%
O00011 (M97 CALL)
T1 M06
G00 G90 G54 X0 Y0 S1000 M03
G43 H01 Z1.
G01 Z0 F20.
M97 P1000 L5 (L5 RUNS THE N1000 LINES FIVE TIMES)
G00 G90 Z1.
M30
N1000 (N LINE THAT RUNS AFTER M97 P1000)
G01 G91 Z-0.1
G90 X2.
G91 Z-0.1
G90 X0
M99
%
"""
# Calls nested: a local subprogram that calls another L3 times, which calls a subprogram by M98
NESTED = """G21 G90 G54
G0 X0 Y0 Z5
M97 P100 L2
G0 Z10
M30
N100 (OUTER)
G91 G1 X10. F300
M97 P200 L3
G90
M99
N200 (INNER)
G91 Y5.
M98 P300
M99
O300
G91 Z-0.5
X-1.
M99
"""
# One run, a profile with an arc
ONCE = """G21 G90 G17 G54
G0 X0 Y0 Z10
M3 S1200
G0 X-150. Y-100. Z2.
G1 Z-2. F150
M97 P1000
G1 X-100. Y150.
G0 Z10.
M30
N1000 (THE PROFILE)
G1 X160. Y120. F500
G1 X100. Y-140.
G2 X160. Y-80. I0 J60.
M99
"""
_PASS = "G01 G91 Z-0.1\nG90 X2.\nG91 Z-0.1\nG90 X0\n"
_INNER = "G91 Y5.\nG91 Z-0.5\nX-1.\n"
_OUTER = "G91 G1 X10. F300\n" + _INNER * 3 + "G90\n"
# The same programs as rs274 reads them, written out by hand: each call replaced by its lines
BY_HAND = {
    "the manual's example": (MANUAL, "T1 M06\nG00 G90 G54 X0 Y0 S1000 M03\nG43 H01 Z1.\nG01 Z0 F20.\n"
                             + _PASS * 5 + "G00 G90 Z1.\nM30\n"),
    "nested calls": (NESTED, "G21 G90 G54\nG0 X0 Y0 Z5\n" + _OUTER * 2 + "G0 Z10\nM30\n"),
    "one run": (ONCE, "G21 G90 G17 G54\nG0 X0 Y0 Z10\nM3 S1200\nG0 X-150. Y-100. Z2.\nG1 Z-2. F150\n"
                "G1 X160. Y120. F500\nG1 X100. Y-140.\nG2 X160. Y-80. I0 J60.\nG1 X-100. Y150.\nG0 Z10.\nM30\n"),
}  # fmt: skip


def said(program: str, dialect: str = "haas") -> tuple[list, str]:
    stream = io.StringIO()
    return events(program, dialect, Warnings(stream=stream)), stream.getvalue()


@pytest.mark.parametrize("name", BY_HAND)
def test_the_moves_are_rs274s_of_the_program_written_out_by_hand(tmp_path, name):
    if not RS274.exists():
        pytest.skip("rs274 not available")
    program, by_hand = BY_HAND[name]
    written = tmp_path / "by_hand.ngc"
    written.write_text(by_hand)
    reference = read_canon(rs274(str(written))[0])
    found, warned = said(program)
    mine = [c for c in map(canon_call, found) if c is not None]
    assert not warned and len(reference) > 5
    assert len(mine) == len(reference) and same_calls(reference, mine), (reference, mine)


def test_the_manuals_example_runs_its_subprogram_five_times():
    """Worked by hand: from Z0 each run feeds down 0.1, to X2, down 0.1, back to X0."""
    found, _ = said(MANUAL)
    feeds = [ev.end[:3] for ev in found if type(ev) is Line and not ev.rapid]
    assert len(feeds) == 1 + 4 * 5 and feeds[-1] == pytest.approx((0.0, 0.0, -1.0))
    after = [ev.end[2] for ev in found if type(ev) is Line][-1]  # (G00 Z1. after the call)
    assert after == pytest.approx(1.0)


def test_a_label_the_program_lacks_is_refused_at_the_call():
    with pytest.raises(NcppError, match=r"p\.nc:2:5: M97 P200: the program has no block N200"):
        events("G0 X0\nN10 M97 P200\nM30\nN100\nG1 X1 F100\nM99\n", "haas")
    with pytest.raises(NcppError, match=r"p\.nc:2:1: M97 P0: a sequence number is 1 to 99999"):
        events("G0 X0\nM97 P0\nM30\n", "haas")


@pytest.mark.parametrize(
    "program, reason",
    [("N100 G0 X0\nM97 P100\nM30\nN100\nG1 X1 F100\nM99\n", "2:1: warning: M97 P100 with a block N100 before the call"),
     ("G0 X0\nM97 P100 L0\nM30\nN100\nG1 X1 F100\nM99\n", "M97 P100 L0 (Haas runs a local subprogram 1 to 99 times)"),
     ("G0 X0\nM97 P100 L100\nM30\nN100\nG1 X1 F100\nM99\n", "M97 P100 L100 (Haas runs"),
     ("G0 X0\nM97 P100.5\nM30\nN100\nG1 X1 F100\nM99\n", "M97 P100.5 (a sequence number is a whole number"),
     ("G0 X0\nM97 P100\nM30\nN100\nG1 X1 F100\n", "M97 P100 (no M99 ends the local subprogram N100"),
     ("G0 X0\nM98 P300\nM30\nN100\nG1 X1 F100\nM99\nO300\nM97 P100\nM99\n", "8:1: warning: M97 P100 in a subprogram M98"),
     ("G0 X0\nM97 P100\nM30\nN100\nG1 X1 F100\nGOTO 110\nN110 X2\nM99\n", "6:1: warning: GOTO in a Haas local subprogram"),
     ("G0 X0\nM97 P100 X1.\nM30\nN100\nM99\n", "M97 with other words in its block than P and L")],
)  # fmt: skip
def test_what_ncpp_does_not_follow_ends_interpretation_with_a_warning(program, reason):
    found, warned = said(program)
    assert reason in warned and "outside the motion interpreter's scope" in warned
    assert type(found[0]) is Line and type(found[-1]) is Pass and type(found[-2]) is Pass


def test_a_block_n_before_the_call_is_found_past_the_blocks_held():
    """The main program's sequence numbers are noted as its lines go by, thousands of lines back too."""
    far = "G0 X0 Z5\nN100 G1 X1 F100\n" + "G1 X2\nG1 X3\n" * 6000 + "M97 P100\nM30\nN100\nG1 X1\nM99\n"
    _, warned = said(far)
    assert "12003:1: warning: M97 P100 with a block N100 before the call" in warned
    _, warned = said(far.replace("N100 G1", "G1"))
    assert not warned


def test_linuxcnc_refuses_m97s_p_and_fanuc_passes_the_rest_through_naming_haas():
    program = "G0 X0\nM97 P100\nM30\nN100\nG1 X1 F100\nM99\n"
    with pytest.raises(NcppError, match="P word with no"):  # (as rs274 does)
        events(program, "iso")
    stream = io.StringIO()
    found = events(program, "fanuc", Warnings(stream=stream))
    assert [type(e).__name__ for e in found] == ["Line"] + ["Pass"] * 5
    assert "2:1: warning: M97 (Haas's local subprogram call" in stream.getvalue()
    assert "give --dialect haas" in stream.getvalue()


def compensated(tmp_path: Path, program: str, **options) -> tuple[str, str]:
    """The program compensated for the reading machine (verified), and what ncpp said."""
    out, stream = io.BytesIO(), io.StringIO()
    process(io.BytesIO(program.encode()), out, file=str(tmp_path / "p.nc"), warnings=Warnings(stream=stream),
            source=ErrorSource.from_machine_file(str(READING)), **options)  # fmt: skip
    return out.getvalue().decode(), stream.getvalue()


def test_expanded_the_runs_carry_no_copy_of_the_label(tmp_path):
    """--expand writes each run where it runs without the label's N: an M97 left in the program
    (the rest passing through) finds its subprogram, not a copy of its first line."""
    written, warned = compensated(tmp_path, MANUAL, expand=True)
    head, rest = written.split("M30\n")
    assert not re.search("^M97", head, re.M) and "N1000" not in head
    assert head.count("(N LINE THAT RUNS AFTER M97 P1000)") == 5
    assert rest == MANUAL.split("M30\n")[1] and "loop or subroutine" not in warned


def test_a_run_whose_label_line_moves_stays_as_programmed(tmp_path):
    """The once-writing keeps the label line as it stands: one with words of its own is not rewritten."""
    program = ONCE.replace("N1000 (THE PROFILE)\nG1 X160.", "N1000 G1 X160.")
    written, warned = compensated(tmp_path, program)
    assert "warning: loop or subroutine" in warned and written.endswith(program.split("M30\n")[1])
