"""Klartext blocks in the control's own coordinates: M91 (machine datum), M140 MB (retract along
the tool axis), M92 and M140 MB MAX (positions ncpp is not told).

TNC 640 Klartext manual, "Miscellaneous functions for coordinate data": M91 references the
block's coordinates to the machine datum, in that block only, and the tool length is not
compensated; "Retraction in the tool-axis direction: M140": MB retracts by a distance from
where the tool stands (MB MAX to the end of the traverse range)."""

from __future__ import annotations

import io
import subprocess
import sys

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import MACHINE, UNPLACED, Line
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests.conftest import READING, ROOT

PROGRAM = """0 BEGIN PGM P MM
1 TOOL DEF 1 L+30 R+3
2 TOOL CALL 1 Z S1000
3 L Z-20 R0 FMAX M91
4 L X+10 Y+10 R0 FMAX
5 L Z-1 F100
6 L X+30 F200 M140 MB 50
7 L X+0 Y+0 FMAX
8 L Z-2 F100
9 END PGM P MM
"""
ZERO = (100.0, 200.0, 300.0)


def lines(text: str, warnings: Warnings | None = None) -> list[Line]:
    interpret, _ = dialect_tools("heidenhain")
    _, blocks = parse_program(io.BytesIO(text.encode()), "p.h", "heidenhain")
    found = interpret(blocks, file="p.h", warnings=warnings or Warnings(stream=io.StringIO()),
                      offsets=WorkOffsets.at(ZERO))  # fmt: skip
    return [event for event in found if type(event) is Line]


def test_m91_puts_the_spindle_at_machine_coordinates_and_is_left_as_programmed():
    """Z-20 at the machine datum is program Z -20 - 300 (the zero) - 30 (the tool length it leaves out)."""
    m91 = lines(PROGRAM)[0]
    assert m91.fixed == MACHINE and m91.placed == (False, False, True)
    assert m91.end[2] == -20.0 - ZERO[2] - 30.0
    assert m91.context.to_machine(m91.end)[2] == -20.0  # the machine position the block names
    after = lines(PROGRAM)[1]
    assert after.start == m91.end and after.end[:2] == (10.0, 10.0)


def test_m140_retracts_from_where_the_block_ends_along_the_tool_axis():
    moves = lines(PROGRAM)
    cut, retract, away = moves[3], moves[4], moves[5]
    assert cut.block is retract.block and retract.fixed == MACHINE and retract.rapid
    assert retract.start == cut.end == (30.0, 10.0, -1.0) and retract.end == (30.0, 10.0, 49.0)
    assert away.start == (30.0, 10.0, 49.0)


def test_m92_ends_what_ncpp_follows_with_a_warning():
    stream = io.StringIO()
    found = lines(PROGRAM.replace("L X+0 Y+0 FMAX", "L Z+0 R0 FMAX M92"), Warnings(stream=stream))
    assert len(found) == 5 and "M92 (a position the machine tool builder sets)" in stream.getvalue()


def test_after_mb_max_moves_are_left_as_programmed_until_a_block_names_the_tool_axis():
    """Where the end of the traverse range is ncpp is not told: from there the control runs from a
    position ncpp does not know, so those moves are the control's, up to the block that names Z."""
    text = PROGRAM.replace("6 L X+30 F200 M140 MB 50", "6 L X+30 F200\n6 L M140 MB MAX").replace(
        "8 L Z-2 F100", "8 L Z+5 FMAX\n8 L Z-2 F100"
    )
    moves = lines(text)
    retract, across, down, cut = moves[4:8]
    assert [m.fixed for m in (retract, across, down)] == [MACHINE, UNPLACED, UNPLACED] and not cut.fixed
    assert down.end[2] == 5.0 and cut.start == down.end


def test_compensated_m91_and_m140_blocks_keep_their_text_and_write_no_extra_block(tmp_path):
    program = tmp_path / "p.h"
    program.write_text(PROGRAM)
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "--machine", str(READING), "--work-offset", ",".join(map(str, ZERO)),
         "--no-guard", str(program)],
        capture_output=True, text=True, cwd=ROOT,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    written = proc.stdout.splitlines()
    assert "L Z-20 R0 FMAX M91" in " ".join(written)  # (renumbered after the header, text as it was)
    retract = next(line for line in written if "M140 MB 50" in line)
    after = written[written.index(retract) + 1].split(" ")  # the program's `L X+0 Y+0 FMAX`, compensated
    assert after[1] == "L" and after[2].startswith("X") and after[3].startswith("Y") and after[-1] == "FMAX"
    assert (
        abs(float(after[2][1:])) < 0.01 and abs(float(after[3][1:])) < 0.01
    )  # no block to the retract's end
    assert "left as programmed: 2 moves in machine coordinates" in proc.stderr
    assert "largest correction" in proc.stderr and "50000" not in proc.stderr


def test_the_first_preset_cycle_247_activates_is_the_program_zero_and_another_ends_interpretation():
    """TNC 640 Klartext manual, "Cycle 247 DATUM SETTING": Q339 is the preset activated."""
    text = PROGRAM.replace(
        "2 TOOL CALL 1 Z S1000", "2 CYCL DEF 247 DATUM SETTING ~\n  Q339=+1 ;DATUM\n2 TOOL CALL 1 Z S1000"
    )
    assert len(lines(text)) == len(lines(PROGRAM))
    stream = io.StringIO()
    again = text.replace(
        "7 L X+0 Y+0 FMAX", "7 CYCL DEF 247 DATUM SETTING ~\n  Q339=+2 ;DATUM\n7 L X+0 Y+0 FMAX"
    )
    assert len(lines(again, Warnings(stream=stream))) == 5
    assert "CYCL DEF 247 activating preset 2 after preset 1" in stream.getvalue()


def test_resets_of_a_plane_or_tcpm_that_move_nothing_are_read_past():
    text = PROGRAM.replace(
        "2 TOOL CALL 1 Z S1000", "2 PLANE RESET STAY\n2 FUNCTION RESET TCPM\n2 TOOL CALL 1 Z S1000"
    )
    stream = io.StringIO()
    assert (
        len(lines(text, Warnings(stream=stream))) == len(lines(PROGRAM)) and "scope" not in stream.getvalue()
    )
    turning = PROGRAM.replace("2 TOOL CALL 1 Z S1000", "2 PLANE RESET TURN FMAX\n2 TOOL CALL 1 Z S1000")
    assert lines(turning, Warnings(stream=stream)) == [] and "PLANE RESET TURN" in stream.getvalue()


def test_a_hidden_block_runs_as_the_control_runs_it_with_block_skip_off():
    """`/ 5 L Z-1 F100`: the `/` before the number hides the block only when the operator switches block
    skip on; ncpp follows it as it follows ISO's `/` (janforys/cnc-programming, Heidenhain/FAZ.H: `/ 16 STOP`)."""
    hidden = PROGRAM.replace("5 L Z-1 F100", "/ 5 L Z-1 F100").replace("8 L Z-2", "/ 8 STOP\n8 L Z-2")
    assert [(m.start, m.end) for m in lines(hidden)] == [(m.start, m.end) for m in lines(PROGRAM)]


def test_a_plane_function_with_its_words_ends_interpretation_with_a_warning():
    """`PLANE SPATIAL SPA-90 SPB+0 SPC+90 TURN F5555 SEQ- TABLE ROT` (janforys/cnc-programming,
    Heidenhain/CHWYT-125.h) tilts the working plane: out of scope, not a line ncpp cannot read."""
    stream = io.StringIO()
    plane = "7 PLANE SPATIAL SPA-90 SPB+0 SPC+90 TURN F5555 SEQ- TABLE ROT"
    text = PROGRAM.replace("7 L X+0 Y+0 FMAX", plane)
    assert len(lines(text, Warnings(stream=stream))) == len([m for m in lines(PROGRAM) if m.block.line < 8])
    assert "p.h:8:3: warning: PLANE SPATIAL SPA-90 SPB+0 SPC+90 TURN F5555 SEQ- TABLE ROT is outside" in (
        stream.getvalue()
    )


def test_a_plane_tilted_by_nothing_that_positions_no_axis_is_read_past():
    """`PLANE SPATIAL SPA0 SPB0 SPC0 STAY` heads CAM programs for parts machined untilted (NC-PB/gEdit,
    tests/fixtures/nc/owner-public/heidenhain-klartext/DRILLING.H, line 5, before `PLANE RESET STAY`;
    hyperMILL writes `... STAY SEQ+ TABLE ROT`).  Spatial angles of 0 leave the working plane as it is,
    and STAY positions no rotary axis (TNC 640 Klartext manual, "PLANE SPATIAL", "Automatic positioning:
    STAY"); the control stores the rotary axes' positions for the plane in Q120-Q122, which ncpp does not
    know, so a block that reads one ends interpretation.  Any other angle, or TURN/MOVE, stays out of scope."""
    for plane in (
        "7 PLANE SPATIAL SPA0 SPB0 SPC0 STAY",
        "7 PLANE SPATIAL SPA+0 SPB+0 SPC+0 STAY SEQ+ TABLE ROT",
    ):
        stream = io.StringIO()
        text = PROGRAM.replace("7 L X+0 Y+0 FMAX", f"{plane}\n7 L X+0 Y+0 FMAX")
        assert [m.end for m in lines(text, Warnings(stream=stream))] == [m.end for m in lines(PROGRAM)]
        assert "scope" not in stream.getvalue()
    stream = io.StringIO()
    reading = PROGRAM.replace(
        "7 L X+0 Y+0 FMAX", "6 Q122 = 0\n7 PLANE SPATIAL SPA0 SPB0 SPC0 STAY\n7 L X+Q122 Y+0 FMAX"
    )
    before = len([m for m in lines(PROGRAM) if m.block.line < 8])
    assert len(lines(reading, Warnings(stream=stream))) == before and "Q122" in stream.getvalue()
    for plane in (
        "7 PLANE SPATIAL SPA0 SPB+0.5 SPC0 STAY",
        "7 PLANE SPATIAL SPA0 SPB0 SPC0 TURN MB MAX FMAX",
    ):
        stream = io.StringIO()
        assert len(lines(PROGRAM.replace("7 L X+0 Y+0 FMAX", plane), Warnings(stream=stream))) == before
        assert f"{plane[2:]} is outside" in stream.getvalue()
