"""The first moves before a program positions an axis: the control's position on it is not the
one the interpreter assumes, so no word is written for it (it would move the axis from wherever
the control has it); its correction is left out until the program positions it, and where that
happens in a feed move a warning names the line and the axes."""

import io

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
