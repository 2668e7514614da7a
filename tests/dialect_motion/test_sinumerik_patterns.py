"""Sinumerik tapping and boring cycles (CYCLE84, CYCLE840, CYCLE85-CYCLE89) and the hole
patterns HOLES1 / HOLES2 under MCALL.

Expected moves are worked out by hand from the 840D Programming Guide Cycles ("Drilling cycles
and drilling patterns"): each cycle's sequence between RFP+SDIS and RTP (`sinumerik_cycles`
sums them up), the tapping feed the spindle speed times the pitch PIT; "Row of holes - HOLES1"
(SPCA SPCO a reference point, STA1 the row's angle, FDIS the first hole's distance, DBH the
distance between holes, NUM holes; the cycle starts at the end nearer the tool) and "Circle of
holes - HOLES2" (CPA CPO the centre, RAD, STA1 the first hole's angle, INDA the angle between
holes, 0: 360/NUM).  The holes' angles and distances are computed here in closed form."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from ncpp.motion.segments import DRILLED, PATTERN, Line, Pass
from ncpp.summary import REASONS
from tests.conftest import ROOT, SHARED
from tests.dialect_motion.test_sinumerik_drilling import HEAD, _events
from tests.writeback.conftest import SQUARE, compensate_file

# Tool at X10 Y20 Z50, F200, S500 before the cycle; RTP 10, RFP 0, SDIS 2
SPINDLE = HEAD.replace("F200\n", "F200 S500 M3\n")


def levels(events: list, fixed: str = DRILLED) -> list[tuple]:
    """(Z end, feed: None for G0) of the cycles' moves."""
    return [
        (round(e.end[2], 6), None if e.rapid else e.feed)
        for e in events
        if type(e) is Line and e.fixed == fixed
    ]


@pytest.mark.parametrize(
    ("call", "expected", "dwells"),
    [
        # rigid tapping: in at SST 400 × PIT 1.5, out at SST1 800 × 1.5
        ("CYCLE84(10, 0, 2, -12, , 0.5, 3, , 1.5, 0, 400, 800)", [(2, None), (-12, 600), (2, 1200), (10, None)],
         [0.5]),
        # SST1 0: out at SST too
        ("CYCLE84(10, 0, 2, -12, , 0, 3, , -1.5, 0, 400, 0)", [(2, None), (-12, 600), (2, 600), (10, None)], []),
        # compensating chuck with encoder: the spindle speed S500 before it × PIT 1.25, DPR 12
        ("CYCLE840(10, 0, 2, , 12, 0, 4, 3, 0, , 1.25)", [(2, None), (-12, 625), (2, 625), (10, None)], []),
        # without encoder and no pitch: the programmed F200 both ways
        ("CYCLE840(10, 0, 2, -12, , 1, 4, 3, 1)", [(2, None), (-12, 200), (2, 200), (10, None)], [1.0]),
        # boring 1: in at FFR 100, out at RFF 300
        ("CYCLE85(10, 0, 2, -8, , 0.2, 100, 300)", [(2, None), (-8, 100), (2, 300), (10, None)], [0.2]),
        # boring 2 without lift-off: out at G0 to RFP+SDIS, then to RTP
        ("CYCLE86(10, 0, 2, -8, , 0.2, 3, 0, 0, 0, 45)", [(2, None), (-8, 200), (2, None), (10, None)], [0.2]),
        # boring 3 and 4: M5 M0 at the depth, then on NC start G0 to RTP
        ("CYCLE87(10, 0, 2, -8, , 3)", [(2, None), (-8, 200), (10, None)], []),
        ("CYCLE88(10, 0, 2, -8, , 1.5, 3)", [(2, None), (-8, 200), (10, None)], [1.5]),
        # boring 5: out at the feed it went in at
        ("CYCLE89(10, 0, 2, -8, , 1)", [(2, None), (-8, 200), (2, 200), (10, None)], [1.0]),
    ],
)  # fmt: skip
def test_tapping_and_boring_cycles_move_as_the_manual_says(call, expected, dwells):
    events, warned = _events(SPINDLE + call + "\nG1 X0 Y0\nM30\n")
    assert levels(events) == expected
    assert [e.dwell for e in events if type(e) is Pass and e.dwell is not None] == dwells
    last = [e for e in events if type(e) is Line][-1]
    assert not last.fixed and last.start == (10, 20, 10) and warned == ""


@pytest.mark.parametrize(
    ("call", "said"),
    [
        ("CYCLE84(10, 0, 2, -12, , 0, 3, 8, , 0, 400, 0)", "the thread pitch as a thread size MPIT"),
        ("CYCLE84(10, 0, 2, -12, , 0, 3, , 1.5, 0, 0, 0)", "CYCLE84 without a spindle speed (SST)"),
        ("CYCLE840(10, 0, 2, -12, , 0, 4, 3, 2, , 1)", "CYCLE840 with ENC=2"),
        ("CYCLE86(10, 0, 2, -8, , 0, 3, 0.5, 0, 0, 45)", "CYCLE86 with a lift-off"),
        ("CYCLE84(10, 0, 2, -12, , 0, 3, , 1.5, 0, 400, 0, 3)", "CYCLE84 with more than 12 parameters"),
    ],
)
def test_what_the_tapping_and_boring_cycles_leave_to_the_control_ends_interpretation(call, said):
    events, warned = _events(HEAD + call + "\nG0 X1\nM30\n")
    assert said in warned and not levels(events)


def holes(events: list) -> list[tuple[float, float]]:
    """X Y of each feed down into a hole of a pattern."""
    return [e.end[:2] for e in events
            if type(e) is Line and e.fixed == PATTERN and not e.rapid and e.end[2] < e.start[2]]  # fmt: skip


def close(found: list[tuple[float, float]], expected: list[tuple[float, float]]) -> bool:
    return len(found) == len(expected) and all(math.dist(f, e) < 1e-9 for f, e in zip(found, expected))


def test_holes2_drills_the_modal_cycle_at_num_holes_from_sta1():
    """INDA 0: 360/6 apart; each hole G0 in the plane at RTP, CYCLE81 down to -4 and back to 10."""
    events, warned = _events(
        HEAD + "MCALL CYCLE81(10, 0, 2, -4)\nHOLES2(50, 20, 20, 30, 0, 6)\nMCALL\nG1 X0 Y0\nM30\n"
    )
    angles = [math.radians(30 + 60 * k) for k in range(6)]
    assert close(holes(events), [(50 + 20 * math.cos(a), 20 + 20 * math.sin(a)) for a in angles])
    assert levels(events, PATTERN)[:4] == [(50, None), (2, None), (-4, 200), (10, None)]
    pitch = _events(HEAD + "MCALL CYCLE81(10, 0, 2, -4)\nHOLES2(0, 0, 10, -90, 45, 3)\nMCALL\nM30\n")[0]
    assert close(
        holes(pitch),
        [(10 * math.cos(math.radians(a)), 10 * math.sin(math.radians(a))) for a in (-90, -45, 0)],
    )
    last = [e for e in events if type(e) is Line][-1]
    assert not last.fixed and warned == ""


def test_holes1_starts_at_the_end_of_the_row_nearer_the_tool():
    """STA1 90: the row runs up Y from FDIS 10 in steps of DBH 8; from X10 Y20 the first hole
    (0, 10) is nearer than the last (0, 34); from Y60 the last is."""
    row = [(0, 10 + 8 * k) for k in range(4)]
    call = "MCALL CYCLE82(10, 0, 2, -4, , 0.5)\nHOLES1(0, 0, 90, 10, 8, 4)\nMCALL\nM30\n"
    assert close(holes(_events(HEAD + call)[0]), row)
    assert close(holes(_events(HEAD + "G0 Y60\n" + call)[0]), row[::-1])


@pytest.mark.parametrize(
    ("text", "said"),
    [
        ("HOLES2(50, 20, 20, 30, 0, 6)\n", "a hole pattern without a drilling cycle under MCALL"),
        ("MCALL CYCLE81(10, 0, 2, -4)\nCYCLE801(0, 0, 0, 5, 5, 2, 2)\nMCALL\n", "the hole pattern CYCLE801"),
        (
            "MCALL CYCLE81(10, 0, 2, -4)\nG0 X-10 Y22\nHOLES1(0, 0, 90, 10, 24, 2)\nMCALL\n",
            "as far from either end",
        ),
    ],
)
def test_patterns_ncpp_cannot_follow_end_interpretation(text, said):
    events, warned = _events(HEAD + text + "G0 X1\nM30\n")
    assert said in warned and not holes(events)


def test_the_holes_stay_where_the_pattern_puts_them_and_the_moves_after_are_compensated(tmp_path):
    """SQUARE: the machine's X is off by 50 µm/m of Y.  The MCALL and HOLES2 blocks are written as
    read, the holes stay where the pattern puts them, the move to X60 Y400 after them is corrected."""
    text = HEAD + "MCALL CYCLE81(10, 0, 2, -4)\nHOLES2(50, 20, 20, 30, 0, 6)\nMCALL\nG1 X60 Y400 F300\nM30\n"
    program = tmp_path / "d.mpf"
    program.write_text(text)
    written = compensate_file(program, SQUARE, tmp_path).read_text()
    assert "HOLES2(50, 20, 20, 30, 0, 6)\n" in written and "MCALL CYCLE81(10, 0, 2, -4)\n" in written
    events = _events(written)[0]
    assert holes(events) == holes(_events(text)[0])
    last = [e for e in events if type(e) is Line][-1]
    assert not last.fixed and last.end[0] == pytest.approx(60 + 50e-6 * 400, abs=5e-4) and last.end[0] != 60


def test_a_tapping_cycle_drills_where_the_compensated_move_leaves_the_tool(tmp_path):
    text = SPINDLE + "G0 X40 Y300\nCYCLE84(10, 0, 2, -12, , 0, 3, , 1.5, 0, 400, 0)\nG0 X0 Y0\nM30\n"
    program = tmp_path / "d.mpf"
    program.write_text(text)
    written = compensate_file(program, SQUARE, tmp_path).read_text()
    bottom = next(e for e in _events(written)[0] if type(e) is Line and e.fixed == DRILLED and not e.rapid)
    assert bottom.end[0] == pytest.approx(40 + 50e-6 * 300, abs=5e-4) and bottom.end[2] == -12


WIDE = SHARED / "machines" / "wide.toml"


@pytest.mark.skipif(not WIDE.exists(), reason="the shared machine files are not here")
def test_the_command_line_compensates_around_holes1_and_holes2_on_the_wide_machine(tmp_path):
    source = tmp_path / "holes.mpf"
    source.write_text(SPINDLE + "MCALL CYCLE85(10, 0, 2, -8, , 0.2, 100, 300)\nHOLES2(50, 20, 20, 30, 0, 6)\n"
                      "HOLES1(0, 0, 90, 10, 8, 4)\nMCALL\nG1 X0 Y0\nM30\n")  # fmt: skip
    out = tmp_path / "out.mpf"
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(WIDE), str(source),
                           "-o", str(out)], capture_output=True, cwd=ROOT)  # fmt: skip
    assert proc.returncode == 0, proc.stderr.decode()
    said = proc.stderr.decode()
    assert "passes through uninterpreted" not in said and REASONS[PATTERN] in said
    events = _events(out.read_text())[0]
    assert len(holes(events)) == 10 and holes(events) == holes(_events(source.read_text())[0])
    last = [e for e in events if type(e) is Line][-1]
    assert not last.fixed and last.end[:2] != (0.0, 0.0) and last.end[:2] == pytest.approx((0, 0), abs=0.01)


def test_ncpp_motion_prints_a_circle_of_holes_at_their_angles(tmp_path):
    """`ncpp motion` (rs274's canonical calls): each STRAIGHT_FEED is a hole's bottom, at Z-4."""
    source = tmp_path / "circle.mpf"
    source.write_text(HEAD + "MCALL CYCLE81(10, 0, 2, -4)\nHOLES2(50, 20, 20, 30, 0, 6)\nMCALL\nM30\n")
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "motion", str(source)], capture_output=True, cwd=ROOT
    )
    feeds = [line for line in proc.stdout.decode().splitlines() if line.startswith("STRAIGHT_FEED")]
    bottoms = [tuple(float(v) for v in line[len("STRAIGHT_FEED(") : -1].split(", ")[:3]) for line in feeds]
    angles = [math.radians(30 + 60 * k) for k in range(6)]
    expected = [(50 + 20 * math.cos(a), 20 + 20 * math.sin(a), -4.0) for a in angles]
    assert proc.returncode == 0 and len(bottoms) == 6
    assert all(math.dist(b, e) < 1e-4 for b, e in zip(bottoms, expected))  # (printed to 4 places)
