"""Cutter compensation (G40-G42.1) against LinuxCNC's rs274: the interpreter follows the
programmed positions through it, gives the moves the tool makes off the programmed path where
the tool centre stands (`centre_shift`; in a plane other than XY it marks them `COMP`), is back
on the program's positions after the first move after G40, and refuses what rs274 refuses with
compensation on, on the same line."""

from __future__ import annotations

import io
import math
import re

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion import interpret
from ncpp.motion.segments import COMP, Arc, Line
from ncpp.program.parser import parse_stream
from tests import rs274 as oracle
from tests.conftest import RS274
from tests.motion.compensating import compensate
from tests.motion.test_oracle import (
    assert_refused_like_rs274,
    ours,
    read_canon,
    rs274,
    rs274_error,
    same_calls,
    without_comp,
    write_program,
)

needs_rs274 = pytest.mark.skipif(not RS274.exists(), reason="rs274 oracle not available")

HEAD = "G21 G90 G17 G94 G64\nG0 X0 Y0 Z5\nG1 Z-1 F100\n"
CONTOUR = (
    HEAD
    + "G41.1 D10\nG1 X10 Y0\nG1 X10 Y10\nG2 X20 Y20 R10\nG1 Y30\nG40\nG1 X30\nG1 Y40 Z2\nG2 X40 Y50 I10\nM2\n"
)


def events_of(text: str, **kwargs) -> list:
    return list(interpret(parse_stream(io.BytesIO(text.encode()), "t.ngc"), file="t.ngc", **kwargs))


def moves(events) -> list:
    return [e for e in events if type(e) is Line or type(e) is Arc]


def test_moves_off_the_path_are_marked_from_the_first_under_comp_to_the_first_after_g40():
    lines = [(e.block.line, e.fixed, e.centre_shift is not None) for e in moves(events_of(CONTOUR))]
    assert lines == [(2, "", False), (3, "", False)] + [(n, "", True) for n in (5, 6, 7, 8, 10)] + [
        (11, "", False),
        (12, "", False),
    ]
    in_xz = (
        CONTOUR.replace("G41.1", "G18 G41.1")
        .replace("G2 X20 Y20 R10", "G2 X20 Z-1 R10")
        .replace("G2 X40 Y50 I10", "G17 G2 X40 Y50 I10")
    )
    followed = moves(events_of(in_xz))[2:7]
    assert [(e.block.line, e.fixed, e.centre_shift is not None) for e in followed] == [
        (n, "", True) for n in (5, 6, 7, 8, 10)
    ]
    # a lathe tool's orientation (L 1-8): the control moves its tip along the offset contour
    lathe = moves(events_of(in_xz.replace("G41.1 D10", "G41.1 D10 L3")))
    assert [(e.block.line, e.fixed) for e in lathe[2:7]] == [(n, COMP) for n in (5, 6, 7, 8, 10)]


def test_the_tool_centre_stands_off_each_move_by_the_radius_to_the_left_of_its_own_direction():
    """G41.1 D10: 5 mm left of the line's direction and radially on the arc, at the end of each move;
    a move starts where the move before left the tool centre (the entry move on its programmed point,
    None), and the exit move after G40 ends on its programmed point."""
    shifts = [e.centre_shift for e in moves(events_of(CONTOUR))[2:7]]
    left_of_x, left_of_y = (0.0, 5.0, 0.0), (-5.0, 0.0, 0.0)
    ends = [left_of_x, left_of_y, left_of_x, left_of_y, (0.0, 0.0, 0.0)]
    assert all(math.dist(s[1], end) < 1e-12 for s, end in zip(shifts, ends))
    assert shifts[0][0] is None and [s[0] for s in shifts[1:]] == [s[1] for s in shifts[:-1]]


def test_in_g18_left_is_as_seen_from_plus_y():
    """G18 G41.1 D10: left of the direction as seen from +Y, in the plane's Z X order (LinuxCNC's
    G41; rs274 puts the tool centre of `G1 X10` from X0 Z-1 at Z-6): moving +X, the tool centre
    stands at -Z; moving +Z, at +X; on an arc turning G2 (clockwise seen from +Y) away from its centre."""
    text = HEAD + "G18 G41.1 D10\nG1 X10\nG1 Z20\nG2 X30 Z40 I20 K0\nG40\nG1 X40\nM2\n"
    shifts = [e.centre_shift[1] for e in moves(events_of(text))[2:5]]
    assert all(math.dist(s, end) < 1e-12 for s, end in zip(shifts, [(0, 0, -5), (5, 0, 0), (0, 0, 5)]))


def test_after_g40_the_position_is_the_programs():
    """rs274 takes an axis the exit move does not name from the programmed contour, not from the
    tool centre: `G1 X30` after the contour's `G1 Y30` ends at (30, 30)."""
    exit_move = moves(events_of(CONTOUR))[6]
    assert exit_move.end[:2] == (30.0, 30.0)


@needs_rs274
def test_simulate_samples_the_tool_centre_where_rs274_runs_it(tmp_path):
    """`ncpp simulate` evaluates the machine's errors where the tool centre runs under cutter
    compensation ncpp follows: every feed sample of the G41.1 contour lies on rs274's tool-centre path."""
    import numpy as np

    from ncpp.cli.simulate import program_events
    from ncpp.simulate import sample_events
    from tests.compensation.tool_centre import Move, deviation, feed_moves

    path = write_program(tmp_path, CONTOUR)
    sampled = sample_events(program_events(str(path), Warnings(stream=io.StringIO())), 0.5)
    points = sampled.points[~sampled.rapid]
    theirs = feed_moves(path, home=tmp_path)
    assert sum(m.comp > 0 for m in theirs) >= 4 and len(points) > 100
    apart = deviation(theirs, [Move(p, p) for p in points], lambda q: q, count=1)
    assert np.max(apart) < 1e-6


@needs_rs274
@pytest.mark.parametrize("name", ["contour", "comp.ngc"])
def test_ncpp_motion_prints_the_tool_centre_as_rs274_does(tmp_path, corpus, name):
    """Under cutter compensation ncpp follows, `ncpp motion` prints rs274's canonical calls of the tool
    centre, line for line: the corpus's comp.ngc (G41/G42 D1 of a tool table, inch; G17 and G18) and a
    G41.1 contour."""
    import subprocess
    import sys

    from tests.conftest import CORPUS
    from tests.verify.test_corpus_pathcheck import tool_table

    table = tool_table(tmp_path)
    path = CORPUS / "iso_gcode/linuxcnc/comp.ngc" if name == "comp.ngc" else write_program(tmp_path, CONTOUR)
    motion = subprocess.run([sys.executable, "-m", "ncpp", "motion", "--tool-table", str(table), "--var-units",
                             "inch", str(path)], capture_output=True, text=True, check=True)  # fmt: skip
    calls = oracle.run(path, tool_table=table, home=tmp_path, cwd=tmp_path).stdout
    theirs = re.findall(r"(?:STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|RIGID_TAP)\(.*\)", calls)
    assert "cutter compensation" not in motion.stderr, motion.stderr
    assert motion.stdout.splitlines() == theirs


@needs_rs274
@pytest.mark.parametrize(
    "body",
    [
        CONTOUR[len(HEAD) :],
        "G42.1 D4\nG0 X10 Y10\nG0 X20\nG40 G0 X30\nG1 Y5\nG3 X40 Y15 J10\n",  # rapids, G40 with the exit move
        "G18\nG41.1 D2\nG1 X10 Z-5\nG1 X20\nG40\nG1 X30 Z0\nG2 X40 Z10 I10\n",  # the XZ plane
        "G41.1 D2\nG91 G1 X10\nG1 Y10\nG90\nG40\nG1 X30 Y5\nG1 X0\n",  # increments under compensation
        "G41.1 D2\nG1 X10 Y10\nG40 G55\nG1 X20 Y20\nG54 G1 X0\n",  # G40 first, then the system: allowed
        "G41.1 D2\nG1 X10\nG10 L2 P2 X3\nG92.1\nG20\nG1 X1\nG21\nG40\nG0 Z5\nG0 X0 Y0\n",  # allowed under compensation
        "G41.1 D2\nG40\nG2 X10 I5\n",  # no move under compensation: an arc may follow G40
        "G41.1 D0\nG1 X10 Y10\nG40\nG3 X-2 Y-16 R32\nG1 X0\n",  # nor with a radius of 0
        "G41.1 D0\nG1 X10\nG1 Y10\nG40\nG1 X0\nG1 X5 Y5\n",
        "G41.1 D10\nG1 X5.001\nG2 X15.001 I5\nG1 Y-20\nG40\nG1 X0\nG1 Y5\n",  # longer than the radius; an arc off the tool's side
        "G41.1 D0\nG1 Z-2\nG1 X10\nG53 G0 X0\nG40\nG1 X0\nG1 Y5\n",  # radius 0: no check, and G53 allowed
        "G41.1 D10\nG1 X20\nG20\nG1 X1\nG3 X1.6 R0.3\nG40\nG1 X0\nG1 Y5\n",  # the radius follows G20 (0.197 in)  # radius 0: rs274's moves are the programmed ones
    ],
    ids=[
        "contour",
        "rapids",
        "xz",
        "g91",
        "g40-g55",
        "allowed",
        "no-move",
        "d0-arc",
        "d0",
        "radius",
        "d0-z",
        "units",
    ],
)
def test_moves_after_compensation_agree_with_rs274(tmp_path, body):
    path = write_program(tmp_path, HEAD + body)
    calls, messages = rs274(str(path))
    assert rs274_error(messages) is None, messages
    off_path: list[bool] = []
    mine, error, warning = ours(path, off_path)
    assert error is None and not warning, (error, warning)
    theirs, kept = without_comp(read_canon(calls), mine, off_path)
    assert not off_path[-1] and len(kept) == len(theirs), (theirs, kept)  # the last move is compared
    assert same_calls(theirs, kept), (theirs, kept)


@needs_rs274
@pytest.mark.parametrize(
    "body, line",
    [
        ("G41.1 D2\nG1 X10\nT1 M6\n", 6),
        ("G41.1 D2\nG1 X10\nG81 X20 Z-2 R1\n", 6),
        ("G41.1 D2\nG1 X10\nG18\n", 6),
        ("G41.1 D2\nG1 X10\nG55\n", 6),
        ("G41.1 D2\nG1 X10\nG54\n", 6),  # the system in effect too
        ("G41.1 D2\nG1 X10\nG92 X0\n", 6),
        ("G41.1 D2\nG1 X10\nG52 X1\n", 6),
        ("G41.1 D2\nG1 X10\nG28\n", 6),
        ("G41.1 D2\nG1 X10\nG30.1\n", 6),
        ("G41.1 D2\nG1 X10\nG53 G1 X20\n", 6),
        ("G41.1 D2\nG1 X10\nG43 H1\n", 6),
        ("G41.1 D2\nG1 X10\nG49\n", 6),
        ("G41.1 D2\nG1 X10\nG10 L2 P1 X3\n", 6),
        ("G41.1 D2\nG1 X10\nG64\n", 6),
        ("G41.1 D2\nG1 X10\nG38.2 X20\n", 6),
        ("G41.1 D2\nG1 X10\nG5 X20 I1 J1 P1 Q1\n", 6),
        ("G41.1 D2\nG1 X10\nG42.1 D2\n", 6),
        ("G41.1 D2\nG1 X10\nM6 T1 G40\n", 6),  # the tool change comes before G40 takes effect
        ("G19\nG41.1 D2\n", 5),
        ("G41.1\n", 4),
        ("G41 D-1\n", 4),
        ("G41.1 D2\nG1 X10\nG1 Y5\nG40\nG2 X20 I5\n", 8),
        ("G41.1 D2\nG1 X10\nG40 G2 X20 I5\n", 6),
        ("G41.1 D2\nG1 X10 Y10\nG40\nG28\nG3 X-2 Y-16 R32\n", 8),  # a G28 is not the straight move
        ("G41.1 D2\nG1 X10 Y10\nG40\nG81 X1 Y1 Z-2 R1\nG80\nG3 X-2 Y-16 R32\n", 9),  # nor a canned cycle
        # the tool radius of G41.1/G42.1 (D: the diameter) against the entry move and arcs on the tool's side
        ("G41.1 D10\nG1 X3\n", 5),
        ("G41.1 D10\nG1 X5\n", 5),  # not greater
        ("G41.1 D10\nG1 Z-2\nG1 X20\n", 5),  # the first move under compensation is the entry
        ("G41.1 D10\nG0 X3\n", 5),
        ("G18\nG41.1 D10\nG1 X3 Z-4.001\n", 6),  # in the XZ plane, from Z-1
        ("G20\nG41.1 D0.3\nG1 X0.1\n", 6),
        ("G41.1 D10\nG2 X4 I2\n", 5),  # an entry arc's chord
        ("G42.1 D10\nG2 X4 I2\n", 5),  # (before its radius)
        ("G1 Y0.001\nG41.1 D2\nG2 X0 Y0.001 R30\n", 6),  # (before the arc's centre: no chord at all)
        ("G41.1 D10\nG2 X3 Y3 Z-3 I1.5 J1.5\n", 5),  # a helix: in the plane
        ("G42.1 D10\nG2 X10 I5\n", 5),
        ("G41.1 D10\nG3 X8 I4\n", 5),
        ("G41.1 D10\nG1 X10\nG3 X14 I2\n", 6),
        ("G41.1 D10\nG1 X10\nG3 X14 R2\n", 6),
        ("G41.1 D10 L3\nG1 X20\n", 4),  # a lathe tool's orientation outside G18
        ("G18\nG41.1 D10 L2.5\nG1 X20\n", 5),
    ],
)
def test_refused_with_compensation_as_rs274_refuses(tmp_path, body, line):
    path = write_program(tmp_path, HEAD + body)
    assert_refused_like_rs274(path, line)
    _, error, _ = ours(path)
    assert rs274_error(rs274(str(path))[1])[0] == error.message  # type: ignore[index,union-attr]


def test_the_ccomp_parameter_says_the_mode():
    text = HEAD + "#1 = #<_ccomp>\nG42.1 D2\n#2 = #<_ccomp>\nG40\n#3 = #<_ccomp>\nG1 X#1 Y#2 Z#3\n"
    assert moves(events_of(text))[-1].end == (400.0, 421.0, 400.0)


def test_program_end_ends_compensation():
    events = moves(events_of(HEAD + "G41.1 D2\nG1 X10\nM2\n"))
    assert events[-1].centre_shift is not None
    from ncpp.motion.interpreter import Interpreter

    interpreter = Interpreter("t.ngc")
    list(
        interpreter.run(
            parse_stream(io.BytesIO((HEAD + "G41.1 D2\nG1 X10\nM2\n").encode()), "t.ngc"), Warnings()
        )
    )
    assert interpreter.cutter_comp is None and not interpreter.centre.off_path


def test_fanuc_corners_under_compensation_are_the_controls_and_the_position_is_followed():
    """A Fanuc `,R` / `,C` corner under G41/G42: the control rounds the contour, then offsets it.
    Every piece is left as programmed, and so is the move the exit move's corner rounds into (the
    control rounds between the two texts: a corrected next move would not take the fillet);
    after it the moves are those of the same program without the corners, compensated."""
    body = "G41.1 D2\nG1 X10 ,R1\nG1 Y10 ,C1\nG1 X0\nG40\nG1 X-5 Y-5 ,R1\nG1 X-20\nG1 Y20\n"
    rounded = moves(events_of(HEAD + body))
    plain = moves(events_of(HEAD + body.replace(" ,R1", "").replace(" ,C1", "")))
    assert [e.fixed for e in rounded] == ["", ""] + [COMP] * 8 + [
        ""
    ]  # (the exit move's fillet and partner too)
    assert [e.end for e in rounded[-2:]] == [e.end for e in plain[-2:]]
    out, warned = compensate(HEAD + body, "corner.ngc")
    lines, start = out.splitlines(), out.splitlines().index("G41.1 D2")
    assert (
        lines[start : start + 7] == body.splitlines()[:7] and warned.count("cutter compensation") == 1
    )  # to the move after the exit move
    assert lines[start + 7] != body.splitlines()[7]  # compensated again


# -- compensation ---------------------------------------------------------------------------------
# in the XZ plane with a lathe tool's orientation: compensation that ncpp does not follow
POCKET = (
    HEAD
    + "G1 X-20 Y-20\nG1 X-5\nG18\nG41.1 D6 L3\nG1 X0 Z0\nG1 X40\nG2 X50 Z10 R10\nG1 Z40\nG40\nG1 X55 Z45\nG1 X70\n"
    "G17\nG2 X80 Y-10 R10\nG0 Z10\nM2\n"
)


def test_moves_off_the_path_pass_through_and_compensation_resumes_after_the_exit_move():
    out, warned = compensate(POCKET, "comp.ngc")
    original, lines = POCKET.splitlines(), out.splitlines()[1:]  # (the header)
    start = lines.index("G41.1 D6 L3")
    assert lines[start - 2].startswith("X-4.97")  # `G1 X-5` compensated before it
    assert lines[start : start + 7] == original[6:13]  # from G41.1 to the exit move: verbatim
    after = lines[start + 7 :]
    # from the exit move's end (as programmed) to the compensated end of the next line, every axis said
    assert after[0].startswith("G1 X70.0") and "Y-19.9" in after[0] and "Z45.0" in after[0]
    assert any(line.startswith("G2 ") and "I" in line for line in after)  # the arc after it replaced
    assert (
        warned.count("warning") == 1
        and "comp.ngc:8:1: warning: cutter compensation: its moves pass through uncompensated" in warned
    )


def test_strict_refuses_moves_under_compensation_it_does_not_follow():
    with pytest.raises(NcppError, match="comp.ngc:8:1: cutter compensation"):
        compensate(POCKET, "comp.ngc", strict=True)


def test_in_g91_the_moves_under_compensation_are_compensated_as_increments():
    """G91 under compensation: each move is corrected where the tool centre stands, written as
    the increment from the compensated end before it (test_cutter_comp_accuracy measures them
    with rs274); with a lathe tool's orientation in G18 they run as programmed from the
    compensated point before them (`apply_error_map._carry`, test_exact_model)."""
    text = HEAD + "G1 X-20 Y-20\nG41.1 D6\nG91 G1 X20\nG1 Y20\nG40\nG1 X10 Y10\nG1 X30\nG90\nG1 X0 Y0\n"
    out, warned = compensate(text, "comp.ngc")
    lines = out.splitlines()
    start = lines.index("G41.1 D6")
    written, programmed = lines[start + 1 : start + 7], text.splitlines()[5:11]
    kept = [w == p for w, p in zip(written, programmed)]
    assert kept == [False, False, True, False, False, True]  # (G40, G90)
    for w, p in zip(written, programmed):  # increments within the corrections (tens of µm) of the program's
        words, theirs = (dict((t[0], float(t[1:])) for t in line.split() if t[0] in "XY") for line in (w, p))
        assert all(abs(words[k] - v) < 0.05 for k, v in theirs.items()), (w, p)
    assert "cutter compensation" not in warned


@needs_rs274
def test_rs274_runs_the_compensated_program_with_the_same_moves_under_compensation(tmp_path):
    out, _ = compensate(POCKET, "comp.ngc")
    before, after = write_program(tmp_path, POCKET, "in.ngc"), write_program(tmp_path, out, "out.ngc")
    calls, messages = rs274(str(after))
    assert rs274_error(messages) is None, messages
    original, compensated = read_canon(rs274(str(before))[0]), read_canon(calls)
    # the tool centre's moves from the arc after the entry move to the exit move: the same
    # (their Z is where the compensated line before them left it); the entry move's end moves a
    # little with its start (rs274 offsets it square to the move), which compensation moved
    # (in the XZ plane: X and Z, an arc's Z X ends and centre)
    k, n = (next(i for i, c in enumerate(calls) if c.name == "ARC_FEED") for calls in (original, compensated))
    xz = lambda a: (a.name, a.args[:4] if a.name == "ARC_FEED" else a.args[:3:2])  # noqa: E731
    assert [xz(a) for a in original[k : k + 3]] == [xz(a) for a in compensated[n : n + 3]]
    assert math.dist(original[k - 1].args[:3:2], compensated[n - 1].args[:3:2]) < 0.005
    assert compensated[n + 3].args[:2] != original[k + 3].args[:2]  # compensated again after the exit move


def test_motion_and_simulate_say_where_the_tool_leaves_the_programmed_contour(tmp_path):
    import subprocess
    import sys

    from tests.conftest import ROOT

    placed = CONTOUR.replace("G0 X0 Y0 Z5", "G0 X0 Y0 Z5\nG10 L2 P1 X400 Y350 Z400")
    path = write_program(tmp_path, placed)
    # (G41 D1 with no tool table: the radius is not known, and `ncpp motion` prints the contour)
    unknown = write_program(tmp_path, placed.replace("G41.1 D10", "G41 D1"), "unknown.ngc")
    run = [sys.executable, "-m", "ncpp"]
    motion = subprocess.run([*run, "motion", str(unknown)], capture_output=True, text=True)
    assert (
        motion.returncode == 0
        and motion.stderr.count("warning: cutter compensation") == 1
        and "unknown.ngc:6:1: warning: cutter compensation" in motion.stderr
    )
    assert (
        "printed as programmed" in motion.stderr
        and "STRAIGHT_FEED(30.0000, 30.0000, -1.0000" in motion.stdout
    )
    assert (
        subprocess.run([*run, "motion", "--strict", str(unknown)], capture_output=True, text=True).returncode
        != 0
    )
    followed = subprocess.run([*run, "motion", str(path)], capture_output=True, text=True)
    assert followed.returncode == 0 and "cutter compensation" not in followed.stderr, followed.stderr
    simulate = [*run, "simulate", "--machine", str(ROOT / "samples/machines/hr5b.toml")]
    unfollowed = subprocess.run([*simulate, str(unknown)], capture_output=True, text=True)
    assert (
        unfollowed.returncode == 0
        and "unknown.ngc:6:1: warning: cutter compensation" in unfollowed.stderr
        and "simulated as programmed" in unfollowed.stderr
    )
    simulated = subprocess.run([*simulate, str(path)], capture_output=True, text=True)
    assert simulated.returncode == 0 and "cutter compensation" not in simulated.stderr, simulated.stderr


@needs_rs274
@pytest.mark.parametrize(
    "body, refused",
    [
        ("T1 M6\nG41\nG1 X126.99\n", 6),  # the spindle tool's radius, 5 in
        ("T1 M6\nG41 D2\nG1 X38.09\n", 6),  # tool 2's, 1.5 in
        ("T1 M6\nG41\nG1 X127.001\nG40\nG1 X0\n", None),
        ("T1 M6\nG41 D2\nG1 X38.11\nG40\nG1 X0\n", None),
        ("G20\nT1 M6\nG41\nG1 X4.99\n", 7),
        ("G20\nT1 M6\nG41\nG1 X5.001\nG40\nG1 X0\n", None),
        ("T3 M6\nG41\nG1 X20\n", 5),  # a lathe tool (orientation Q3) outside G18
        ("T3 M6\nG18\nG41\nG1 X20 Z20\nG40\nG1 X0\n", None),
        ("T4 M6\nG41\nG1 X20\nG40\nG1 X0\n", None),  # (Q9: the tool centre, any plane)
    ],
)
def test_g41_checks_against_the_radius_of_the_tool_table_ncpp_is_told(tmp_path, body, refused):
    """With `--tool-table` the radius of G41/G42 is the table's D over 2, in the machine's units,
    as rs274 reads it (the stand-alone rs274's are inches: `--var-units inch`)."""
    from dataclasses import replace

    from ncpp.motion.offsets import WorkOffsets
    from ncpp.motion.tools import ToolTable

    table = tmp_path / "tool.tbl"
    table.write_text("T1 P1 D10 Z0\nT2 P2 D3 Z0\nT3 P3 D0.2 Z0 Q3\nT4 P4 D0.2 Z0 Q9\n")
    path = write_program(tmp_path, HEAD + body)
    proc = oracle.run(path, tool_table=table, timeout=60)
    theirs = rs274_error(proc.stderr)
    offsets = replace(WorkOffsets.at((0.0, 0.0, 0.0)), tools=ToolTable.from_file(table, unit_mm=25.4))
    try:
        events_of(HEAD + body, offsets=offsets, warnings=Warnings(stream=io.StringIO()))
        error = None
    except NcppError as err:
        error = err
    if refused is None:
        assert theirs is None and error is None, (theirs, error)
    else:
        assert (
            theirs is not None
            and error is not None
            and theirs[0] == error.message
            and error.where.line == refused
        ), (theirs, error)
