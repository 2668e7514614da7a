"""Klartext drilling cycles called with M99 and CYCL CALL: the moves the control makes, and
compensation going on through them.

The expected moves are worked out by hand from the Heidenhain TNC 640 / iTNC 530 "Cycle
programming" manual, each cycle's "Cycle run" (`ncpp.motion.heidenhain_cycles` sums them up):
the levels count from the surface Q203 (set-up clearance Q200, depth Q201, 2nd set-up
clearance Q204), the cycle runs in the tool axis where the tool stands (after the move of the
block M99 ends).  No Klartext interpreter ncpp did not write is at hand: the written programs
are read back by ncpp's own interpreter (and its verifier, on in `process`), and judged against
a closed-form machine (`SQUARE`: X is off by -50 µm/m · Y, so a compensated X gains 5e-5 · Y)."""

from __future__ import annotations

import io
import math
import os
import re
import subprocess
import sys

import pytest

from ncpp.errors import Warnings
from ncpp.motion.segments import DRILLED, Line
from ncpp.pipeline import ErrorSource, dialect_tools, process
from ncpp.program.dialects import parse_program
from ncpp.summary import REASONS
from tests.conftest import ROOT, SHARED
from tests.writeback.conftest import SQUARE

CYCLE_200 = """CYCL DEF 200 DRILLING ~
    Q200=+5    ;SET-UP CLEARANCE ~
    Q201=-6    ;DEPTH ~
    Q206=+30   ;FEED RATE FOR PLNGNG ~
    Q202=+6    ;PLUNGING DEPTH ~
    Q210=+0    ;DWELL TIME AT TOP ~
    Q203=+0    ;SURFACE COORDINATE ~
    Q204=+11   ;2ND SET-UP CLEARANCE ~
    Q211=+0    ;DWELL TIME AT DEPTH"""
HOLES = ["L FMAX M99", "L  X+90 FMAX M99", "L  Y-42.5 FMAX M99", "L  X+25 FMAX M99"]
AFTER = ["L  Z+21 FMAX", "L  X+0 Y+100 F500"]


def program(
    cycle: str = CYCLE_200, holes: list[str] = HOLES, after: list[str] = AFTER, before: str = ""
) -> str:
    """A Fusion-style drilling program: its blocks numbered, the cycle's continuation lines as written."""
    body = [*before.splitlines(), "TOOL CALL 7 Z S10000", "L  X+25 Y-7.5 R0 FMAX", "L  Z+21 R0 FMAX",
            cycle, *holes, *after, "M30"]  # fmt: skip
    lines = ["0  BEGIN PGM DRILL MM"] + [f"{n}  {text}" for n, text in enumerate(body, 1)]
    return "\n".join(lines + [f"{len(body) + 1}  END PGM DRILL MM"]) + "\n"


def moves(text: str, warned: io.StringIO | None = None) -> list[Line]:
    interpret, _ = dialect_tools("heidenhain")
    _, blocks = parse_program(io.BytesIO(text.encode()), "drill.h", "heidenhain")
    events = interpret(blocks, file="drill.h", warnings=Warnings(stream=warned or io.StringIO()))
    return [e for e in events if type(e) is Line]


def runs(found: list[Line]) -> list[list[tuple]]:
    """Each cycle run's moves as (X, Y, Z end, rapid, feed: None for a rapid)."""
    out: list[list[tuple]] = []
    for k, move in enumerate(found):
        if move.fixed != DRILLED:
            continue
        if k == 0 or found[k - 1].fixed != DRILLED or found[k - 1].block is not move.block:
            out.append([])
        out[-1].append((*move.end, move.rapid, None if move.rapid else move.feed))
    return out


def drilled(x: float, y: float, levels: list[tuple[float, float | None]]) -> list[tuple]:
    return [(x, y, z, feed is None, feed) for z, feed in levels]


# Cycle 200 with Q200=5 Q201=-6 Q202=6 Q203=0 Q204=11, from Z21: FMAX to 5, drill to -6 at 30,
# FMAX to 5, FMAX to the 2nd set-up clearance 11 (above 5)
ONE_HOLE = [(5.0, None), (-6.0, 30.0), (5.0, None), (11.0, None)]


def test_drilling_200_runs_at_every_hole_an_m99_block_ends_at():
    found = moves(program())
    assert runs(found) == [
        drilled(x, y, ONE_HOLE) for x, y in ((25, -7.5), (90, -7.5), (90, -42.5), (25, -42.5))
    ]
    up, across = found[-2:]  # after the cycles: from where the last one ends, interpreted
    assert not up.fixed and up.start == (25.0, -42.5, 11.0) and up.end == (25.0, -42.5, 21.0)
    assert not across.fixed and across.end == (0.0, 100.0, 21.0) and across.feed == 500.0


def test_drilling_200_pecks_back_to_the_set_up_clearance_and_down_to_it_above_the_depth_reached():
    """Q202=2, Q201=-5: infeeds to -2, -4, -5; out at FMAX to 5 after each, in at FMAX to the set-up
    clearance above the depth reached (-2+5, -4+5)."""
    cycle = CYCLE_200.replace("Q201=-6 ", "Q201=-5 ").replace("Q202=+6 ", "Q202=+2 ")
    (first, *_) = runs(moves(program(cycle)))
    assert first == drilled(25, -7.5, [(5, None), (-2, 30), (5, None), (3, None), (-4, 30), (5, None),
                                       (1, None), (-5, 30), (5, None), (11, None)])  # fmt: skip


def test_cycl_call_runs_the_cycle_where_the_tool_stands_and_reaming_201_retracts_at_its_feed():
    """201 REAMING: FMAX to Q203+Q200 = 2+2, ream to 2-10 at Q206=100, back to 4 at Q208=250 (0: at Q206),
    FMAX to Q203+Q204 = 52."""
    reaming = """CYCL DEF 201 REAMING ~
    Q200=+2 ;SET-UP CLEARANCE ~
    Q201=-10 ;DEPTH ~
    Q206=+100 ;FEED RATE FOR PLNGNG ~
    Q211=+0.5 ;DWELL TIME AT DEPTH ~
    Q208=+250 ;RETRACTION FEED RATE ~
    Q203=+2 ;SURFACE COORDINATE ~
    Q204=+50 ;2ND SET-UP CLEARANCE"""
    found = moves(program(reaming, ["L  X+40 Y+10 FMAX", "CYCL CALL M13"]))
    expected = drilled(40, 10, [(4, None), (-8, 100), (4, 250), (52, None)])
    assert runs(found) == [expected]
    no_retraction_feed = runs(moves(program(reaming.replace("Q208=+250", "Q208=+0"), ["CYCL CALL"])))
    assert no_retraction_feed == [drilled(25, -7.5, [(4, None), (-8, 100), (4, 100), (52, None)])]
    assert found[-2].start == (40.0, 10.0, 52.0) and not found[-2].fixed


UNIVERSAL_203 = """CYCL DEF 203 UNIVERSAL DRILLING ~
    Q200=+2 ;SET-UP CLEARANCE ~
    Q201=-20 ;DEPTH ~
    Q206=+150 ;FEED RATE FOR PLNGNG ~
    Q202=+8 ;PLUNGING DEPTH ~
    Q210=+0 ;DWELL TIME AT TOP ~
    Q203=+0 ;SURFACE COORDINATE ~
    Q204=+50 ;2ND SET-UP CLEARANCE ~
    Q212=+2 ;DECREMENT ~
    Q213=+1 ;BREAKS ~
    Q205=+3 ;MIN. PLUNGING DEPTH ~
    Q211=+0 ;DWELL TIME AT DEPTH ~
    Q208=+400 ;RETRACTION FEED RATE ~
    Q256=+0.5 ;DIST FOR CHIP BRKNG"""
# its levels and feeds (None: FMAX)
LEVELS_203 = [(2, None), (-8, 150), (-7.5, 400), (-14, 150), (2, 400), (-12, None),
              (-18, 150), (-17.5, 400), (-20, 150), (2, 400), (50, None)]  # fmt: skip


def test_universal_drilling_203_decreases_its_plunge_and_breaks_chips():
    """Q201=-20 Q202=8 Q212=2 Q205=3: plunges 8, 6, 4, then 3 (the minimum) cut to the depth: to -8,
    -14, -18, -20.  Q213=1: a chip break (back by Q256=0.5 at Q208=400) then, the next time, out to the
    set-up clearance 2 at Q208 and in at FMAX to 2 above the depth reached; out at Q208, FMAX to 50."""
    (first, *_) = runs(moves(program(UNIVERSAL_203, ["L FMAX M99"])))
    assert first == drilled(25, -7.5, LEVELS_203)


def test_a_retraction_feed_of_max_retracts_at_rapid():
    """`Q208= MAX ;RETRACTION FEED RATE`, as Fusion's Heidenhain post writes cycle 203 (polymech-info/
    heidenhain-simulator, `samples/a_phv3/motorflange/m7s.h`; refused as unreadable before).  TNC 640
    Cycle Programming manual, cycle 203: "Q208 Feed rate for retraction ... alternatively FMAX": the
    same moves as the test above, each one out at Q208 a rapid."""
    universal = UNIVERSAL_203.replace("Q208=+400", "Q208= MAX")
    (first, *_) = runs(moves(program(universal, ["L FMAX M99"])))
    levels = [(level, None if feed == 400 else feed) for level, feed in LEVELS_203]
    assert first == drilled(25, -7.5, levels)
    said = io.StringIO()
    assert runs(moves(program(universal.replace("Q208= MAX", "Q208=AUTO"), ["L FMAX M99"]), said)) == []
    assert "Q208=AUTO (a feed ncpp does not follow)" in said.getvalue()


def test_centering_240_goes_to_its_depth_and_back_at_fmax():
    centering = """CYCL DEF 240 CENTERING ~
    Q200=+2 ;SET-UP CLEARANCE ~
    Q343=+0 ;SELECT DIA./DEPTH ~
    Q201=-1.5 ;DEPTH ~
    Q344=-9 ;DIAMETER ~
    Q206=+80 ;FEED RATE FOR PLNGNG ~
    Q211=+0.1 ;DWELL TIME AT DEPTH ~
    Q203=+0 ;SURFACE COORDINATE ~
    Q204=+20 ;2ND SET-UP CLEARANCE"""
    assert runs(moves(program(centering, ["L FMAX M99"]))) == [
        drilled(25, -7.5, [(2, None), (-1.5, 80), (2, None), (20, None)])
    ]


def test_incremental_positioning_and_q_parameters_from_formulas():
    """Q201 = -Q1 * 2 with Q1 = 3 is the depth -6, Q206 = Q2 the feed 45; IX+20 IY-10 put the next
    hole 20 right of and 10 below the one before."""
    cycle = CYCLE_200.replace("Q201=-6 ", "Q201=-Q1*2 ").replace("Q206=+30 ", "Q206=Q2 ")
    found = moves(program(cycle, ["L FMAX M99", "L  IX+20 IY-10 FMAX M99"], before="Q1 = 3\nFN 0: Q2 = +45"))
    hole = [(5.0, None), (-6.0, 45.0), (5.0, None), (11.0, None)]
    assert runs(found) == [drilled(25, -7.5, hole), drilled(45, -17.5, hole)]


def test_cycles_ncpp_does_not_follow_and_changed_parameters_still_end_interpretation():
    warned = io.StringIO()
    boring = "CYCL DEF 202 BORING ~\n    Q200=+2 ;SET-UP CLEARANCE ~\n    Q201=-15 ;DEPTH"
    assert runs(moves(program(boring), warned)) == []
    assert "drill.h:8:11: warning: the cycle call M99 (CYCL DEF 202) is outside" in warned.getvalue()
    warned = io.StringIO()  # a cycle ncpp does not read sets its Q parameters: they are not known after it
    found = moves(
        program(
            holes=["L FMAX M99", "CYCL DEF 209 TAPPING CHIP BRKG ~\n    Q201=-31 ;DEPTH", "L  Z-Q201 FMAX"]
        ),
        warned,
    )
    assert len(runs(found)) == 1 and "the parameter Q201 (not set in the program)" in warned.getvalue()
    warned = io.StringIO()
    found = moves(program(holes=["L FMAX M99", "Q201 = -8", "L  X+90 FMAX M99"]), warned)
    assert len(runs(found)) == 1 and "Q201 changed since CYCL DEF 200" in warned.getvalue()


def test_a_datum_shift_moves_the_program_coordinates_of_the_holes():
    """`CYCL DEF 7.0 PUNKT BAZOWY` / `CYCL DEF 7.1 IY-11.75` (janforys/cnc-programming, Heidenhain/JF/AD/
    N021.00/OTW.H; TNC 640 Cycle Programming manual, "DATUM SHIFT (Cycle 7)": absolute values from the
    preset, incremental ones from the datum in effect): each hole, its X and Y programmed, is drilled where
    the same program without the shift drills it moved by the shift, machine point for machine point."""
    holes = [f"L  X+{x} Y{y} FMAX M99" for x, y in ((25, -7.5), (90, -7.5), (90, -42.5), (25, -42.5))]
    shifted = moves(program(holes=["CYCL DEF 7.0 DATUM SHIFT", "CYCL DEF 7.1  X+10", "CYCL DEF 7.2 IY-11.75",
                                   "CYCL DEF 7.2 IY+1.75", *holes]))  # fmt: skip
    plain = moves(program(holes=holes))
    machine = [m.context.to_machine(m.end) for m in shifted if m.fixed == DRILLED]
    expected = [tuple(a + b for a, b in zip(m.context.to_machine(m.end), (10.0, -10.0, 0.0)))
                for m in plain if m.fixed == DRILLED]  # fmt: skip
    assert len(machine) == len(expected) == 16
    assert all(abs(a - b) < 1e-9 for p, q in zip(machine, expected) for a, b in zip(p, q))
    warned = io.StringIO()
    assert runs(moves(program(holes=["CYCL DEF 7.0 DATUM SHIFT", "CYCL DEF 7.1 #5", *HOLES]), warned)) == []
    assert "CYCL DEF 7.1 (a datum shift ncpp does not read)" in warned.getvalue()


def compensate(text: str, machine_toml: str = SQUARE) -> tuple[str, object]:
    """`text` compensated for a machine file (SQUARE), verified as it is written (`process`'s default)."""
    folder = os.environ.get("TMPDIR", "/tmp")
    machine = os.path.join(folder, f"square-{os.getpid()}.toml")
    with open(machine, "w") as stream:
        stream.write(machine_toml)
    out = io.BytesIO()
    source = ErrorSource.from_machine_file(machine)
    stats = process(io.BytesIO(text.encode()), out, file="drill.h", source=source,
                    warnings=Warnings(stream=io.StringIO()), dialect="heidenhain")  # fmt: skip
    os.remove(machine)
    return out.getvalue().decode(), stats


INCREMENTAL = ["L FMAX M99", "L  IX+65 FMAX M99", "L  IY-35 FMAX M99", "L  IX-65 FMAX M99"]


@pytest.mark.parametrize("call", ["M99", "CYCL CALL", "IX IY"])
def test_compensation_goes_on_through_the_holes_and_keeps_the_cycle_text(call):
    """The positioning moves' X gains 5e-5 · Y; the cycle's text, and each M99 once, are written as
    read; the moves after the drilling are compensated; read back, every hole is drilled at its
    compensated X Y (IX IY written as increments from where the cycle before leaves the tool)."""
    holes = {"M99": HOLES, "IX IY": INCREMENTAL}.get(call) or [
        h.replace(" M99", "") + "\nCYCL CALL" for h in HOLES
    ]
    text = program(holes=holes)
    written, stats = compensate(text)
    assert CYCLE_200 in written and written.count("M99") == text.count("M99")
    assert written.count("CYCL CALL") == text.count("CYCL CALL")
    assert stats.summary.passed_on_from is None  # nothing passed through uninterpreted
    assert list(stats.summary.left) == [REASONS[DRILLED]]  # only the cycles' own moves left as programmed
    holes_written = [c for x, y, *_ in (run[1] for run in runs(moves(written))) for c in (x, y)]
    programmed = [(25, -7.5), (90, -7.5), (90, -42.5), (25, -42.5)]
    assert holes_written == pytest.approx([c for x, y in programmed for c in (x + 5e-5 * y, y)], abs=6e-5)
    last = moves(written)[-1]  # after the drilling: X0 Y100 compensated
    assert last.end[:2] == pytest.approx((0.005, 100.0), abs=6e-5)
    bottoms = [run[1][2] for run in runs(moves(written))]
    assert bottoms == [-6.0] * 4  # (the cycle's levels are the control's: as programmed)


WIDE = SHARED / "machines" / "wide.toml"


@pytest.mark.skipif(not WIDE.exists(), reason="the shared machine files are not here")
def test_a_positioning_move_written_in_pieces_calls_its_cycle_from_the_last():
    """On the shared wide machine (reversal tables, backlash), the feed from the hole at X90 Y-7.5 to
    Y-42.5 is written as a step (X, held, would reverse) and the line: the M99 goes with the line,
    so the hole is drilled at Y-42.5, not where the step ends, above the hole before."""
    text = program(holes=["L FMAX M99", "L  X+90 F500 M99", "L  Y-42.5 F500 M99"], after=["L  Z+21 FMAX"])
    written, _ = compensate(text, WIDE.read_text())
    assert written.count("M99") == 3 and CYCLE_200 in written
    lines = written.splitlines()
    call = next(n for n, line in enumerate(lines) if "Y-42" in line)
    assert lines[call].endswith(" M99") and lines[call - 1].endswith(" F500")  # the step, then the line
    holes = [run[1][:2] for run in runs(moves(written))]
    assert holes[2][1] == pytest.approx(-42.5, abs=0.01) and holes[1][1] == pytest.approx(-7.5, abs=0.01)


def test_a_touch_probe_cycle_ends_interpretation_with_a_warning(tmp_path):
    """A probing program as Fusion's Heidenhain post writes it (polymech-info/heidenhain-simulator,
    `samples/a_phv3/brackets/probe-40.h`): TCH PROBE 412 probes a bore and may set the datum (TNC 640
    User's Manual, Touch Probe Cycles, "Cycle 412 DATUM INSIDE CIRCLE"), so the moves after it cannot be
    placed: the program is compensated up to the cycle and passes through unchanged from it, with a
    warning, where the block was refused as unreadable before."""
    source = "\n".join(["0  BEGIN PGM probe MM", "1  TOOL CALL 100 Z S50", "2  L  X+10  Y+5 R0 FMAX",
                        "3  L  Z+55 R0 FMAX", "4  TCH PROBE 412 DATUM INSIDE CIRCLE ~",
                        "    Q321=+0    ;CENTER IN 1ST AXIS ~", "    Q262=+40   ;NOMINAL DIAMETER",
                        "5  L  X+20 Z+55 FMAX", "6  M30", "7  END PGM probe MM", ""])  # fmt: skip
    path, machine, out = tmp_path / "probe.h", tmp_path / "square.toml", tmp_path / "out.h"
    path.write_text(source)
    machine.write_text(SQUARE)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(machine), str(path),
                           "-o", str(out)], capture_output=True, text=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert "probe.h:5:4: warning: TCH PROBE 412 (a touch probe cycle" in proc.stderr
    written = [re.sub(r"^\d+ +", "", line) for line in out.read_text().splitlines()]  # (ncpp renumbers)
    tail = [re.sub(r"^\d+ +", "", line) for line in source.splitlines()[4:]]
    assert written[-len(tail) :] == tail  # from the cycle on, as it was
    moved = next(line for line in written if line.startswith("L  X+10"))
    assert abs(float(moved.split()[1][1:]) - 10.00025) <= 0.00005  # (X gains 5e-5 * Y on the square machine)


def test_a_warning_in_a_continued_block_names_the_line_its_word_is_on():
    """A cycle definition spans `~`-continued lines (its Q parameters one a line, as the TNC writes it):
    a warning at one of them names that line and its column, not the CYCL DEF's line with a column
    counted through the block's other lines."""
    said = io.StringIO()
    text = program(CYCLE_200.replace("Q206=+30  ", "Q206=AUTO "), ["L FMAX M99"])
    moves(text, said)
    line = next(n for n, row in enumerate(text.splitlines(), 1) if "Q206=AUTO" in row)
    assert said.getvalue().startswith(f"drill.h:{line}:5: warning: Q206=AUTO (a feed ncpp does not follow)")


def test_a_plunging_feed_of_auto_is_the_tool_calls_feed():
    """`Q206= AUTO ;WARTOSC POSUWU WGL.` after `TOOL CALL 8 Z S1500 F120` (janforys/cnc-programming,
    cnc-programming/Heidenhain/DENKO-OTW-BOKI.H; TNC 640 Cycle Programming manual, cycle 200: "Q206 Feed rate
    for plunging ... alternatively FAUTO", the TOOL CALL's feed): the moves of `Q206=+30`.  Without a feed in
    the TOOL CALL, the feed is not told: interpretation ends there."""
    auto = program(CYCLE_200.replace("Q206=+30 ", "Q206= AUTO"))
    told = auto.replace("TOOL CALL 7 Z S10000", "TOOL CALL 7 Z S10000 F30")
    assert runs(moves(told)) == runs(moves(program()))
    said = io.StringIO()
    assert runs(moves(auto, said)) == [] and "Q206=AUTO (a feed ncpp does not follow)" in said.getvalue()


def test_a_contour_cycle_call_leaves_the_scope_and_a_tolerance_cycle_changes_nothing():
    """The SL cycles (14 CONTOUR GEOMETRY, 20 CONTOUR DATA, 22 ROUGH-OUT) cut a pocket the control works
    out itself: their CYCL CALL is out of scope, told at its line.  Cycle 32 TOLERANCE is active once
    defined and moves nothing: the moves after it are followed (drunsinn/language-klartext,
    `testprogramme/SLII001.klartext`, `Krivka.klartext`)."""
    sl = "CYCL DEF 14.0 KONTUR\nCYCL DEF 14.1 KONTURLABEL1 /2 /3\n" + CYCLE_200.replace(
        "200 DRILLING", "20 KONTUR"
    )
    warned = io.StringIO()
    found = moves(program(sl, holes=["CYCL CALL M8"]), warned)
    assert "drill.h:16:4: warning: the cycle call CYCL CALL (CYCL DEF 20) is outside" in warned.getvalue()
    assert len(found) == 2  # (the two moves before the call)
    tolerance = "CYCL DEF 32.0 TOLERANCE\nCYCL DEF 32.1 T0,01\nCYCL DEF 32.2 HSC-MODE:0 TA0"
    followed = moves(program(tolerance, holes=[]))
    assert [m.end for m in followed][-2:] == [(25.0, -7.5, 21.0), (0.0, 100.0, 21.0)]


@pytest.mark.parametrize("angle, turned", [("ROT+0", 0.0), ("IROT+0,000", 0.0), ("ROT+30", 30.0)])
def test_cycle_10_turns_the_moves_after_it_and_a_rotation_of_zero_changes_nothing(angle, turned):
    """`CYCL DEF 10.1 ROT+0` resets cycle 10 ROTATION (Cycle Programming manual, "ROTATION (Cycle
    10)"; drunsinn/language-klartext, `programm-zirkularnut-fraesen.klartext` writes it before its
    moves): it changes nothing; `ROT+30` turns the moves after it about the datum (the last one's
    X+0 Y+100 ends at 100 mm along 120 degrees), the Z move before X and Y are given in place."""
    warned = io.StringIO()
    found = moves(program(f"CYCL DEF 10.0 ROTATION\nCYCL DEF 10.1 {angle}", holes=[]), warned)
    assert not warned.getvalue(), warned.getvalue()
    assert len(found) == 4
    assert found[-2].end == pytest.approx((25.0, -7.5, 21.0), abs=1e-12)
    along = math.radians(90.0 + turned)
    assert found[-1].end == pytest.approx((100 * math.cos(along), 100 * math.sin(along), 21.0), abs=1e-12)


POCKET_4 = [  # an iTNC 530 program's cycle 4 POCKET MILLING (a DMU 50's, its blocks N35-N41)
    "CYCL DEF 4.0 TASCHENFRAESEN",
    "CYCL DEF 4.1 ABST 1",
    "CYCL DEF 4.2 TIEFE -4",
    "CYCL DEF 4.3 ZUSTLG 4 F100",
    "CYCL DEF 4.4 X+145",
    "CYCL DEF 4.5 Y+35.065",
    "CYCL DEF 4.6 F200 DR- RADIUS 16",
]


def test_the_old_pocket_cycle_is_read_and_its_call_ends_interpretation():
    """Cycle 4's last line writes the corner radius after a blank, `RADIUS 16` (iTNC 530 User's Manual,
    Conversational Programming, "POCKET MILLING (Cycle 4)"): the program is read, its moves before the
    cycle's call are compensated (X gains 5e-5 · Y), the definition is written as read, and the call,
    a cycle ncpp does not follow, passes through with the rest."""
    body = ["TOOL CALL 2 Z S2020 F200", "L  X+60 Y+45 Z+1 R0 FMAX", *POCKET_4, "L  X+60 Y+85 Z+1 FMAX",
            "CYCL CALL", "L  X+200 Y+200 Z+100 FMAX", "M30"]  # fmt: skip
    lines = ["0  BEGIN PGM POCKET MM"] + [f"{n}  {text}" for n, text in enumerate(body, 1)]
    text = "\n".join(lines + [f"{len(body) + 1}  END PGM POCKET MM"]) + "\n"
    written, stats = compensate(text)
    assert all(line in written for line in POCKET_4)
    tail = [line.split(" ", 1)[1] for line in written.splitlines()[-4:]]  # (renumbered after the header)
    assert tail == [line.split(" ", 1)[1] for line in lines[-3:]] + [" END PGM POCKET MM"]
    assert stats.summary.passed_on_from == len(body) - 2 + 1  # the CYCL CALL's line
    ends = [c for m in moves(written)[:2] for c in m.end[:2]]
    assert ends == pytest.approx([60 + 5e-5 * 45, 45, 60 + 5e-5 * 85, 85], abs=6e-5)


@pytest.mark.parametrize(
    "cycle, what",
    [("8.0 MIRROR IMAGE", "a mirror image"), ("11.0 SCALING", "a scaling"),
     ("19.0 WORKING PLANE", "a tilted working plane"), ("26.0 AXIS-SPECIFIC SCALING", "an axis-specific scaling")],
)  # fmt: skip
def test_a_transformation_cycle_ncpp_does_not_follow_is_named_for_what_it_does(cycle, what):
    """Cycles 8, 11, 19 and 26 transform the coordinate system (TNC 640 Cycle Programming manual,
    "MIRRORING (Cycle 8)", "SCALING (Cycle 11)", "WORKING PLANE (Cycle 19)", "AXIS-SPECIFIC SCALING
    (Cycle 26)"); the warning said each "moves the datum", which none of them does (a TNC 426 manual
    program mirrored by cycle 8 met it)."""
    warned = io.StringIO()
    moves(program(before=f"CYCL DEF {cycle}"), warned)
    assert f"CYCL DEF {cycle.split()[0]} ({what} of the coordinate system) is outside" in warned.getvalue()
    assert "moves the datum" not in warned.getvalue()
