"""Sinumerik drilling cycles CYCLE81 and CYCLE82, called once or modally with MCALL (840D
Programming Guide Cycles, "Drilling, centering - CYCLE81", "Drilling, counterboring - CYCLE82",
"Modal call of drilling cycles"): G0 down the tool axis to the reference plane plus the safety
clearance, G1 to the final depth at the feed programmed before, the dwell (CYCLE82), G0 to the
retraction plane; with MCALL after every block that moves, until an MCALL alone.

No Sinumerik interpreter outside ncpp runs these cycles here: the moves are checked against
the manual's sequence worked out by hand, and the compensated holes by mapping ncpp's reading
of the written program through a machine whose errors are written here (a squareness)."""

from __future__ import annotations

import io

import numpy as np
import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import DRILLED, Line, Pass
from ncpp.motion.sinumerik import interpret
from ncpp.program.dialects import parse_program
from tests.writeback.conftest import SQUARE, compensate_file

HEAD = "G17 G90 G71 G54\nT1 D1\nM6\nG0 X10 Y20 Z50\nF200\n"


def _events(text: str) -> tuple[list, str]:
    warned = io.StringIO()
    _, blocks = parse_program(io.BytesIO(text.encode()), "d.mpf", "sinumerik")
    return list(interpret(blocks, file="d.mpf", warnings=Warnings(stream=warned))), warned.getvalue()


def _moves(events: list) -> list[tuple]:
    return [(tuple(round(v, 6) for v in e.end), e.rapid, e.fixed) for e in events if type(e) is Line]


def test_a_modal_cycle_drills_after_each_move_until_mcall_alone():
    events, _ = _events(HEAD + "MCALL CYCLE81(10, 0, 2, -4)\nX40 Y30\nX-40\nMCALL\nG0 X20\nM30\n")

    def drill(x: float, y: float) -> list[tuple]:
        return [((x, y, 2.0), True, DRILLED), ((x, y, -4.0), False, DRILLED), ((x, y, 10.0), True, DRILLED)]

    assert _moves(events)[1:] == [((40.0, 30.0, 50.0), True, ""), *drill(40.0, 30.0),
                                  ((-40.0, 30.0, 10.0), True, ""), *drill(-40.0, 30.0),
                                  ((20.0, 30.0, 10.0), True, "")]  # fmt: skip


def test_a_relative_depth_counts_and_cycle82_dwells_at_the_bottom():
    events, _ = _events(HEAD + "G0 X5 Y5\nCYCLE82(10, 1, 2, -99, 5, 0.5)\nM30\n")
    assert _moves(events)[2:] == [((5.0, 5.0, 3.0), True, DRILLED), ((5.0, 5.0, -4.0), False, DRILLED),
                                  ((5.0, 5.0, 10.0), True, DRILLED)]  # fmt: skip
    assert [e.dwell for e in events if type(e) is Pass and e.dwell is not None] == [0.5]


@pytest.mark.parametrize(
    "call, said",
    [("CYCLE81(10, 0, 2, -4, , 0, 0, 10)", "CYCLE81 with more than 5 parameters"),
     ("G18\nCYCLE81(10, 0, 2, -4)", "outside G17")],
)  # fmt: skip
def test_what_the_cycle_would_mean_otherwise_ends_interpretation(call, said):
    events, warned = _events(HEAD + call + "\nG0 X1\nM30\n")
    assert said in warned and not any(type(e) is Line and e.fixed == DRILLED for e in events)


def test_a_depth_above_the_reference_plane_is_an_error_at_its_line():
    with pytest.raises(NcppError, match="d.mpf:6:.*CYCLE81: the depth 5 is not below"):
        _events(HEAD + "CYCLE81(10, 0, 2, 5)\nM30\n")


def test_the_holes_are_compensated_and_compensation_goes_on(tmp_path):
    """The positioning blocks are compensated (the machine's X is off by 50 µm/m of Y): each hole's
    bottom lands where the program puts it, the cycle's text stays, and the move after it is
    compensated too."""
    text = HEAD + "MCALL CYCLE81(10, 0, 2, -4)\nX40 Y300\nX-40 Y-300\nMCALL\nG1 X60 Y400 F300\nM30\n"
    program = tmp_path / "d.mpf"
    program.write_text(text)
    written = compensate_file(program, SQUARE, tmp_path).read_text()
    assert "MCALL CYCLE81(10, 0, 2, -4)\n" in written and written.count("MCALL") == 2
    events, _ = _events(written)
    bottoms = np.array([e.end for e in events if type(e) is Line and e.fixed == DRILLED and not e.rapid])
    landed = bottoms + np.column_stack([-50e-6 * bottoms[:, 1], 0 * bottoms[:, 1], 0 * bottoms[:, 1]])
    assert np.abs(landed - [[40, 300, -4], [-40, -300, -4]]).max() < 0.5e-3
    last = [e for e in events if type(e) is Line][-1]
    assert abs(last.end[0] - 50e-6 * 400 - 60) < 0.5e-3 and last.end[0] != 60


# -- deep-hole drilling CYCLE83 (Programming Guide Cycles, "Deep-hole drilling - CYCLE83") --


def _feeds(events: list) -> list[tuple]:
    return [(round(e.end[2], 6), e.rapid, e.feed) for e in events if type(e) is Line and e.fixed == DRILLED]


def test_cycle83_breaks_chips_one_mm_up_after_each_infeed():
    """VARI=0: G0 to RFP+SDIS, G1 to the first depth FDEP at F times FRF, dwell DTB; back up
    1 mm at G1 and the programmed feed, G1 down to the next depth (strokes of DAM = the first
    stroke), dwell; ...; G0 to RTP.  Under MCALL, at each position."""
    call = "MCALL CYCLE83(10, 0, 2, -15, , -5, , 5, 0.5, 3, 0.5, 0)\nX40 Y30\nX-40\nMCALL\nM30\n"
    events, _ = _events(HEAD + call)
    one_hole = [(2.0, True, 200.0), (-5.0, False, 100.0), (-4.0, False, 200.0), (-10.0, False, 200.0),
                (-9.0, False, 200.0), (-15.0, False, 200.0), (10.0, True, 200.0)]  # fmt: skip
    assert _feeds(events) == one_hole * 2
    assert {e.end[:2] for e in events if type(e) is Line and e.fixed == DRILLED} == {(40, 30), (-40, 30)}
    assert [e.dwell for e in events if type(e) is Pass and e.dwell is not None] == [0.5] * 6


def test_cycle83_in_one_infeed_drills_to_the_depth_at_the_reduced_feed():
    """The first depth (FDPR below RFP, as DPR) is the final depth: one infeed, in either mode;
    DTS, the dwell at the start between infeeds, does not come in."""
    events, _ = _events(HEAD + "G0 X5 Y5\nCYCLE83(10, 1, 2, -7, , , 8, 0, 1, 3, 0.25, 1)\nM30\n")
    assert _feeds(events) == [(3.0, True, 200.0), (-7.0, False, 50.0), (10.0, True, 200.0)]
    assert [e.dwell for e in events if type(e) is Pass and e.dwell is not None] == [1.0]


@pytest.mark.parametrize(
    "call, said",
    [("CYCLE83(10, 0, 2, -15, , -5, , 5, 0, 0, 1, 1)", "chip removal (VARI=1) in more than one infeed"),
     ("CYCLE83(10, 0, 2, -15, , -5, , 2, 0, 0, 1, 0)", "strokes of different lengths"),
     ("CYCLE83(10, 0, 2, -14, , -5, , 5, 0, 0, 1, 0)", "do not reach the depth -14 exactly"),
     ("CYCLE83(10, 0, 2, -15, , -5, , 5, 0, 0, , 0)", "the feed factor FRF left out"),
     ("CYCLE83(10, 0, 6, -15, , -5, , 5, 0, 0, 1, 0)", "the safety clearance SDIS above the degression"),
     ("CYCLE83(10, 0, 2, -15, , , , 5, 0, 0, 1, 0)", "without a first drilling depth"),
     ("CYCLE83(10, 0, 2, -15, , -20, , 5, 0, 0, 1, 0)", "first drilling depth -20 outside the hole"),
     ("CYCLE83(10, 0, 2, -15, , -5, , 5, 0, 0, 1, 0, 3)", "CYCLE83 with more than 12 parameters"),
     ("G70\nCYCLE83(10, 0, 2, -15, , -5, , 5, 0, 0, 1, 0)", "in inches")],
)  # fmt: skip
def test_what_cycle83_leaves_to_the_control_ends_interpretation(call, said):
    events, warned = _events(HEAD + "G0 X5 Y5\n" + call + "\nG0 X1\nM30\n")
    assert said in warned and not any(type(e) is Line and e.fixed == DRILLED for e in events)


def test_cycle83_holes_are_compensated(tmp_path):
    """The positioning blocks before a modal CYCLE83 are compensated (the machine's X off by
    50 µm/m of Y): every move of each hole lands on the hole's axis, the call stays as written."""
    call = "MCALL CYCLE83(10, 0, 2, -15, , -5, , 5, 0.5, 0, 1, 0)"
    program = tmp_path / "d.mpf"
    program.write_text(HEAD + call + "\nX40 Y300\nX-40 Y-300\nMCALL\nG0 X0 Y0\nM30\n")
    written = compensate_file(program, SQUARE, tmp_path).read_text()
    assert call + "\n" in written
    events, _ = _events(written)
    drilled = np.array([e.end for e in events if type(e) is Line and e.fixed == DRILLED])
    assert len(drilled) == 14
    landed = drilled[:, 0] - 50e-6 * drilled[:, 1]
    assert np.abs(landed - np.repeat([40, -40], 7)).max() < 0.5e-3 and np.all(drilled[:, 0] != 40)


@pytest.mark.parametrize(
    "pattern", ["CYCLE801(20, 30, 0, 10, 15, 4, 2)", "CYCLE802(111111111, 111111111, 0, 0)"]
)
def test_a_hole_pattern_under_mcall_ends_interpretation_before_its_holes(pattern):
    """A grid's order and CYCLE802's positions are the cycle's own: not followed (out of scope,
    the rest of the program passes through), the moves before it are (HOLES1 and HOLES2:
    test_sinumerik_patterns)."""
    events, warned = _events(
        HEAD + "MCALL CYCLE83(10, 0, 2, -5, , -5, , 5, 0, 0, 1, 0)\n" + pattern + "\nMCALL\nM30\n"
    )
    assert f"the hole pattern {pattern[:8]}" in warned
    assert len([e for e in events if type(e) is Line]) == 1


def test_the_chip_breaking_cycle_ncpp_posts_is_followed():
    """`ncpp post` writes CL chip breaking (CYCLE/DRILL, BRKCHP, STEP s) as CYCLE83 with FDEP one
    step below RFP and DAM the step: read back, each hole's moves reach the CL depth in strokes
    of the step, 1 mm back up between them."""
    from ncpp.post import post

    cl = ("UNITS / MM\nLOADTL / 1\nSPINDL / RPM, 1500, CLW\nFROM / 0, 0, 80\nRAPID\nGOTO / 20, 100, 50\n"
          "CYCLE/DRILL,BRKCHP,RAPTO,2,FEDTO,-8,STEP,2,MMPM,120\nGOTO / 120, 100, 4\nGOTO / 140, -300, 4\n"
          "CYCLE/OFF\nFINI\n")  # fmt: skip
    out = io.BytesIO()
    post(io.StringIO(cl), out, file="h.cls", dialect="sinumerik", warnings=Warnings(stream=io.StringIO()))
    events, warned = _events(out.getvalue().decode())
    hole = [(6.0, True), (2.0, False), (3.0, False), (0.0, False), (1.0, False), (-2.0, False), (-1.0, False),
            (-4.0, False), (6.0, True)]  # fmt: skip
    assert [(round(z, 6), rapid) for z, rapid, _ in _feeds(events)] == hole * 2
    assert "outside" not in warned


@pytest.mark.parametrize(
    "call", ["CYCLE81(10, 0, 2, -4, 0)", "CYCLE81(10, 0, 2, -4)", "CYCLE81(10, 0, 2, -9, 4)"]
)
def test_a_relative_depth_of_0_is_one_left_out_and_dp_counts(call):
    """The cycle cannot tell a DPR written as 0 from one left out (both are 0 to it): DP counts."""
    events, _ = _events(HEAD + "G0 X5 Y5\n" + call + "\nM30\n")
    assert [m[0][2] for m in _moves(events) if m[2] == DRILLED and not m[1]] == [-4.0]
