"""Unit tests of the motion interpreter: modal features, parameters, bad input, scope."""

from __future__ import annotations

import io
import math
import subprocess
import sys

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion import Arc, Line, Pass, interpret
from ncpp.motion.canon import format_event
from ncpp.program.parser import parse_text
from tests.conftest import CORPUS, READING


def run(text: str, **kwargs) -> list:
    return list(
        interpret(
            parse_text(text),
            file="t.nc",
            warnings=kwargs.pop("warnings", Warnings(stream=io.StringIO())),
            **kwargs,
        )
    )


def moves(text: str) -> list:
    return [e for e in run(text) if type(e) is not Pass]


def calls(text: str) -> list[str]:
    return [format_event(e) for e in moves(text)]


def error(text: str) -> NcppError:
    with pytest.raises(NcppError) as err:
        run(text)
    return err.value


# -- modal motion -------------------------------------------------------------------------
def test_modal_continuation_lines_keep_the_motion_mode():
    events = moves("G0 X1 Y2\nG1 Z-1 F100\nX5\n Y6\nG2 X7 Y4 I0 J-2\nX5 Y2 I-2 J0\n")
    assert [type(e).__name__ for e in events] == ["Line", "Line", "Line", "Line", "Arc", "Arc"]
    assert events[0].rapid and not events[1].rapid
    assert events[3].start == (5.0, 2.0, -1.0) and events[3].end == (5.0, 6.0, -1.0)
    assert events[5].center == (5.0, 4.0, -1.0) and events[5].turn == -1


def test_every_block_gives_one_event_and_keeps_its_block():
    blocks = parse_text("(c)\nG0 X1\nF100\n\nM2\n")
    events = list(interpret(blocks))
    assert [e.block for e in events] == blocks
    assert [type(e) for e in events] == [Pass, Line, Pass, Pass, Pass]


def test_incremental_and_absolute_distance():
    assert calls("G91 G0 X1 Y1\nX1\nG90 X0\n") == [
        "STRAIGHT_TRAVERSE(1.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
        "STRAIGHT_TRAVERSE(2.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
        "STRAIGHT_TRAVERSE(0.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
    ]


def test_motion_code_alone_moves_to_where_it_is():
    assert calls("G0\n") == ["STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)"]


def test_g80_may_share_a_line_with_a_motion_code():
    assert len(moves("N1 G00 G17 G21 G40 G49 G80 G90 X1\n")) == 1


def test_units_switch_converts_the_position_and_sets_context():
    events = moves("G20 G0 X1\nG21\nG0 Y1\n")
    assert events[1].start == pytest.approx((25.4, 0.0, 0.0)) and events[1].end == pytest.approx(
        (25.4, 1.0, 0.0)
    )
    assert events[0].context.inch and not events[1].context.inch


def test_planes_order_arc_feed_like_rs274():
    # G18: first axis Z, second X; G19: first Y, second Z
    assert calls("G18 G2 X10 Z0 I5 K0 F1\n") == [
        "ARC_FEED(0.0000, 10.0000, 0.0000, 5.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)"
    ]
    assert calls("G19 G3 Y10 Z0 J5 K0 F1\n") == [
        "ARC_FEED(10.0000, 0.0000, 5.0000, 0.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)"
    ]


def test_helix_full_circle_and_extra_turns():
    (arc,) = moves("G17 G3 Z-3 I5 P3 F10\n")
    assert arc.end == (0.0, 0.0, -3.0) and arc.turn == 3
    assert arc.sweep() == pytest.approx(6 * math.pi)
    assert format_event(arc) == "ARC_FEED(0.0000, 0.0000, 5.0000, 0.0000, 3, -3.0000, 0.0000, 0.0000, 0.0000)"


def test_r_arcs_short_and_long_way():
    (short,) = moves("G2 X10 R5 F1\n")
    assert short.center == pytest.approx((5.0, 0.0, 0.0))
    (arc,) = moves("G2 X10 R10 F1\n")
    assert arc.center == pytest.approx((5.0, -math.sqrt(75), 0.0))
    (long_way,) = moves("G2 X10 R-10 F1\n")
    assert long_way.center == pytest.approx((5.0, math.sqrt(75), 0.0))
    assert abs(long_way.sweep()) > math.pi > abs(arc.sweep())


def test_absolute_arc_centres_g90_1():
    (arc,) = moves("G0 X10\nG90.1 G3 X0 Y10 I0 J0 F1\n")[1:]
    assert arc.center == (0.0, 0.0, 0.0) and arc.context.arc_absolute


def test_work_offsets_g10_l2_g54_g55_and_context_offset():
    events = moves("G10 L2 P2 X100 Y50\nG0 X1\nG55\nG0 X1\nG54 G0 X1\n")
    assert events[0].context.offset == (0.0, 0.0, 0.0)
    assert events[1].start == (-99.0, -50.0, 0.0) and events[1].context.offset == (100.0, 50.0, 0.0)
    assert events[2].start == (101.0, 0.0, 0.0)  # machine X 101, Y 0 back in G54


def test_g10_l20_and_g92_family():
    events = moves("G0 X10\nG10 L20 P1 X0\nG0 X1\nG92 X5\nG0 X6\nG92.1\nG0 X0\n")
    assert events[1].start == (0.0, 0.0, 0.0) and events[1].context.offset[0] == 10.0
    assert events[2].start == (5.0, 0.0, 0.0) and events[2].context.offset[0] == 6.0
    assert events[3].start == (2.0, 0.0, 0.0)  # machine 12 minus the G54 offset 10


def test_g53_moves_in_machine_coordinates_and_g28_goes_home():
    events = moves("G92 X-10\nG53 G0 X0\nG28 Z5\n")
    assert events[0].end == (-10.0, 0.0, 0.0)  # machine 0 is program -10
    assert [e.end for e in events[1:]] == [(-10.0, 0.0, 5.0), (-10.0, 0.0, 0.0)]


def test_tool_length_g43_1_shifts_the_program_position():
    events = moves("G0 Z10\nG43.1 Z2\nG0 Z10\nG49 G0 Z10\n")
    assert events[1].start[2] == 8.0 and events[1].context.offset[2] == 2.0
    assert events[2].context.offset[2] == 0.0


def test_g43_1_sets_the_axes_it_names_and_keeps_the_others():
    """As rs274ngc: `G43.1 Z2` then `G43.1 X1` is an offset of X1 Z2 (was X1 Z0)."""
    events = moves("G43.1 Z2\nG43.1 X1\nG53 G0 Z0\n")
    assert events[-1].context.offset[:3] == (1.0, 0.0, 2.0)


def test_fractional_line_numbers_and_block_delete_are_read():
    assert len(moves("N10.5 G0 X1\n/G0 X2\n")) == 2


def test_rotary_axes_appear_as_extra():
    (line,) = moves("G0 X1 A90\n")
    assert line.extra == (90.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    assert format_event(line) == "STRAIGHT_TRAVERSE(1.0000, 0.0000, 0.0000, 90.0000, 0.0000, 0.0000)"


def test_program_end_stops_interpretation():
    events = run("G0 X1\nM2\nG0 X2\n")
    assert [type(e) for e in events] == [Line, Pass, Pass]


# -- parameters -----------------------------------------------------------------------------
def test_parameters_are_assigned_after_the_line_is_read():
    events = moves("#1=5\n#1=7 G0 X#1\nG0 X#1\n")
    assert [e.end[0] for e in events] == [5.0, 7.0]


def test_named_parameters_expressions_and_functions():
    text = "#<r> = 10\n#<_g> = [#<r> * 2]\nG0 X[#<r> * COS[60]] Y[SQRT[#<_g> + 5] MOD 3] Z[ATAN[1]/[1]]\n"
    (line,) = moves(text)
    assert line.end == pytest.approx((5.0, 2.0, 45.0))


def test_system_parameters_read_the_position():
    (_, line) = moves("G0 X3\nG0 Y#<_x>\n")
    assert line.end == (3.0, 3.0, 0.0)


def test_undefined_named_parameter_is_an_error():
    err = error("G0 X#<nothing>\n")
    assert (err.where.line, err.where.col, err.message) == (1, 4, "Named parameter #<nothing> not defined")


def test_a_name_assigned_on_a_line_reads_0_there_as_in_rs274ngc():
    """rs274ngc creates a name as it reads its assignment: the rest of the line (the value's
    expression too) reads 0, the next line the value (was: refused as not defined)."""
    events = moves("#<r> = [#<r> + 5] G0 X#<r>\nG0 X#<r>\n#<_g> = 3 #<_g> = 7 G0 Y#<_g>\nG0 Y#<_g>\n")
    assert [e.end[:2] for e in events] == [(0.0, 0.0), (5.0, 0.0), (5.0, 0.0), (5.0, 7.0)]
    err = error("G0 X#<q> #<q> = 5\n")  # read before the assignment: not defined yet
    assert (err.where.line, err.where.col, err.message) == (1, 4, "Named parameter #<q> not defined")


def test_divide_by_zero_is_an_error():
    err = error("G0 X0\nG0 X[1/0]\n")
    assert (err.where.line, err.where.col, err.message) == (2, 4, "Attempt to divide by zero")


def test_powers_group_left_to_right_as_in_rs274ngc():
    """2**3**2 is (2**3)**2 = 64 in rs274ngc (the grammar grouped it 2**(3**2) = 512)."""
    (line,) = moves("G1 F100 X[2 ** 3 ** 2] Y[-2 ** 2] Z[4 ** 0.5 ** 2]\n")
    assert line.end == (64.0, 4.0, 4.0)


def test_zero_to_a_negative_power_is_an_error():
    err = error("G0 X0\n#1=[0**-1]\n")  # was a traceback (math.pow: math domain error)
    assert (err.where.line, err.message) == (2, "Attempt to divide by zero (zero to a negative power)")


# -- bad input: file, line, column, LinuxCNC's message -------------------------------------------
@pytest.mark.parametrize(
    "text, line, col, message",
    [
        ("G0 X1\nG2 X10 F1\n", 2, 1, "R i j k words all missing for arc"),
        ("G2 X10 I5 R5 F1\n", 1, 1, "Mixed radius ijk format for arc"),
        ("G2 X10 R3 F1\n", 1, 1, "Arc radius too small to reach end point"),
        ("G1 X1 F-5\n", 1, 7, "Negative f word used"),
        ("G1 F100\nX1 F-5\n", 2, 4, "Negative f word used"),
        ("G10 L2 X3\n", 1, 1, "P value out of range (0-9) with G10 L2"),
        ("G10 L20 X3\n", 1, 1, "P value out of range (0-9) with G10 L20"),
        # rs274ngc's RADIUS_TOLERANCE_INCH (0.00005 in, 0.00127 mm), not the 0.002 mm of other checks
        ("G21 G2 X20.0026 R10 F1\n", 1, 5, "Arc radius too small to reach end point"),
        ("G20 G2 X20.00011 R10 F1\n", 1, 5, "Arc radius too small to reach end point"),
        ("G2 X0 R3 F1\n", 1, 1, "Current point same as end point of arc"),
        ("G1 F1\nG2 X10 I5 K3\n", 2, 11, "K word given for arc in xy plane"),
        ("G18 G2 X10 I5 J3 F1\n", 1, 15, "J word given for arc in xz plane"),
        ("G0 G1 X10\n", 1, 4, "Two g codes used from same modal group"),
        ("G1 X10 X3 F1\n", 1, 8, "Multiple x words on one line"),
        ("G3.5 X1\n", 1, 1, "Unknown g code used"),
        ("X10\n", 1, 1, "Cannot use axis values without a g code that uses them"),
        ("G80 X10\n", 1, 5, "Cannot use axis values with G80"),
        ("G92\n", 1, 1, "All axes missing with g52 or g92"),
        ("G0 G92 X1\n", 1, 1, "Cannot use two g codes that both use axis values"),
        ("G38.2 F1\n", 1, 1, "All axes missing with motion code"),
        ("G61 R0.5\n", 1, 5, "R word with no g code that uses it"),
        ("G0 X1 I2\n", 1, 7, "I word with no G2, G3, G5, G5.1, G10, G71, G76, or G87 to use it"),
        ("G2 X1 I0.5 P0 F1\n", 1, 12, "P value should be 1 or greater with G2 or G3"),
        ("G91 G53 G0 X1\n", 1, 5, "Cannot use g53 incremental"),
        ("G4\n", 1, 1, "Dwell time missing with G4"),
        ("G81 X0 Y0 Z-1 R0 A90 F12\n", 1, 18, "Cannot put an a in canned cycle"),
        ("G2 X1 I0.0001 F1\n", 1, 1, "Zero-radius arc"),
        ("G93 G1 X1\n", 1, 1, "F word missing with inverse time g1 move"),
    ],
)
def test_bad_input_names_line_column_and_linuxcnc_message(text, line, col, message):
    err = error(text)
    assert (err.where.file, err.where.line, err.where.col, err.message) == ("t.nc", line, col, message)


def test_an_r_arc_within_rs274s_tolerance_is_read():
    (arc,) = moves("G21 G2 X20.0024 R10 F1\n")  # half chord 10.0012: 0.0012 mm past R (rs274: within)
    assert arc.end[0] == 20.0024


@pytest.mark.parametrize("units, radius", [("G21", 0.0015), ("G21", 0.002), ("G20", 0.00006)])
def test_an_ijk_arc_of_a_radius_above_rs274s_radius_tolerance_is_read(units, radius):
    """rs274 (LinuxCNC 2.9) reads an arc of 0.002 mm radius (a SolidWorks CAM contour's corner in
    nick-burrill/Gcode-Tools, `G3 X-5.1982 Y-2.8783 I0. J-0.002`): zero is below convert_arc2's radius
    tolerance, 0.00127 mm (0.00005 in), not the 0.002 mm of other checks; below it, "Zero-radius arc"."""
    (_, arc) = moves(f"{units} G17 G90\nG1 X0 Y0 F60\nG3 X0 Y0 I0 J{radius:.5f}\n")
    assert arc.center[1] == pytest.approx(radius)
    err = error(f"{units} G17 G90\nG1 X0 Y0 F60\nG3 X0 Y0 I0 J{radius * 0.6:.6f}\n")
    assert err.message == "Zero-radius arc"


def test_arc_radius_tolerance_matches_linuxcnc_files():
    for path in sorted((CORPUS / "malformed/linuxcnc_interp_bad").glob("bad-arc.*.ngc")):
        expected = path.read_text().splitlines()[0].lstrip(";")
        with pytest.raises(NcppError) as err:
            list(interpret(parse_text(path.read_text(), str(path)), file=str(path)))
        assert err.value.message == expected and err.value.where.line == 6
    for path in sorted((CORPUS / "malformed/linuxcnc_interp_good").glob("good-arc.*.ngc")):
        assert any(type(e) is Arc for e in interpret(parse_text(path.read_text(), str(path))))


# -- scope --------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "text, construct",
    [
        ("o<probe> call\n", "o<probe>, which the program does not define (a subroutine file"),
        ("G65 P100 X1\n", "G65 P100: a macro the program does not define"),
        ("G1 X1 IF [#1 EQ 1] GOTO 10\n", "Fanuc macro IF"),  # (Fanuc: a macro statement alone on its line)
        ("M98 P100\n", "M98 P100: a subprogram the program does not define"),
        (
            "G88 X0 Y0 Z-1 R1 P1 F10\n",
            "canned cycle G88",
        ),  # a manual retract: the other cycles are interpreted
        ("G38.2 X1 F1\n", "probing G38.2"),
        ("G0 X#<_hal[x.y]>\n", "machine-state parameter"),
        ("G0 X#5221\n", "machine-state parameter #5221"),
        # the control's G55 zero, in its own units: was stored and not followed (G55 then ran at the zero ncpp was told)
        ("#5241 = 10 G55\n", "a write to the machine-state parameter #5241"),
    ],
)
def test_out_of_scope_passes_through_with_one_warning_then_stops(text, construct):
    stream = io.StringIO()
    events = run("G0 X1\n" + text + "G0 X2\nG0 X3\n", warnings=Warnings(stream=stream))
    steps = [e for e in events if type(e) is Pass and e.setting is not None]
    # a call ncpp cannot follow: a step back to the programmed point before it (ncpp.motion.entries)
    assert [(e.block.line, e.setting.values, e.setting.position) for e in steps] == (
        [(2, (), (1.0, 0.0, 0.0))] if " call" in text or "P100" in text else []
    )
    assert [type(e) for e in events if e not in steps] == [Line, Pass, Pass, Pass]
    assert (
        stream.getvalue().count("warning") == 1
        and "t.nc:2:" in stream.getvalue()
        and construct in stream.getvalue()
    )
    with pytest.raises(NcppError) as err:
        run("G0 X1\n" + text, strict=True)
    assert err.value.where.line == 2 and "strict" in err.value.message


# -- the filter ------------------------------------------------------------------------------------
def test_filter_refuses_a_bad_program_and_writes_nothing(corpus):
    bad = (CORPUS / "malformed/linuxcnc_interp_bad/bad-arc.small.metric.center-format.ngc").read_bytes()
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "--machine", str(READING)], input=bad, capture_output=True
    )
    assert proc.returncode != 0 and proc.stdout == b""
    assert proc.stderr.decode().startswith("<stdin>:6:1: Radius to end of arc differs")
    assert b"Traceback" not in proc.stderr


def test_filter_passes_out_of_scope_programs_through_with_a_warning(corpus):
    path = CORPUS / "iso_gcode/linuxcnc/threading.ngc"
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "--machine", str(READING), str(path)], capture_output=True
    )
    assert proc.returncode == 0
    assert proc.stderr.decode().count("warning: threading G33") == 1
    program = path.read_bytes()
    from_threading = program[program.index(b"\ng33") :]  # the rest passes through as it is
    assert proc.stdout.endswith(from_threading)


def test_motion_command_prints_rs274_calls(corpus):
    path = CORPUS / "iso_gcode/cncjs/g2-arc.gcode"
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "motion", str(path)], capture_output=True, text=True, check=True
    )
    lines = proc.stdout.splitlines()
    assert lines[0] == "STRAIGHT_TRAVERSE(0.0000, 0.0000, 50.0000, 0.0000, 0.0000, 0.0000)"
    assert lines[5] == "ARC_FEED(50.0000, 40.0000, 40.0000, 40.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)"
