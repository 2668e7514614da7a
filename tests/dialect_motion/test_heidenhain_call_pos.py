"""Klartext `CYCL CALL POS`, cycle 207 RIGID TAPPING and M89: the holes where the manual puts
them, and compensation going on after them.

Expected moves are worked out by hand from the TNC 640 Klartext / cycle programming manual:
"Calling a cycle with CYCL CALL POS" (from above the surface Q203: first in the working plane
to X Y, then in the tool axis to Z; Z is an additional datum shift of the cycle; the feed is for
this approach only) and "Cycle 207 RIGID TAPPING" (to the depth and back to the set-up
clearance at the feed of the spindle speed times the pitch Q239, then FMAX to the 2nd set-up
clearance).  The end-to-end test runs the command line on the shared wide machine, whose
verifier reads the written program back."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from ncpp.motion.segments import DRILLED
from ncpp.summary import REASONS
from tests.conftest import ROOT, SHARED
from tests.dialect_motion.test_heidenhain_cycles import CYCLE_200, compensate, drilled, moves, program, runs
from tests.writeback.conftest import SQUARE

# Cycle 200 (Q200=5 Q201=-6 Q202=6 Q203=0 Q204=11), its levels shifted by the call's Z
POS = ["CYCL CALL POS X+90 Y-7.5 Z+0 FMAX", "CYCL CALL POS X+90 Y-42.5 Z-2 F500"]
AFTER = ["L  Z+21 FMAX", "L  X+0 Y+100 F500"]


def shifted(x: float, y: float, z: float, leg: float | None) -> list[tuple]:
    """A cycle-200 hole at X Y after the move in the plane: down (or up) to the call's Z at the
    call's feed (`leg`: None at FMAX), then cycle 200 with every level + z."""
    levels = [(z, leg), (5 + z, None), (-6 + z, 30.0), (5 + z, None), (11 + z, None)]
    return drilled(x, y, levels)


def test_cycl_call_pos_moves_in_the_plane_then_the_tool_axis_and_shifts_the_cycle_by_its_z():
    found = moves(program(holes=POS, after=AFTER))
    assert runs(found) == [shifted(90, -7.5, 0.0, None), shifted(90, -42.5, -2.0, 500.0)]
    plane = [m for m in found if m.end[:2] != m.start[:2]]
    # from Z21 (above the surface 0): in the plane at the height the tool stands, rapid, then at F500
    assert [(m.start, m.end, m.rapid) for m in plane[1:3]] == [
        ((25.0, -7.5, 21.0), (90.0, -7.5, 21.0), True),
        ((90.0, -7.5, 11.0), (90.0, -42.5, 11.0), False),
    ]
    assert plane[2].feed == 500.0 and not plane[1].fixed and not plane[2].fixed
    up, across = found[-2:]  # after the calls: interpreted, the call's F500 not modal (the program's F500)
    assert not up.fixed and up.start == (90.0, -42.5, 9.0) and not across.fixed and across.feed == 500.0


@pytest.mark.parametrize(
    ("holes", "reason"),
    [
        (
            ["L  Z-3 FMAX", "CYCL CALL POS X+90 Y-7.5 Z+0 FMAX"],
            "CYCL CALL POS from below the workpiece surface",
        ),
        (["CYCL CALL POS X+90 Y-7.5 FMAX"], "CYCL CALL POS without absolute X, Y and Z"),
        (["CYCL CALL POS X+90 Y-7.5 Z+0"], "CYCL CALL POS without F or FMAX"),
    ],
)
def test_cycl_call_pos_the_manual_leaves_open_stays_out_of_scope(holes, reason):
    warned = io.StringIO()
    assert runs(moves(program(holes=holes), warned)) == []
    assert reason in warned.getvalue() and "passes through uninterpreted" in warned.getvalue()


RIGID_TAPPING = """CYCL DEF 207 RIGID TAPPING ~
    Q200=+4 ;SET-UP CLEARANCE ~
    Q201=-12 ;DEPTH OF THREAD ~
    Q239=+1.25 ;THREAD PITCH ~
    Q203=+0 ;SURFACE COORDINATE ~
    Q204=+30 ;2ND SET-UP CLEARANCE"""


def test_rigid_tapping_207_taps_at_the_spindle_speed_times_the_pitch():
    """S800 × 1.25 = 1000 mm/min down to -12 and back to 4; FMAX to 30."""
    text = program(RIGID_TAPPING, ["L FMAX M99", "L  X+40 FMAX M99"]).replace("S10000", "S800")
    expected = [(4, None), (-12, 1000.0), (4, 1000.0), (30, None)]
    assert runs(moves(text)) == [drilled(25, -7.5, expected), drilled(40, -7.5, expected)]
    warned = io.StringIO()  # no spindle speed: the feed is not known
    assert runs(moves(text.replace(" S800", ""), warned)) == []
    assert "CYCL DEF 207 without a spindle speed" in warned.getvalue()


def test_m89_stays_out_of_scope_as_the_machine_tool_builder_decides_what_it_does():
    warned = io.StringIO()
    assert runs(moves(program(holes=["L FMAX M89", "L  X+90 FMAX"]), warned)) == []
    assert "M89 (a modal cycle call or a free M function" in warned.getvalue()


def test_compensation_goes_on_after_cycl_call_pos_and_207():
    """SQUARE: X gains 5e-5 · Y.  The calls' X follow, their Z (the datum shift) stays, and so do
    the cycles' levels; the moves after them are compensated."""
    text = program(CYCLE_200, [*POS, "CYCL DEF 207 RIGID TAPPING ~\n" + RIGID_TAPPING.split("\n", 1)[1],
                               "CYCL CALL POS X+40 Y+10 Z+0 FMAX"], AFTER)  # fmt: skip
    written, stats = compensate(text, SQUARE)
    assert stats.summary.passed_on_from is None
    assert list(stats.summary.left) == [REASONS[DRILLED]]
    calls = [line for line in written.splitlines() if "CYCL CALL POS" in line]
    assert [line.split("Z")[1] for line in calls] == ["+0 FMAX", "-2 F500", "+0 FMAX"]
    holes = [run[1][:2] for run in runs(moves(written))]
    programmed = [(90, -7.5), (90, -42.5), (40, 10)]
    assert [c for h in holes for c in h] == pytest.approx(
        [c for x, y in programmed for c in (x + 5e-5 * y, y)], abs=6e-5
    )
    assert [run[2][2] for run in runs(moves(written))] == [-6.0, -8.0, -12.0]  # the bottoms as programmed
    assert moves(written)[-1].end[:2] == pytest.approx((0.005, 100.0), abs=6e-5)


WIDE = SHARED / "machines" / "wide.toml"


@pytest.mark.skipif(not WIDE.exists(), reason="the shared machine files are not here")
def test_the_command_line_compensates_and_verifies_cycl_call_pos_on_the_wide_machine(tmp_path):
    source = tmp_path / "pos.h"  # (the calls' F is for their own moves: the last line runs at F700)
    third = "CYCL CALL POS X+40 Y-42.5 Z-2 F300"
    source.write_text(program(holes=["L  X+26 F700", *POS, third], after=["L  Z+21 FMAX", "L  X+0 Y+100"]))
    out = tmp_path / "out.h"
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(WIDE), str(source),
                           "-o", str(out)], capture_output=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr.decode()
    assert "passes through" not in proc.stderr.decode()
    written = out.read_text()
    assert written.count("CYCL CALL POS") == 3 and CYCLE_200 in written
    holes = [c for run in runs(moves(written)) for c in run[-1][:2]]
    assert holes == pytest.approx([90, -7.5, 90, -42.5, 40, -42.5], abs=0.01)  # the corrections are µm
    assert holes != [90, -7.5, 90, -42.5, 40, -42.5]  # (and corrected)
    assert not moves(written)[-1].fixed and moves(written)[-1].feed == 700.0


UNIVERSAL_PECKING = """CYCL DEF 205 UNIVERSAL PECKING ~
    Q200=+2 ;SET-UP CLEARANCE ~
    Q201=-15 ;DEPTH ~
    Q206=+150 ;FEED RATE FOR PLNGNG ~
    Q202=+15 ;PLUNGING DEPTH ~
    Q203=+1 ;SURFACE COORDINATE ~
    Q204=+50 ;2ND SET-UP CLEARANCE ~
    Q212=+0 ;DECREMENT ~
    Q205=+0 ;MIN. PLUNGING DEPTH ~
    Q258=+0.2 ;UPPER ADV STOP DIST ~
    Q259=+0.2 ;LOWER ADV STOP DIST ~
    Q257=+0 ;DEPTH FOR CHIP BRKNG ~
    Q256=+0.2 ;DIST FOR CHIP BRKNG ~
    Q211=+0 ;DWELL TIME AT DEPTH ~
    Q379=+0 ;STARTING POINT ~
    Q253=+750 ;F PRE-POSITIONING ~
    Q208=+600 ;RETRACTION FEED RATE"""


@pytest.mark.parametrize(
    "change", [("Q202=+15 ", "Q202=+5 "), ("Q257=+0 ", "Q257=+4 "), ("Q379=+0 ", "Q379=+2 ")]
)
def test_universal_pecking_205_in_one_infeed_and_its_pecks_out_of_scope(change):
    """Q203=1: FMAX to 3, to 1-15 = -14 at Q206=150, out to 3 at Q208=600, FMAX to 51.  More
    infeeds, chip breaking within the infeed and a deepened start end interpretation."""
    assert runs(moves(program(UNIVERSAL_PECKING, ["L FMAX M99"]))) == [
        drilled(25, -7.5, [(3, None), (-14, 150.0), (3, 600.0), (51, None)])
    ]
    warned = io.StringIO()
    assert runs(moves(program(UNIVERSAL_PECKING.replace(*change), ["L FMAX M99"]), warned)) == []
    assert "CYCL DEF 205 " in warned.getvalue() and "passes through uninterpreted" in warned.getvalue()
