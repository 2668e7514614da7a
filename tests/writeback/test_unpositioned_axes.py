"""The first moves before a program positions an axis: the control's position on it is not the
one the interpreter assumes, so no word is written for it (it would move the axis from wherever
the control has it); its correction is left out until the program positions it, and where that
happens in a feed move a warning names the line and the axes."""

import io
import re

import pytest

from ncpp.errors import Warnings
from ncpp.pipeline import ErrorSource, process
from tests.conftest import SHARED

# the start of camotics/cds.gcode: Z3 and X at rapid, the plunge, and only then Y
CAMOTICS = b"G21\nF400\nM3 S10000\nG0 Z3\nG0 X-27\nG1 Z-1.5\nG1 X0 Y-27\nG1 X27 Y0\nM2\n"
KLARTEXT = b"0 BEGIN PGM T MM\n1 TOOL CALL 3 Z S1000\n2 L Z+100 R0 FMAX\n3 L Z+5 F500\n4 L X+10 Y+10\n5 END PGM T MM\n"


def compensated(program: bytes, dialect: str | None = None) -> tuple[str, str]:
    wide = SHARED / "machines" / "wide.toml"
    if not wide.is_file():
        pytest.skip(f"{wide} not found")
    said, out = io.StringIO(), io.BytesIO()
    process(io.BytesIO(program), out, file="p.nc", source=ErrorSource.from_machine_file(str(wide)),
            warnings=Warnings(stream=said), dialect=dialect)  # fmt: skip
    return out.getvalue().decode(), said.getvalue()


def test_the_axes_not_yet_positioned_are_named_once_at_the_first_compensated_feed_move():
    written, said = compensated(CAMOTICS)
    lines = said.splitlines()
    assert len(lines) == 1, said
    assert lines[0].startswith("p.nc:6:1: warning: Y not positioned by the program yet")
    body = written.split("\n")[3:]  # (after the header)
    assert body[3].startswith("G0 Z") and "X" not in body[3] and "Y" not in body[4] and "Y" not in body[5]


def test_klartext_names_them_too():
    _, said = compensated(KLARTEXT, "heidenhain")
    assert "p.nc:4:1: warning: X and Y not positioned by the program yet" in said


@pytest.mark.parametrize(
    "before",
    ["1 BLK FORM 0.1 Z X+0 Y+0 Z-20\n1 BLK FORM 0.2 X+100 Y+100 Z+0\n", "1 CC X+50 Y+50\n",
     "1 CYCL DEF 7.0 DATUM SHIFT\n1 CYCL DEF 7.1 X+0\n1 CYCL DEF 7.2 Y+0\n1 CYCL DEF 7.3 Z+0\n"],
    ids=["blk-form", "pole", "datum-shift"],
)  # fmt: skip
def test_klartext_words_that_move_nothing_do_not_position_their_axes(before):
    """The blank (`BLK FORM`), a pole (`CC`) and a datum shift (`CYCL DEF 7`) move no axis (TNC 640
    Klartext manual, "Defining a workpiece blank: BLK FORM", "Circle center CC": "the tool does not
    move"; Cycle Programming manual, "DATUM SHIFT (Cycle 7)").  Their words were taken for positions:
    `L Z+100 R0 FMAX` after them was written with X and Y (and `L X+20 Y+20` after a BLK FORM with Z),
    moving the tool from where the control had it to the program zero (a TNC 426 manual program, whose
    `L Z+250 R0 F MAX` after `CC X+50 Y+50` became `L Z+249.9970 X+0.0034 Y+0.0000`; NC-PB/gEdit
    DRILLING.H, whose `L X20 Y20 R0 FMAX` after its BLK FORM gained `Z+0.0000`, the blank's bottom)."""
    program = KLARTEXT.replace(b"1 TOOL CALL", before.encode() + b"1 TOOL CALL")
    written, said = compensated(program, "heidenhain")
    retract = next(line for line in written.splitlines() if "FMAX" in line)
    assert " L Z+" in retract and not re.search(r" [XY][+-]", retract)
    assert "X and Y not positioned by the program yet" in said
    xy_first = program.replace(b"2 L Z+100 R0 FMAX", b"2 L X+20 Y+20 R0 FMAX")
    written, _ = compensated(xy_first, "heidenhain")
    rapid = next(line for line in written.splitlines() if "FMAX" in line)
    assert "X+20" in rapid and not re.search(r" Z[+-]", rapid)


@pytest.mark.parametrize(
    "program, dialect",
    [(b"G21 G90\nG52 X10 Y10 Z0\nG0 Z5\nG0 X10 Y10\nG1 Z-1 F100\nX40\nM2\n", "iso"),
     (b"G21 G90\nG10 L2 P1 X0 Y0 Z0\nG54\nG0 Z5\nG0 X10 Y10\nG1 Z-1 F100\nX40\nM2\n", "iso"),
     (b"%_N_T_MPF\nG17 G90 G71 G54\nTRANS X10 Y20 Z5\nG0 Z5\nG0 X1 Y2\nG1 Z-1 F100\nX30\nM30\n", "sinumerik")],
    ids=["g52", "g10-l2", "trans"],
)  # fmt: skip
def test_words_that_set_an_offset_or_a_frame_do_not_position_their_axes(program, dialect):
    """`G52 X10 Y10 Z0` (a local coordinate system), `G10 L2 P1 X0 Y0 Z0` (a work offset's zero) and
    Sinumerik's `TRANS X10 Y20 Z5` (a programmable frame) move no axis (LinuxCNC G-code manual, "G52",
    "G10 L2"; 840D sl Programming Manual, Fundamentals, "TRANS, ATRANS").  Their words were taken for
    positions: the `G0 Z5` after them was written with X and Y, moving the tool sideways from where
    the control had it to the program zero (after G52, 10 mm from where the original goes)."""
    written, _ = compensated(program, dialect)
    retract = next(line for line in written.splitlines() if re.match(r"G0 Z", line))
    assert not re.search(r"[XY]-?\d", retract), retract


def test_rapids_before_the_first_cut_or_a_program_that_positions_every_axis_say_nothing():
    assert compensated(CAMOTICS.replace(b"G0 Z3\n", b"G0 X0 Y0 Z3\n"))[1] == ""
    assert compensated(CAMOTICS.replace(b"G1 Z-1.5\n", b"G0 Y-5\nG1 Z-1.5\n"))[1] == ""


# a hobby program's start: the tool jogged to the part's corner, G92 makes it the zero
G92_FIRST = b"G21 G90\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM2\n"


def test_a_g92_before_the_program_positions_its_axes_says_where_ncpp_takes_the_tool_to_stand():
    """G92 sets its offset from where the control stands (LinuxCNC G-code manual, "G92 Coordinate
    System Offset"), which a program that has not positioned the axes does not say."""
    _, said = compensated(G92_FIRST)
    assert said.startswith("p.nc:2:1: warning: this block sets its offset from where the control stands")
    assert "has not positioned X and Y and Z yet" in said and said.count("warning") == 1
    _, said = compensated(G92_FIRST.replace(b"G92 X0 Y0 Z0", b"G0 X5 Y5\nG92 X0 Y0 Z0"))
    assert "has not positioned Z yet" in said
    assert compensated(G92_FIRST.replace(b"G92 X0 Y0 Z0", b"G0 X5 Y5 Z5\nG92 X0 Y0 Z0"))[1] == ""
