"""Klartext (RL/RR ... R0) and Sinumerik (G41/G42 ... G40) moves under radius compensation,
compensated where the tool centre stands, judged in closed form: the test offsets the programmed
contour by the tool radius itself (a line moves square to its direction, an arc's radius grows or
shrinks by it) for the tool-centre path the drawing wants, and offsets the rewritten program's
contour the same way for the path the control makes of it; a machine whose errors are linear in
position (`AFFINE`, `closed_form`; `affine_in`, `closed_form_in` for the other working planes and
a depth error that changes along the plane) must put the second on the first within 0.5 µm, where
the original program misses it by more than 10 µm.  Each contour is also written in the Z X and
Y Z planes (`in_plane`: Klartext's tool axis Y and X, Sinumerik's G18 and G19, left and right as
seen from the positive tool axis) and in incremental words (Klartext IX IY, Sinumerik G91, IC()),
which the readers (`klartext_contour`, `sinumerik_contour`) take from the end before them.

The controls' rules used: at a move's end the tool centre stands square to the move, by the
radius, whatever the corner after it (outside corners: a transition arc about the corner, G450
and the TNC's; inside corners: the crossing of the offset paths; TNC 640 user's manual,
"Radius compensation: Machining corners"; 840D sl Programming Manual Fundamentals, "Corner
behavior: G450, G451"); the move that turns it on starts from the programmed point and the one
that turns it off ends on its programmed point (840D sl Fundamentals, "Tool radius compensation
OFF: G40").  The entry move ends square to itself (the TNC's), or with Sinumerik's NORM (and KONT
in front of the contour) square to the next element at its start (`offset`'s `norm`: 840D sl
Fundamentals, "Contour approach and retraction (NORM, KONT, KONTC, KONTT)").
(The rewritten program's transition arcs at outside corners, about a corrected corner point, are
not checked: they keep an error of the error's gradient times the radius.)"""

from __future__ import annotations

import contextlib
import functools
import io
import math
import re
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import NamedTuple

import numpy as np
import pytest

from ncpp.cli import main
from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import PLANE_AXES, Arc, Line
from ncpp.motion.tools import ToolTable
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests.compensation.test_cutter_comp_accuracy import AFFINE, closed_form
from tests.compensation.tool_centre import Move, deviation
from tests.conftest import SHARED
from tests.writeback.conftest import linear_errors, machine_file

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


def offset(
    contour: list,
    side: float,
    start=(-20.0, 0.0),
    transitions: bool = False,
    depth: float = 0.0,
    norm: bool = False,
) -> list[Move]:
    """The tool centre's path for a contour (entry move first, exit move last) under compensation:
    `side` the radius, positive to the left of the direction of travel.  Each move under it offset
    (a line square to its direction, an arc's radius by the side, towards the centre on the left
    of a counter-clockwise arc), two lines that cross (an inside corner) cut where they cross, and
    with `transitions` an arc of the radius about the corner between two offset moves that do not
    meet (an outside corner); the entry starts at its programmed start, the exit ends on its
    programmed end; with `norm` (Sinumerik's NORM) the entry ends square to the next move at its
    start instead of to its own direction.  Points in the plane's (u, v) axes, with the coordinate
    along its normal third (`depth` where a point has none)."""
    moves: list[Move] = []
    at3 = _point(start, depth)
    corners = []  # the programmed point between each move and the next
    for k, (end, centre, turn) in enumerate(contour):
        end3 = _point(end, depth)
        at, end = at3[:2], end3[:2]
        if centre is None:
            d = (end - at) / np.linalg.norm(end - at)
            normal = side * np.array([-d[1], d[0]])
            if k == 0:  # the entry move: from its programmed start
                normal = _normal_at_start(end, contour[1], side) if norm else normal
                moves.append(_move(at, end + normal, at3[2], end3[2]))
            elif k == len(contour) - 1:  # the exit move: to its programmed end, from where the tool stands
                moves.append(_move(moves[-1].end, end, moves[-1].end[2], end3[2]))
            else:
                moves.append(_move(at + normal, end + normal, at3[2], end3[2]))
        else:
            c = np.array(centre, dtype=float)
            grow = -side if turn > 0 else side  # (left of a counter-clockwise arc: towards its centre)
            a = c + (at - c) * (1 + grow / np.linalg.norm(at - c))
            b = c + (end - c) * (1 + grow / np.linalg.norm(end - c))
            moves.append(Move(np.append(a, at3[2]), np.append(b, end3[2]), c, turn))
        corners.append(end)
        at3 = end3
    return _joined(moves, corners, transitions)


def _normal_at_start(at: np.ndarray, move: tuple, side: float) -> np.ndarray:
    """The tool centre minus the programmed point at the start `at` of a contour's `move` (a line:
    square to it; an arc: along its radius, towards its centre on the left of a counter-clockwise one)."""
    end, centre, turn = move
    if centre is None:
        d = (np.array(end[:2], dtype=float) - at) / np.linalg.norm(np.array(end[:2], dtype=float) - at)
        return side * np.array([-d[1], d[0]])
    inward = (np.array(centre, dtype=float) - at) / np.linalg.norm(np.array(centre, dtype=float) - at)
    return side * inward if turn > 0 else -side * inward


def _point(p, depth: float) -> np.ndarray:
    """A point of the plane as (u, v, w), at `depth` along the normal where it has no third coordinate."""
    return np.array(p if len(p) == 3 else (*p, depth), dtype=float)


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
            out[-1] = _move(move.start, crossing, move.start[2], move.end[2])
            moves[k + 1] = _move(crossing, second.end, second.start[2], second.end[2])
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


def _move(a, b, wa: float = 0.0, wb: float = 0.0) -> Move:
    return Move(np.append(a[:2], wa), np.append(b[:2], wb))


# ---- the rewritten programs' contours --------------------------------------------------------------

# a Klartext word: an axis (absolute), I and an axis (incremental) or IPA, and its number
_KLARTEXT_WORD = re.compile(r"(?<![A-Z])(IPA|I?[XYZ])([-+]?\d*\.?\d+)")
AXES = "XYZ"


def klartext_contour(text: str, plane: int = 17) -> tuple[list, tuple]:
    """The moves in the plane of a Klartext program's section from its RL/RR block to its R0 block,
    as `RECTANGLE` has them (in the plane's (u, v) axes, with the normal's coordinate third:
    `PLANE_AXES`), and the point the section starts from; X Y Z absolute, IX IY IZ incremental,
    `C` about the `CC` pole and `CP IPA` (a helix's turn about it, DR+ counter-clockwise in (u, v))."""
    axes = PLANE_AXES[plane]
    contour, at, pole, start, on = [], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], None, False
    for line in text.splitlines():
        words = line.split()[1:]
        assert not (on and words and words[0] in ("RND", "CHF")), line  # (a corner the writer kept)
        if not words or words[0] not in ("L", "C", "CC", "CR", "CP"):
            continue
        values = {m.group(1): float(m.group(2)) for m in _KLARTEXT_WORD.finditer(" ".join(words[1:]))}
        end = [values.get(axis, at[k] + values.get("I" + axis, 0.0)) for k, axis in enumerate(AXES)]
        if words[0] == "CC":
            pole = end
            continue
        if words[0] == "CP":  # (the pole's plane is the working plane: `IPA` turns about it)
            a, b, n = axes
            turn = math.radians(values["IPA"])
            du, dv = at[a] - pole[a], at[b] - pole[b]
            end[a] = pole[a] + du * math.cos(turn) - dv * math.sin(turn)
            end[b] = pole[b] + du * math.sin(turn) + dv * math.cos(turn)
        on = on or "RL" in words or "RR" in words
        if on and end != at:
            if start is None:
                start = tuple(at[k] for k in axes)
            point = tuple(end[k] for k in axes)
            if words[0] == "L":
                contour.append((point, None, 0))
            else:
                assert words[0] in ("C", "CP"), line  # (an arc in another form: not rewritten)
                contour.append((point, (pole[axes[0]], pole[axes[1]]), 1 if "DR+" in words else -1))
        at = end
        if on and "R0" in words:
            break
    assert start is not None
    return contour, start


# a Sinumerik word: an axis or an arc's I J K or CR=, its mode (`=AC(`, `=IC(`) and its number
_SINUMERIK_WORD = re.compile(r"(?<![A-Z0-9_=])(CR|[XYZIJK])(?:=(AC|IC)\(|=)?([-+]?\d*\.?\d+)")


def sinumerik_contour(text: str, plane: int = 17) -> tuple[list, tuple]:
    """As `klartext_contour`, for a Sinumerik program's section from G41/G42 to G40: G90 and G91,
    `AC()` and `IC()` per word, I J K incremental (`=AC(` absolute), CR= less than half a circle."""
    axes = PLANE_AXES[plane]
    contour, at, start, on, motion, absolute = [], [0.0, 0.0, 0.0], None, False, 0, True
    for line in text.splitlines():
        code = line.split(";")[0]
        words = {m.group(1): (m.group(2), float(m.group(3))) for m in _SINUMERIK_WORD.finditer(code)}
        codes = [int(g) for g in re.findall(r"\bG(\d+)", code)]
        motion = next((g for g in reversed(codes) if g in (0, 1, 2, 3)), motion)
        absolute = next((g == 90 for g in reversed(codes) if g in (90, 91)), absolute)
        on = on or 41 in codes or 42 in codes
        end = list(at)
        for k, axis in enumerate(AXES):
            if axis in words:
                mode, value = words[axis]
                end[k] = value if mode == "AC" or (mode is None and absolute) else at[k] + value
        if on and end != at:
            if start is None:
                start = tuple(at[k] for k in axes)
            a, b, _ = axes
            point, turn = tuple(end[k] for k in axes), 1 if motion == 3 else -1
            if motion in (0, 1):
                contour.append((point, None, 0))
            elif "CR" in words:
                centre = _centre((at[a], at[b]), (end[a], end[b]), words["CR"][1], motion == 2)
                contour.append((point, centre, turn))
            else:
                centre = tuple(
                    words["IJK"[k]][1] if words.get("IJK"[k], ("", 0.0))[0] == "AC"
                    else at[k] + words.get("IJK"[k], ("", 0.0))[1] for k in (a, b)
                )  # fmt: skip
                contour.append((point, centre, turn))
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


WIDE = SHARED / "machines" / "wide.toml"  # (a machine file whose travel fits the corpus programs)
# where the program zero sits on the machine (mm): far enough from the machine's zero for errors of
# tens of µm
ZERO = np.array([200.0, 150.0, 0.0])


def affine_in(plane: int) -> str:
    """AFFINE's errors in `plane`'s (u, v) axes (`PLANE_AXES`: G18 Z X, G19 Y Z): u runs 100 µm/m long
    and v 80 µm/m short, v moves u by -100 µm/m of v; and the normal axis runs 50 µm/m long, u moves it
    by 120 µm/m of u and v by -100 µm/m of v, so the depth is corrected too, differently along the
    contour (at an inside corner where the tool centre stands at the crossing of the offset lines)."""
    u, v, n = (AXES[k] for k in PLANE_AXES[plane])
    errors = {f"E{u}{u}": 0.1, f"E{v}{v}": -0.08, f"E{u}{v}": -0.1, f"E{n}{n}": 0.05, f"E{n}{u}": 0.12,
              f"E{n}{v}": -0.1}  # fmt: skip
    return machine_file("affine", linear_errors(**errors), 500.0)


def closed_form_in(plane: int) -> Callable[[np.ndarray], np.ndarray]:
    """Where `affine_in(plane)`'s machine puts the tool for commands (n,3), machine mm."""
    axes = list(PLANE_AXES[plane])

    def reached(command: np.ndarray) -> np.ndarray:
        u, v, w = command[:, axes].T
        out = command.copy()
        out[:, axes] = np.stack(
            [u + 1e-4 * u - 1e-4 * v, v - 0.8e-4 * v, w + 0.5e-4 * w + 1.2e-4 * u - 1e-4 * v], axis=1
        )
        return out

    return reached


def machine(command: np.ndarray, plane: int = 17, reached=closed_form) -> np.ndarray:
    """Where a machine (`reached`: machine mm) puts the tool for commands (n,3) in program coordinates
    in the plane's (u, v) axes and its normal (`PLANE_AXES`), in them."""
    axes = list(PLANE_AXES[plane])
    xyz = np.empty_like(command)
    xyz[:, axes] = command
    return (reached(xyz + ZERO) - ZERO)[:, axes]


def in_plane(text: str, plane: int, letters: str = "XYZ") -> str:
    """A G17 program's text for `plane`: its axis words' (and I J K's, `letters` IJK) letters each
    the plane's axis in its place (G18: X Y Z -> Z X Y, G19: X Y Z -> Y Z X)."""
    order = [letters[k] for k in PLANE_AXES[plane]]
    to = dict(zip(letters, order))
    return re.sub(rf"(?<![A-HJ-Z0-9_])([{letters}])(?![A-Z])", lambda m: to[m.group(1)], text)  # (IX: X)


def compensated(
    tmp_path: Path, name: str, text: str, *options: str, machine_text: str = AFFINE
) -> tuple[str, str]:
    """The program ncpp writes for AFFINE's machine (or `machine_text`'s), placed at `ZERO`, and its
    messages."""
    (tmp_path / "affine.toml").write_text(machine_text)
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


# the rectangle in IX IY (the entry from the approach's end, the exit's two words)
KLARTEXT_INCREMENTAL = (
    KLARTEXT.format(tool="TOOL DEF 3 L+0 R+5\n3 TOOL CALL 3 Z S3000")
    .replace("6 L X+0 Y+0 RL", "6 L IX+20 Y+0 RL")
    .replace("7 L X+80", "7 L IX+80")
    .replace("10 L Y+60", "10 L IY+40")
    .replace("11 CR X+80 Y+80", "11 CR IX-20 IY+20")
    .replace("12 L X+0", "12 L IX-80")
    .replace("14 L X-20 Y-20 R0", "14 L IX-20 IY-20 R0")
)
# the outline in G91 from its entry's end, and in G90 with IC() words
SINUMERIK_G91 = SINUMERIK.replace(
    "N60 X80\nN70 G3 X100 Y20 I0 J20\nN80 G1 Y60\nN90 G3 X80 Y80 CR=20\nN100 G1 X30\nN110 X0 Y50\n"
    "N120 Y0\nN130 G40 X-20 Y-20\n",
    "N60 G91 X80\nN70 G3 X20 Y20 I0 J20\nN80 G1 Y40\nN90 G3 X-20 Y20 CR=20\nN100 G1 X-50\n"
    "N110 X-30 Y-30\nN120 Y-50\nN130 G40 X-20 Y-20\nN135 G90\n",
)
SINUMERIK_IC = (
    SINUMERIK.replace("N60 X80\n", "N60 X=IC(80)\n")
    .replace("N80 G1 Y60", "N80 G1 Y=IC(40)")
    .replace("N110 X0 Y50", "N110 X=IC(-30) Y=IC(-30)")
)
KLARTEXT_TOOL_DEF = KLARTEXT.format(tool="TOOL DEF 3 L+0 R+5\n3 TOOL CALL 3 Z S3000")
# in the ZX plane (tool axis Y, G18) and the YZ plane (tool axis X, G19): left and right as seen from the
# positive tool axis (the plane's first axis to the right, its second up)
SINUMERIK_ZX = in_plane(in_plane(SINUMERIK, 18).replace("G17", "G18"), 18, "IJK")
SINUMERIK_YZ = in_plane(in_plane(SINUMERIK_G91, 19).replace("G17", "G19"), 19, "IJK")
KLARTEXT_ZX = in_plane(KLARTEXT_TOOL_DEF, 18)
KLARTEXT_YZ = in_plane(KLARTEXT_INCREMENTAL, 19)


# Sinumerik's approach (NORM, the control's initial setting: the entry ends square to the next
# element at its start, not to itself): the outline entered from inside the part, behind its first
# edge, and from below onto its first arc; with KONT so from below (in front of the contour), and
# from inside (behind it: the entry ends square to itself and the control goes round the corner)
SINUMERIK_BEHIND = SINUMERIK.replace("N30 G0 X-20 Y0 Z5", "N30 G0 X0 Y20 Z5")
OUTLINE_FROM_ARC = [*OUTLINE[1:-1], ((60, 0), None, 0), ((60, -20), None, 0)]
SINUMERIK_ARC_FIRST = (
    SINUMERIK.replace("N30 G0 X-20 Y0 Z5", "N30 G0 X80 Y-20 Z5")
    .replace("N50 G42 G1 X0 Y0\nN60 X80\n", "N50 G42 G1 X80 Y0\n")
    .replace("N130 G40 X-20 Y-20", "N125 X60\nN130 G40 X60 Y-20")
)


class Case(NamedTuple):
    text: str
    name: str
    contour: list
    side: float  # the radius, positive on the left
    table: str | None = None  # the tool table's file name and text
    table_text: str | None = None
    read: Callable = klartext_contour
    plane: int = 17
    machine_text: str = AFFINE
    start: tuple = (-20.0, 0.0)  # where the entry starts
    norm: bool = False  # the entry ends square to the next move (Sinumerik's NORM, and KONT in front)


CASES = {
    "klartext-rl-tool-t": Case(KLARTEXT.format(tool="TOOL CALL 3 Z S3000 DR+0.05"), "rect.h", RECTANGLE, 5.0,
                               "TOOL.T", TOOL_T),
    "klartext-rl-tool-def": Case(KLARTEXT_TOOL_DEF, "rect.h", RECTANGLE, 5.0),
    "klartext-rnd-chf": Case(KLARTEXT_CORNERS, "corn.h", CORNERS, 5.0),
    "sinumerik-g42": Case(SINUMERIK, "OUTLINE.MPF", OUTLINE, -4.0, "_N_TO_INI", TO_INI, sinumerik_contour),
    "klartext-incremental": Case(KLARTEXT_INCREMENTAL, "rect.h", RECTANGLE, 5.0),
    "klartext-tool-axis-y": Case(KLARTEXT_ZX, "rect.h", RECTANGLE, 5.0, plane=18, machine_text=affine_in(18)),
    "klartext-tool-axis-x-incremental": Case(KLARTEXT_YZ, "rect.h", RECTANGLE, 5.0, plane=19,
                                             machine_text=affine_in(19)),
    "sinumerik-g91": Case(SINUMERIK_G91, "OUTLINE.MPF", OUTLINE, -4.0, "_N_TO_INI", TO_INI, sinumerik_contour),
    "sinumerik-ic": Case(SINUMERIK_IC, "OUTLINE.MPF", OUTLINE, -4.0, "_N_TO_INI", TO_INI, sinumerik_contour),
    "sinumerik-g18": Case(SINUMERIK_ZX, "OUTLINE.MPF", OUTLINE, -4.0, "_N_TO_INI", TO_INI, sinumerik_contour,
                          18, affine_in(18)),
    "sinumerik-g19-g91": Case(SINUMERIK_YZ, "OUTLINE.MPF", OUTLINE, -4.0, "_N_TO_INI", TO_INI,
                              sinumerik_contour, 19, affine_in(19)),
    "klartext-depth-at-an-inside-corner": Case(KLARTEXT_TOOL_DEF, "rect.h", RECTANGLE, 5.0,
                                               machine_text=affine_in(17)),
    "sinumerik-norm-from-behind": Case(SINUMERIK_BEHIND, "OUTLINE.MPF", OUTLINE, -4.0, "_N_TO_INI", TO_INI,
                                       sinumerik_contour, start=(0.0, 20.0), norm=True),
    "sinumerik-norm-onto-an-arc": Case(SINUMERIK_ARC_FIRST, "OUTLINE.MPF", OUTLINE_FROM_ARC, -4.0, "_N_TO_INI",
                                       TO_INI, sinumerik_contour, start=(80.0, -20.0), norm=True),
    "sinumerik-kont-in-front": Case(SINUMERIK_ARC_FIRST.replace("N40", "N35 KONT\nN40"), "OUTLINE.MPF",
                                    OUTLINE_FROM_ARC, -4.0, "_N_TO_INI", TO_INI, sinumerik_contour,
                                    start=(80.0, -20.0), norm=True),
    "sinumerik-kont-behind": Case(SINUMERIK_BEHIND.replace("N40", "N35 KONT\nN40"), "OUTLINE.MPF", OUTLINE,
                                  -4.0, "_N_TO_INI", TO_INI, sinumerik_contour, start=(0.0, 20.0)),
}  # fmt: skip
DEPTH = -1.0  # (the contours' programs cut at Z-1, or Y-1, X-1)


@pytest.mark.parametrize("case", CASES.values(), ids=CASES.keys())
def test_the_tool_centre_lands_on_the_offset_contour_within_half_a_micron(tmp_path, case):
    """The tool centre of the rewritten program, run on the machine, within 0.5 µm of the tool-centre
    path of the programmed contour all along; the original's misses it by more than 10 µm.  In G91,
    IX IY and IC() the written increments are read from the corrected end before them; in the other
    planes (`affine_in`) the machine's errors move the tool along the plane's normal too, which the
    depth read from the written program must correct."""
    options = ()
    if case.table is not None:
        (tmp_path / case.table).write_text(case.table_text, encoding="latin-1")
        options = ("--tool-table", str(tmp_path / case.table))
    reached = closed_form if case.machine_text is AFFINE else closed_form_in(case.plane)
    on = functools.partial(machine, plane=case.plane, reached=reached)
    wanted = offset(case.contour, case.side, case.start, transitions=True, depth=DEPTH, norm=case.norm)
    assert deviation(wanted, wanted, on).max() > 0.010
    written, messages = compensated(tmp_path, case.name, case.text, *options, machine_text=case.machine_text)
    moves, start = case.read(written, case.plane)
    assert len(moves) >= len(case.contour)  # (arcs may come in pieces)
    made = offset(moves, case.side, start, norm=case.norm)
    assert deviation(wanted, made, on).max() <= 0.0005
    assert "left as programmed: nothing" in messages, messages
    assert np.allclose(
        made[-1].end[:2], case.contour[-1][0], atol=0.1
    )  # (the exit move: the section is whole)


NEW = ("klartext-incremental", "klartext-tool-axis-y", "klartext-tool-axis-x-incremental", "sinumerik-g91",
       "sinumerik-ic", "sinumerik-g18", "sinumerik-g19-g91", "sinumerik-norm-from-behind",
       "sinumerik-norm-onto-an-arc", "sinumerik-kont-in-front", "sinumerik-kont-behind")  # fmt: skip


@pytest.mark.skipif(not WIDE.exists(), reason="the shared machine file is not available")
@pytest.mark.parametrize("name", NEW)
def test_the_verifier_accepts_each_program_written_for_the_shared_machine(tmp_path, name):
    """`ncpp compensate` reads each program it writes back and refuses one whose actions or path
    differ from the input's: on the shared machine file it writes them all, compensated."""
    case = CASES[name]
    options = ()
    if case.table is not None:
        (tmp_path / case.table).write_text(case.table_text, encoding="latin-1")
        options = ("--tool-table", str(tmp_path / case.table))
    written, messages = compensated(tmp_path, case.name, case.text, *options, machine_text=WIDE.read_text())
    assert "left as programmed: nothing" in messages and written != case.text, messages


def test_an_entry_waits_for_the_next_move_in_the_plane_past_an_infeed(tmp_path):
    """NORM: the entry's tool centre is square to the first move in the plane, past a block that
    moves along Z alone (the control looks ahead to it), which stands there too; the events come
    in the program's order."""
    text = SINUMERIK_ARC_FIRST.replace("N50 G42 G1 X80 Y0\n", "N50 G42 G1 X80 Y0\nN55 Z-2\n")
    (tmp_path / "_N_TO_INI").write_text(TO_INI)
    offsets = WorkOffsets(tools=ToolTable.from_file(tmp_path / "_N_TO_INI"))
    dialect, blocks = parse_program(io.BytesIO(text.encode()), "OUTLINE.MPF", None)
    interpret, _ = dialect_tools(dialect)
    events = list(
        interpret(blocks, file="OUTLINE.MPF", warnings=Warnings(stream=io.StringIO()), offsets=offsets)
    )
    assert [e.block.line for e in events] == sorted(e.block.line for e in events)
    entry, infeed, arc = [e for e in events if type(e) is Line or type(e) is Arc][2:5]
    square = pytest.approx((0.0, -4.0, 0.0))  # (G42, radius 4: outside the arc about (80, 20))
    assert entry.centre_shift == (None, square) and infeed.centre_shift == (square, square)
    assert arc.centre_shift[0] == square


def test_an_entry_along_the_tool_axis_alone_does_not_wait(tmp_path):
    """G42 in a block that moves no axis of the plane: no selection takes place there (840D sl
    Function Manual W1), so that move keeps the tool centre on its point, not square to the next."""
    text = SINUMERIK_ARC_FIRST.replace(
        "N40 G1 Z-1 F300\nN50 G42 G1 X80 Y0", "N40 G42 G1 Z-1 F300\nN50 X80 Y0"
    )
    (tmp_path / "_N_TO_INI").write_text(TO_INI)
    offsets = WorkOffsets(tools=ToolTable.from_file(tmp_path / "_N_TO_INI"))
    dialect, blocks = parse_program(io.BytesIO(text.encode()), "OUTLINE.MPF", None)
    interpret, _ = dialect_tools(dialect)
    moves = [e for e in interpret(blocks, file="OUTLINE.MPF", warnings=Warnings(stream=io.StringIO()),
                                  offsets=offsets) if type(e) is Line]  # fmt: skip
    assert moves[1].centre_shift == (None, (0.0, 0.0, 0.0))


def test_a_change_of_units_keeps_where_the_tool_centre_stands_in_every_axis(tmp_path):
    """G70 under G42 in G18: the tool centre stands off along Z after a move along X, and stays there
    in the new units."""
    text = (
        "N10 G18 G90 G71\nN20 T1 M6\nN30 G0 Z-20 X0 Y5\nN40 G1 Y-1 F300\nN50 G42 G1 Z0 X0\nN60 X80\nN70 G70\n"
    )
    text += "N80 Z1\nN90 G40 Z2 X4\nN100 M30\n"
    (tmp_path / "_N_TO_INI").write_text(TO_INI)
    offsets = WorkOffsets(tools=ToolTable.from_file(tmp_path / "_N_TO_INI"))
    dialect, blocks = parse_program(io.BytesIO(text.encode()), "T.MPF", None)
    interpret, _ = dialect_tools(dialect)
    moves = [e for e in interpret(blocks, file="T.MPF", warnings=Warnings(stream=io.StringIO()), offsets=offsets)
             if type(e) is Line]  # fmt: skip
    along_x, in_inch = moves[3], moves[4]
    assert along_x.centre_shift[1] == pytest.approx((0.0, 0.0, 4.0))  # (right of +X in Z X: +Z)
    assert in_inch.centre_shift[0] == pytest.approx((0.0, 0.0, 4.0 / 25.4))


def test_kontc_and_kontt_are_out_of_scope(tmp_path):
    """KONTC and KONTT approach on the control's own polynomials: the rest passes through."""
    (tmp_path / "_N_TO_INI").write_text(TO_INI)
    text = SINUMERIK.replace("N40", "N35 KONTC\nN40")
    _, messages = compensated(tmp_path, "OUTLINE.MPF", text, "--tool-table", str(tmp_path / "_N_TO_INI"))
    assert "OUTLINE.MPF:5:5: warning: the approach KONTC (the control's polynomial" in messages, messages


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
    ends = [end[:2] for end, *_ in moves]
    corners = [end for end, centre, _ in contour if centre is None]
    for point in corners[:-1]:  # (the exit's end too is corrected where it is)
        assert any(np.allclose(end, programmed(point), atol=0.6e-4) for end in ends), (point, ends)


def test_klartext_rl_in_an_arc_block_is_left_as_programmed(tmp_path):
    """RL turned on in an arc block (the TNC turns it on in a line block: TNC 640 user's manual,
    "Radius compensation") leaves the moves as programmed with the warning; compensation follows
    again from a line that starts at a corrected point."""
    change, why = "6 L X+0 Y+0 RL F300\n7 L X+80", "6 L X+0 Y+0 F300\n7 CR X+80 Y+0 R+200 DR+ RL"
    text = KLARTEXT.format(tool="TOOL DEF 3 L+0 R+5\n3 TOOL CALL 3 Z S3000").replace(change, why)
    written, messages = compensated(tmp_path, "rect.h", text)
    assert "cutter compensation: its moves pass through uncompensated" in messages
    lines = written.splitlines()
    kept = next(line for line in why.splitlines() if "RL" in line).split(" ", 1)[1]
    assert any(line.endswith(kept) for line in lines), written
    assert not any(line.endswith(" L Y+60") for line in lines), written  # (followed again)


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
