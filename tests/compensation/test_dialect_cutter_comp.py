"""Klartext (RL/RR ... R0) and Sinumerik (G41/G42 ... G40) moves under radius compensation,
compensated where the tool centre stands, judged in closed form: the test offsets the programmed
contour by the tool radius itself (a line moves square to its direction, an arc's radius grows or
shrinks by it) for the tool-centre path the drawing wants, and offsets the rewritten program's
contour the same way for the path the control makes of it; a machine whose errors are linear in
position (`AFFINE`, `closed_form`) must put the second on the first within 0.5 µm, where the
original program misses it by more than 10 µm.

The controls' rules used: at a move's end the tool centre stands square to the move, by the
radius, whatever the corner after it (outside corners: a transition arc about the corner, G450
and the TNC's; inside corners: the crossing of the offset paths; TNC 640 user's manual,
"Radius compensation: Machining corners"; 840D sl Programming Manual Fundamentals, "Corner
behavior: G450, G451"); the move that turns it on starts from the programmed point and the one
that turns it off ends on its programmed point (840D sl Fundamentals, "Tool radius compensation
OFF: G40").  The test contours approach the contour in line with its first edge, where the
controls' approaches (NORM: square to the contour's tangent) agree with the move's own normal.
(The rewritten program's transition arcs at outside corners, about a corrected corner point, are
not checked: they keep an error of the error's gradient times the radius.)"""

from __future__ import annotations

import contextlib
import io
import math
import re
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pytest

from ncpp.cli import main
from ncpp.errors import Warnings
from ncpp.motion.segments import Arc, Line
from ncpp.motion.tools import ToolTable
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests.compensation.test_cutter_comp_accuracy import AFFINE, closed_form
from tests.compensation.tool_centre import Move, deviation

# ---- the contours: lines, and arcs (centre, turn +1 counter-clockwise), from (-20, 0) -------------

# a rounded rectangle run counter-clockwise, the tool on the left (inside it): arcs the tool is inside
# of, an inside corner at (0, 80), the approach along the first edge, the exit away from the last
RECTANGLE = [
    ((0, 0), None, 0),
    ((80, 0), None, 0),
    ((100, 20), (80, 20), 1),
    ((100, 60), None, 0),
    ((80, 80), (80, 60), 1),
    ((0, 80), None, 0),
    ((0, 0), None, 0),
    ((-20, -20), None, 0),
]
KLARTEXT = """0 BEGIN PGM RECT MM
1 BLK FORM 0.1 Z X-30 Y-30 Z-10
2 BLK FORM 0.2 X+120 Y+100 Z+0
3 {tool}
4 L X-20 Y+0 Z+5 R0 FMAX
5 L Z-1 F300
6 L X+0 Y+0 RL F300
7 L X+80
8 CC X+80 Y+20
9 C X+100 Y+20 DR+
10 L Y+60
11 CR X+80 Y+80 R+20 DR+
12 L X+0
13 L Y+0
14 L X-20 Y-20 R0
15 L Z+5 FMAX
16 END PGM RECT MM
"""
# TOOL.T as the TNC writes it: the radius R + DR (4.9 + 0.05), the call adds its own DR (0.05)
TOOL_T = """BEGIN TOOL    .T       MM
T    NAME             L          R          DL      DR      TL RT
3    D10_ENDMILL      +0,000     +4,900     +0,000  +0,050
[END]
"""

# a pocket with a Klartext fillet (RND R10) and chamfer (CHF 10) in two of its inside corners, the
# contour the control rounds and cuts, then offsets
CORNERS = [
    ((0, 0), None, 0),
    ((70, 0), None, 0),
    ((80, 10), (70, 10), 1),
    ((80, 50), None, 0),
    ((70, 60), None, 0),
    ((0, 60), None, 0),
    ((0, 0), None, 0),
    ((-20, -20), None, 0),
]
KLARTEXT_CORNERS = """0 BEGIN PGM CORN MM
1 TOOL DEF 3 L+0 R+5
2 TOOL CALL 3 Z S3000
3 L X-20 Y+0 Z+5 R0 FMAX
4 L Z-1 F300
5 L X+0 Y+0 RL F300
6 L X+80
7 RND R10
8 L Y+60
9 CHF 10
10 L X+0
11 L Y+0
12 L X-20 Y-20 R0
13 L Z+5 FMAX
14 END PGM CORN MM
"""

# a part outline run counter-clockwise, the tool on the right (outside it): arcs the tool is outside
# of, two outside corners (45° turns) and a line-to-line corner at (0, 0) before the exit
OUTLINE = [
    ((0, 0), None, 0),
    ((80, 0), None, 0),
    ((100, 20), (80, 20), 1),
    ((100, 60), None, 0),
    ((80, 80), (80, 60), 1),
    ((30, 80), None, 0),
    ((0, 50), None, 0),
    ((0, 0), None, 0),
    ((-20, -20), None, 0),
]
SINUMERIK = """%_N_OUTLINE_MPF
N10 G17 G90 G71 G94
N20 T1 M6
N30 G0 X-20 Y0 Z5
N40 G1 Z-1 F300
N50 G42 G1 X0 Y0
N60 X80
N70 G3 X100 Y20 I0 J20
N80 G1 Y60
N90 G3 X80 Y80 CR=20
N100 G1 X30
N110 X0 Y50
N120 Y0
N130 G40 X-20 Y-20
N140 G0 Z5
N150 M30
"""
# the control's tool offsets: the radius $TC_DP6 plus the wear radius $TC_DP15
TO_INI = '$TC_TP2[1]="D8"\n$TC_DP1[1,1]=120\n$TC_DP3[1,1]=0.0\n$TC_DP6[1,1]=3.9\n$TC_DP15[1,1]=0.1\n'


def offset(contour: list, side: float, start=(-20.0, 0.0), transitions: bool = False) -> list[Move]:
    """The tool centre's path for a contour (entry move first, exit move last) under compensation:
    `side` the radius, positive to the left of the direction of travel.  Each move under it offset
    (a line square to its direction, an arc's radius by the side, towards the centre on the left
    of a counter-clockwise arc), two lines that cross (an inside corner) cut where they cross, and
    with `transitions` an arc of the radius about the corner between two offset moves that do not
    meet (an outside corner); the entry starts at its programmed start, the exit ends on its
    programmed end."""
    moves: list[Move] = []
    at = np.array(start, dtype=float)
    corners = []  # the programmed point between each move and the next
    for k, (end, centre, turn) in enumerate(contour):
        end = np.array(end, dtype=float)
        if centre is None:
            d = (end - at) / np.linalg.norm(end - at)
            normal = side * np.array([-d[1], d[0]])
            if k == 0:  # the entry move: from its programmed start
                moves.append(_move(at, end + normal))
            elif k == len(contour) - 1:  # the exit move: to its programmed end, from where the tool stands
                moves.append(_move(moves[-1].end[:2], end))
            else:
                moves.append(_move(at + normal, end + normal))
        else:
            c = np.array(centre, dtype=float)
            grow = -side if turn > 0 else side  # (left of a counter-clockwise arc: towards its centre)
            a = c + (at - c) * (1 + grow / np.linalg.norm(at - c))
            b = c + (end - c) * (1 + grow / np.linalg.norm(end - c))
            moves.append(Move(np.append(a, 0.0), np.append(b, 0.0), c, turn))
        corners.append(end)
        at = end
    return _joined(moves, corners, transitions)


def _joined(moves: list[Move], corners: list, transitions: bool) -> list[Move]:
    """The offset moves joined at their corners as the controls join them: two lines that cross (an
    inside corner) end and start where they cross; with `transitions`, two moves that do not meet
    (an outside corner) get an arc about the programmed corner between them."""
    out: list[Move] = []
    for k, move in enumerate(moves):  # (`moves[k + 1]` cut where it crosses is met so)
        out.append(move)
        if not 1 <= k < len(moves) - 2:  # (the corners after the entry move, before the exit move)
            continue
        second = moves[k + 1]
        if (
            move.centre is None
            and second.centre is None
            and (crossing := _crossing(move, second)) is not None
        ):
            out[-1], moves[k + 1] = _move(move.start[:2], crossing), _move(crossing, second.end[:2])
        elif transitions and np.linalg.norm(move.end - second.start) > 1e-9:
            d1, d2 = move.end[:2] - corners[k], second.start[:2] - corners[k]
            turn = 1 if d1[0] * d2[1] - d1[1] * d2[0] > 0 else -1
            out.append(Move(move.end, second.start, corners[k], turn))
    return out


def _crossing(first: Move, second: Move):
    """Where two offset lines cross, within both (None: they do not)."""
    d1, d2 = first.end[:2] - first.start[:2], second.end[:2] - second.start[:2]
    across = d1[0] * d2[1] - d1[1] * d2[0]
    if abs(across) < 1e-9 * np.linalg.norm(d1) * np.linalg.norm(d2):
        return None
    gap = second.start[:2] - first.start[:2]
    t, u = (gap[0] * d2[1] - gap[1] * d2[0]) / across, (gap[0] * d1[1] - gap[1] * d1[0]) / across
    return first.start[:2] + t * d1 if 0.0 <= t <= 1.0 and 0.0 <= u <= 1.0 else None


def _move(a, b) -> Move:
    return Move(np.append(a, 0.0), np.append(b, 0.0))


# ---- the rewritten programs' contours --------------------------------------------------------------

_WORD = re.compile(r"\b(CR=|CC|[A-Z])\s*([-+]?\d*\.?\d+)")


def klartext_contour(text: str) -> tuple[list, tuple[float, float]]:
    """The moves in the plane of a Klartext program's section from its RL/RR block to its R0 block,
    as `RECTANGLE` has them, and the point the section starts from."""
    contour, at, pole, start, on = [], (0.0, 0.0), (0.0, 0.0), None, False
    for line in text.splitlines():
        words = line.split()[1:]
        assert not (on and words and words[0] in ("RND", "CHF")), line  # (a corner the writer kept)
        if not words or words[0] not in ("L", "C", "CC", "CR"):
            continue
        values = {m.group(1): float(m.group(2)) for m in _WORD.finditer(" ".join(words[1:]))}
        end = (values.get("X", at[0]), values.get("Y", at[1]))
        if words[0] == "CC":
            pole = end
            continue
        on = on or "RL" in words or "RR" in words
        if on and end != at:
            if start is None:
                start = at
            if words[0] == "L":
                contour.append((end, None, 0))
            else:
                assert words[0] == "C", line  # (an arc the writer left in another form: not rewritten)
                contour.append((end, pole, 1 if "DR+" in words else -1))
        at = end
        if on and "R0" in words:
            break
    assert start is not None
    return contour, start


def sinumerik_contour(text: str) -> tuple[list, tuple[float, float]]:
    """As `klartext_contour`, for a Sinumerik program's section from G41/G42 to G40 (G90, I J
    incremental, CR= less than half a circle)."""
    contour, at, start, on, motion = [], (0.0, 0.0), None, False, 0
    for line in text.splitlines():
        values = {m.group(1): float(m.group(2)) for m in _WORD.finditer(line.split(";")[0])}
        codes = [int(g) for g in re.findall(r"\bG(\d+)", line)]
        motion = next((g for g in reversed(codes) if g in (0, 1, 2, 3)), motion)
        on = on or 41 in codes or 42 in codes
        end = (values.get("X", at[0]), values.get("Y", at[1]))
        if on and end != at:
            if start is None:
                start = at
            if motion in (0, 1):
                contour.append((end, None, 0))
            elif "CR=" in values:
                contour.append((end, _centre(at, end, values["CR="], motion == 2), 1 if motion == 3 else -1))
            else:
                contour.append((end, (at[0] + values["I"], at[1] + values["J"]), 1 if motion == 3 else -1))
        at = end
        if on and 40 in codes:
            break
    assert start is not None
    return contour, start


def _centre(a, b, radius: float, clockwise: bool) -> tuple[float, float]:
    """The centre of the arc of `radius` (less than half a circle) from a to b."""
    (x0, y0), (x1, y1) = a, b
    half = math.hypot(x1 - x0, y1 - y0) / 2
    away = math.sqrt(radius * radius - half * half)
    angle = math.atan2(y1 - y0, x1 - x0) + (-math.pi / 2 if clockwise else math.pi / 2)
    return (x0 + x1) / 2 + away * math.cos(angle), (y0 + y1) / 2 + away * math.sin(angle)


# where the program zero sits on the machine (mm): far enough from the machine's zero for errors of
# tens of µm
ZERO = np.array([200.0, 150.0, 0.0])


def machine(command: np.ndarray) -> np.ndarray:
    """Where AFFINE's machine puts the tool for commands (n,3) in program coordinates, in them."""
    return closed_form(command + ZERO) - ZERO


def compensated(tmp_path: Path, name: str, text: str, *options: str) -> tuple[str, str]:
    """The program ncpp writes for AFFINE's machine, placed at `ZERO`, and its messages."""
    (tmp_path / "affine.toml").write_text(AFFINE)
    program, out = tmp_path / name, tmp_path / f"out_{name}"
    program.write_text(text)
    with _captured_stderr() as messages:
        code = main(["compensate", "--machine", str(tmp_path / "affine.toml"), "--tolerance", "0.0001",
                     "--work-offset", ",".join(map(str, ZERO)), *options, str(program), "-o", str(out)])  # fmt: skip
    assert code == 0, messages.getvalue()
    return out.read_text(), messages.getvalue()


@contextlib.contextmanager
def _captured_stderr() -> Iterator[io.StringIO]:
    text = io.StringIO()
    with contextlib.redirect_stderr(text):
        yield text


CASES = {
    "klartext-rl-tool-t": (KLARTEXT.format(tool="TOOL CALL 3 Z S3000 DR+0.05"), "rect.h", RECTANGLE, 5.0,
                           "TOOL.T", TOOL_T, klartext_contour),
    "klartext-rl-tool-def": (KLARTEXT.format(tool="TOOL DEF 3 L+0 R+5\n3 TOOL CALL 3 Z S3000"), "rect.h",
                             RECTANGLE, 5.0, None, None, klartext_contour),
    "klartext-rnd-chf": (KLARTEXT_CORNERS, "corn.h", CORNERS, 5.0, None, None, klartext_contour),
    "sinumerik-g42": (SINUMERIK, "OUTLINE.MPF", OUTLINE, -4.0, "_N_TO_INI", TO_INI, sinumerik_contour),
}  # fmt: skip


@pytest.mark.parametrize("case", CASES.values(), ids=CASES.keys())
def test_the_tool_centre_lands_on_the_offset_contour_within_half_a_micron(tmp_path, case):
    """The tool centre of the rewritten program, run on the machine, within 0.5 µm of the tool-centre
    path of the programmed contour all along; the original's misses it by more than 10 µm."""
    text, name, contour, side, table, table_text, read = case
    options = ()
    if table is not None:
        (tmp_path / table).write_text(table_text, encoding="latin-1")
        options = ("--tool-table", str(tmp_path / table))
    wanted = offset(contour, side, transitions=True)
    assert deviation(wanted, wanted, machine).max() > 0.010
    written, messages = compensated(tmp_path, name, text, *options)
    moves, start = read(written)
    assert len(moves) >= len(contour)  # (arcs may come in pieces)
    made = offset(moves, side, start)
    assert deviation(wanted, made, machine).max() <= 0.0005
    assert "left as programmed: nothing" in messages, messages
    assert np.allclose(made[-1].end[:2], [-20, -20], atol=0.1)  # (the exit move: the section is whole)


def test_the_compensation_words_stay_on_their_blocks(tmp_path):
    """RL/R0 and G42/G40 stay where the program has them, on the rewritten blocks."""
    klartext, _ = compensated(tmp_path, "rect.h", CASES["klartext-rl-tool-def"][0])
    assert re.search(r"^\d+ L X[-+]0\.0\d* Y[-+]0\.0\d* RL F300$", klartext, re.M), klartext
    assert re.search(r"^\d+ L X-(20\.0|19\.9)\d* Y-(20\.0|19\.9)\d* R0$", klartext, re.M), klartext
    assert "L X+80 " not in klartext and "X+80.0000 Y+0.0000" not in klartext  # (rewritten)
    (tmp_path / "_N_TO_INI").write_text(TO_INI)
    sinumerik, _ = compensated(
        tmp_path, "OUTLINE.MPF", SINUMERIK, "--tool-table", str(tmp_path / "_N_TO_INI")
    )
    assert re.search(r"^N50 G42 G1 X", sinumerik, re.M) and re.search(r"^N130 G40 X-", sinumerik, re.M)


UNKNOWN = {
    "klartext": (KLARTEXT.format(tool="TOOL CALL 3 Z S3000"), "rect.h", 7, RECTANGLE),
    "sinumerik": (SINUMERIK, "OUTLINE.MPF", 6, OUTLINE),
}


@pytest.mark.parametrize("case", UNKNOWN.values(), ids=UNKNOWN.keys())
def test_without_the_radius_the_points_are_corrected_where_they_are_and_the_warning_says_so(tmp_path, case):
    """No tool table and no TOOL DEF R: as ISO's G41 without one, each programmed point gets the
    command that lands it, in closed form C = (I + A)⁻¹ P for AFFINE's linear error A, and the
    warning at the entry says the radius is unknown."""
    text, name, entry, contour = case
    written, messages = compensated(tmp_path, name, text)
    assert f"{name}:{entry}:1: warning: cutter compensation with the tool radius not known" in messages
    inverse = np.linalg.inv(np.array([[1 + 1e-4, -1e-4], [0.0, 1 - 0.8e-4]]))
    programmed = lambda point: inverse @ (point + ZERO[:2]) - ZERO[:2]  # noqa: E731  (program coordinates)
    read = klartext_contour if name.endswith(".h") else sinumerik_contour
    moves, _ = read(written)
    ends = [end for end, *_ in moves]
    corners = [end for end, centre, _ in contour if centre is None]
    for point in corners[:-1]:  # (the exit's end too is corrected where it is)
        assert any(np.allclose(end, programmed(point), atol=0.6e-4) for end in ends), (point, ends)


@pytest.mark.parametrize(
    "change, why",
    [
        ("6 L X+0 Y+0 RL F300", "6 L IX+20 Y+0 RL F300"),
        ("6 L X+0 Y+0 RL F300\n7 L X+80", "6 L X+0 Y+0 F300\n7 CR X+80 Y+0 R+200 DR+ RL"),
    ],
    ids=["incremental-entry", "arc-entry"],
)
def test_klartext_moves_ncpp_does_not_follow_are_left_as_programmed(tmp_path, change, why):
    """An incremental word under RL, or RL turned on in an arc block (the TNC turns it on in a line
    block: TNC 640 user's manual, "Radius compensation"), leave the moves as programmed with the
    warning; compensation follows again from a line that starts at a corrected point."""
    text = KLARTEXT.format(tool="TOOL DEF 3 L+0 R+5\n3 TOOL CALL 3 Z S3000").replace(change, why)
    written, messages = compensated(tmp_path, "rect.h", text)
    assert "cutter compensation: its moves pass through uncompensated" in messages
    lines = written.splitlines()
    kept = next(line for line in why.splitlines() if "RL" in line).split(" ", 1)[1]
    assert any(line.endswith(kept) for line in lines), written
    assert not any(line.endswith(" L Y+60") for line in lines), written  # (followed again)


def test_sinumerik_incremental_moves_under_g42_are_left_as_programmed(tmp_path):
    """G91 under G42 (incremental: out of ncpp's scope under compensation, as in ISO) leaves the move
    as programmed with the warning, the arc from where it ends too; the line after is followed."""
    text = SINUMERIK.replace("N60 X80\nN70 G3", "N60 G91 X80\nN70 G90 G3")
    (tmp_path / "_N_TO_INI").write_text(TO_INI)
    written, messages = compensated(
        tmp_path, "OUTLINE.MPF", text, "--tool-table", str(tmp_path / "_N_TO_INI")
    )
    assert "OUTLINE.MPF:7:1: warning: cutter compensation: its moves pass through uncompensated" in messages
    lines = written.splitlines()
    assert "N60 G91 X80" in lines and "N70 G90 G3 X100 Y20 I0 J20" in lines
    assert "N80 G1 Y60" not in lines and any(line.startswith("N80 G1 Y60.0") for line in lines), written


@pytest.mark.parametrize(
    "name, text, change, new, why",
    [
        ("rect.h", KLARTEXT.format(tool="TOOL CALL 3 Z"), "10 L Y+60", "10 TOOL CALL 4 Z",
         "rect.h:11:4: warning: TOOL CALL with radius compensation RL/RR is outside"),
        ("OUTLINE.MPF", SINUMERIK, "N80 G1 Y60", "N80 D2",
         "OUTLINE.MPF:9:5: warning: a tool or cutting edge change under radius compensation G41/G42 is outside"),
    ],
    ids=["klartext-tool-call", "sinumerik-edge"],
)  # fmt: skip
def test_a_tool_change_under_compensation_leaves_the_scope(tmp_path, name, text, change, new, why):
    """The radius compensation offsets by is the one it was turned on with; a new tool under it is
    the control's to follow: the rest passes through with the warning."""
    _, messages = compensated(tmp_path, name, text.replace(change, new))
    assert why in messages, messages


LOOPS = {
    "klartext": (KLARTEXT.format(tool="TOOL DEF 3 L+0 R+5\n3 TOOL CALL 3 Z").replace(
        "12 L X+0\n", "12 LBL 1\n12 L X+0\n12 LBL 0\n12 CALL LBL 1 REP 1\n"), "rect.h"),
    "sinumerik": (SINUMERIK.replace("N100 G1 X30\n", "N100 FOR R1=1 TO 2\nN101 G1 X30\nN102 ENDFOR\n"),
                  "OUTLINE.MPF"),
}  # fmt: skip


@pytest.mark.parametrize("case", LOOPS.values(), ids=LOOPS.keys())
def test_a_move_that_runs_again_under_compensation_is_left_as_programmed(case):
    """A move in a loop or a repeated section under RL/G42 is one text run several times: it is left
    as programmed, never also given where the tool centre stands (the arc after it would then start
    from a corrected point it never reached)."""
    text, name = case
    dialect, blocks = parse_program(io.BytesIO(text.encode()), name, None)
    interpret, _ = dialect_tools(dialect)
    events = list(interpret(blocks, file=name, warnings=Warnings(stream=io.StringIO())))
    moves = [e for e in events if type(e) is Line or type(e) is Arc]
    assert any(m.fixed for m in moves) and any(m.centre_shift is not None for m in moves)
    assert not [m for m in moves if m.fixed and m.centre_shift is not None]


def test_the_tool_tables_give_the_radius_compensation_offsets_by(tmp_path):
    """TOOL.T: R + DR in its units (a table without an R column gives none); _N_TO_INI: $TC_DP6 +
    $TC_DP15 per tool and edge, in the machine's units."""
    (tmp_path / "TOOL.T").write_text(TOOL_T.replace("MM\n", "INCH\n", 1), encoding="latin-1")
    assert ToolTable.from_file(tmp_path / "TOOL.T").radii == {(3, 1): pytest.approx(4.95 * 25.4)}
    (tmp_path / "TOOL.T").write_text(
        "BEGIN TOOL    .T       MM\nT    L\n3    +10\n[END]\n", encoding="latin-1"
    )
    assert ToolTable.from_file(tmp_path / "TOOL.T").radii == {}
    (tmp_path / "_N_TO_INI").write_text(TO_INI + "$TC_DP6[1,2]=2\n$TC_DP15[2,1]=-0.05\n")
    assert ToolTable.from_file(tmp_path / "_N_TO_INI").radii == {
        (1, 1): pytest.approx(4.0), (1, 2): 2.0, (2, 1): -0.05,
    }  # fmt: skip
