"""Klartext `PATTERN DEF` and `CYCL CALL PAT`: the holes where the pattern puts them, left as
programmed, and compensation going on after them.

The holes are worked out here in closed form from the TNC 640 cycle programming manual,
"Pattern definition PATTERN DEF": a full circle CIRC (centre X Y, diameter D, first hole at
START, NUM holes 360/NUM apart), a pitch circle PITCHCIRC (STEP apart), a row ROW (from X Y,
D apart, turned by ROT about its start), a grid PAT and its outline FRAME (DX DY apart,
NUMX × NUMY), single positions POS1-POS9; each shape's Z is added to the cycle's surface
Q203.  Cycle 200 as in test_heidenhain_cycles (Q200=5 Q201=-6 Q203=0 Q204=11)."""

from __future__ import annotations

import io
import math
import subprocess
import sys

import pytest

from ncpp.motion.segments import DRILLED, PATTERN, UNPLACED
from ncpp.summary import REASONS
from tests.conftest import ROOT, SHARED
from tests.dialect_motion.test_heidenhain_cycles import CYCLE_200, compensate, moves, program
from tests.writeback.conftest import SQUARE

AFTER = ["L  Z+21 FMAX", "L  X+0 Y+100 F500", "L  X+10 Y+100 F500"]


def patterned(pattern: str, call: str = "CYCL CALL PAT FMAX M13", after: list[str] = AFTER) -> str:
    return program(CYCLE_200, [f"PATTERN DEF ~\n   {pattern}", call], after)


def holes_drilled(text: str, warned: io.StringIO | None = None) -> list[tuple[float, float]]:
    """X Y of each bottom the pattern's moves reach (the feed to Q201 + Z), in order."""
    return [m.end[:2] for m in moves(text, warned) if m.fixed == PATTERN and not m.rapid]


def assert_holes(found: list[tuple[float, float]], expected: list[tuple[float, float]]) -> None:
    assert len(found) == len(expected)
    assert [c for h in found for c in h] == pytest.approx([c for h in expected for c in h], abs=1e-9)


def test_a_full_circle_drills_num_holes_360_over_num_apart_from_start():
    found = holes_drilled(patterned("CIRC1 (X+50 Y+20 D40 START+30 NUM6 Z+0)"))
    angles = [math.radians(30 + 60 * k) for k in range(6)]
    assert_holes(found, [(50 + 20 * math.cos(a), 20 + 20 * math.sin(a)) for a in angles])


def test_a_pitch_circle_steps_by_step_and_every_hole_runs_the_whole_cycle_at_the_shapes_surface():
    text = patterned("PITCHCIRC1 (X+0 Y+0 D30 START+90 STEP-45 NUM3 Z-2)")
    found = holes_drilled(text)
    assert_holes(
        found, [(15 * math.cos(math.radians(a)), 15 * math.sin(math.radians(a))) for a in (90, 45, 0)]
    )
    first = [m for m in moves(text) if m.fixed == PATTERN][:5]
    # in the plane at Z21 to the first hole, then cycle 200 with its levels 2 lower (Z-2 on Q203)
    assert [(m.end[2], m.rapid) for m in first] == [(21, True), (3, True), (-8, False), (3, True), (9, True)]
    assert first[0].end[:2] == pytest.approx((0.0, 15.0), abs=1e-9)


def test_a_row_turned_by_rot_and_single_positions_in_the_order_defined():
    assert_holes(
        holes_drilled(patterned("ROW1 (X+10 Y+5 D+8 NUM4 ROT+90 Z+0)")), [(10, 5 + 8 * k) for k in range(4)]
    )
    positions = "POS1 (X+25 Y+33.5 Z+0) ~\n   POS2 (X+15 Y+40 Z+0) ~\n   POS3 (X+Q7 Y-5 Z+0)"
    text = program(CYCLE_200, ["Q7 = 60", f"PATTERN DEF ~\n   {positions}", "CYCL CALL PAT FMAX"], AFTER)
    assert_holes(holes_drilled(text), [(25, 33.5), (15, 40), (60, -5)])


def test_a_grid_and_its_frame_drill_their_holes_and_leave_x_and_y_unknown():
    """The manual does not give the order of a grid's holes: after it, the moves are the
    control's (UNPLACED) up to and with the first block naming X and Y."""
    grid = holes_drilled(patterned("PAT1 (X+10 Y+10 DX+10 DY+5 NUMX3 NUMY2 ROT+0 ROTX+0 ROTY+0 Z+0)"))
    assert sorted(grid) == sorted((10 + 10 * i, 10 + 5 * j) for i in range(3) for j in range(2))
    turn = math.radians(30)
    text = patterned("FRAME1 (X+0 Y+0 DX+10 DY+10 NUMX3 NUMY3 ROT+30 ROTX+0 ROTY+0 Z+0)")
    outline = [(10 * i, 10 * j) for i in range(3) for j in range(3) if (i, j) != (1, 1)]
    expected = [
        (x * math.cos(turn) - y * math.sin(turn), x * math.sin(turn) + y * math.cos(turn)) for x, y in outline
    ]
    found = sorted(holes_drilled(text))
    assert [c for h in found for c in h] == pytest.approx([c for h in sorted(expected) for c in h], abs=1e-9)
    after = [m for m in moves(text) if m.fixed != PATTERN]
    assert [m.fixed for m in after[-3:]] == [UNPLACED, UNPLACED, ""]


@pytest.mark.parametrize(
    ("pattern", "call", "reason"),
    [
        ("POS1 (X+25 IY+33.5 Z+0)", "CYCL CALL PAT FMAX", "PATTERN DEF POS with IY"),
        ("ROW1 (X+10 Y+5 NUM4 Z+0)", "CYCL CALL PAT FMAX", "PATTERN DEF ROW without D"),
        (
            "PAT1 (X+0 Y+0 DX+5 DY+5 NUMX2 NUMY2 ROTX+10 Z+0)",
            "CYCL CALL PAT FMAX",
            "a distortion ROTX or ROTY",
        ),
        (
            "POS1 (X+0 Y+0 Z+0) ~\n   POS2 (X+5 Y+0 Z-3)",
            "CYCL CALL PAT FMAX",
            "holes at different surfaces Z",
        ),
        ("CIRC1 (X+0 Y+0 D10 NUM2.5 Z+0)", "CYCL CALL PAT FMAX", "PATTERN DEF CIRC with 2.5 holes"),
        (
            "PAT1 (X+0 Y+0 DX+5 DY+5 NUMX2.5 NUMY2 Z+0)",
            "CYCL CALL PAT FMAX",
            "PATTERN DEF PAT with 2.5 holes",
        ),
        ("CIRC1 (X+0 Y+0 D10 NUM4 Z+0)", "CYCL CALL PAT", "CYCL CALL PAT without F or FMAX"),
        ("CIRC1 (X+0 Y+0 D10 NUM4 Z+20)", "CYCL CALL PAT FMAX", "from below the 2nd set-up clearance 31"),
    ],
)
def test_patterns_the_manual_leaves_to_the_control_end_interpretation(pattern, call, reason):
    warned = io.StringIO()
    assert holes_drilled(patterned(pattern, call), warned) == []
    assert reason in warned.getvalue() and "passes through uninterpreted" in warned.getvalue()


def test_the_holes_stay_where_the_pattern_puts_them_and_the_moves_after_are_compensated():
    """SQUARE: X gains 5e-5 · Y.  The PATTERN DEF and the call are written as read; the move to
    X0 Y100 after them is corrected to X0.005."""
    pattern = "CIRC1 (X+50 Y+20 D40 START+30 NUM6 Z+0)"
    text = patterned(pattern)
    written, stats = compensate(text, SQUARE)
    assert stats.summary.passed_on_from is None
    assert list(stats.summary.left) == [REASONS[PATTERN]]
    assert pattern in written and "CYCL CALL PAT FMAX M13" in written
    assert holes_drilled(written) == holes_drilled(text)
    last = moves(written)[-1]
    assert not last.fixed and last.end[:2] == pytest.approx((10.005, 100.0), abs=6e-5)


WIDE = SHARED / "machines" / "wide.toml"


@pytest.mark.skipif(not WIDE.exists(), reason="the shared machine files are not here")
def test_the_command_line_compensates_around_a_pattern_and_verifies_it_on_the_wide_machine(tmp_path):
    source = tmp_path / "circle.h"
    source.write_text(patterned("PITCHCIRC1 (X+50 Y+20 D40 START+30 STEP+60 NUM5 Z+0)"))
    out = tmp_path / "out.h"
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(WIDE), str(source),
                           "-o", str(out)], capture_output=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr.decode()
    assert (
        "passes through uninterpreted" not in proc.stderr.decode() and "hole pattern" in proc.stderr.decode()
    )
    written = out.read_text()
    assert holes_drilled(written) == holes_drilled(source.read_text())
    across = moves(written)[-2]  # X0 Y100 after the pattern, compensated
    assert (
        not across.fixed
        and across.end[:2] != (0.0, 100.0)
        and across.end[:2] == pytest.approx((0, 100), abs=0.01)
    )


def test_a_row_after_a_grid_and_a_cycl_call_pos_put_x_and_y_where_the_holes_are_again():
    """After a PAT the plane position is not known; a ROW's last hole (or a CYCL CALL POS, whose
    move in the plane then starts from a place ncpp is not told: left as programmed) makes it
    known, and the move after is compensated."""
    grid = "PATTERN DEF ~\n   PAT1 (X+10 Y+10 DX+10 DY+5 NUMX3 NUMY2 ROT+0 ROTX+0 ROTY+0 Z+0)"
    row = "PATTERN DEF ~\n   ROW1 (X+10 Y+5 D+8 NUM4 ROT+0 Z+0)"
    for then in ([row, "CYCL CALL PAT FMAX"], ["CYCL CALL POS X+90 Y-7.5 Z+0 FMAX"]):
        found = moves(program(CYCLE_200, [grid, "CYCL CALL PAT FMAX", *then], ["L  X+0 Y+100 F500"]))
        assert not found[-1].fixed and found[-1].start[:2] == (
            (34.0, 5.0) if then[0] == row else (90.0, -7.5)
        )
    position = moves(program(CYCLE_200, [grid, "CYCL CALL PAT FMAX", "CYCL CALL POS X+90 Y-7.5 Z+0 FMAX"]))
    plane = next(m for m in position if m.end[:2] == (90.0, -7.5) and m.fixed != DRILLED)
    assert plane.fixed == UNPLACED and not position[-1].fixed


def test_ncpp_motion_prints_a_circles_holes_at_their_angles(tmp_path):
    """`ncpp motion` (rs274's canonical calls): each STRAIGHT_FEED is a hole's bottom, at Z-6."""
    source = tmp_path / "circle.h"
    source.write_text(patterned("CIRC1 (X+50 Y+20 D40 START+30 NUM6 Z+0)"))
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "motion", str(source)], capture_output=True, cwd=ROOT
    )
    feeds = [line for line in proc.stdout.decode().splitlines() if line.startswith("STRAIGHT_FEED")]
    bottoms = [
        tuple(float(v) for v in line[len("STRAIGHT_FEED(") : -1].split(", ")[:3]) for line in feeds[:-2]
    ]
    angles = [math.radians(30 + 60 * k) for k in range(6)]
    expected = [(50 + 20 * math.cos(a), 20 + 20 * math.sin(a), -6.0) for a in angles]
    assert proc.returncode == 0 and len(bottoms) == 6
    assert all(math.dist(b, e) < 1e-4 for b, e in zip(bottoms, expected))  # (printed to 4 places)
