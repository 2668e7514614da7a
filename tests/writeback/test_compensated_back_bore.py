"""G87, rs274ngc's back boring cycle, is compensated hole by hole: the cut (the feed back up to K on
the bore's centre) ends where the program puts it, and the bottom (Z) and the R level are where the
program puts them.  Judged by LinuxCNC's rs274 running ncpp's output (LinuxCNC G-code manual, "G87
Back Boring Cycle": to X Y, down to R, over by I J, down to Z, back by I J, spindle on, feed up to K,
feed down to Z, over by I J, out to the clear level, back over the hole), its moves mapped through
the machines written by hand in test_compensated_holes.py, not by ncpp's interpreter or model."""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np
import pytest

from ncpp.errors import Warnings
from tests.compensation.accuracy import _moves, actual_moves
from tests.writeback.conftest import compensate_file
from tests.writeback.test_compensated_holes import (
    MACHINE,
    PLANE_INDICES,
    PLANE_LETTERS,
    REVERSAL,
    _passes_pathcheck,
    reversing,
    reversing_in,
    square,
)

# (X, Y, Z bottom, R, K top) of each hole (in G18 and G19 the plane's first and second axis, the levels
# along its normal), in the order the program bores them
HOLES = [(200, 150, -30, 5, -12), (-180, 220, -30, 5, -12), (-250, -200, -25, 4, -10),
         (260, -240, -25, 4, -10), (300, 280, -20, 2, -8)]  # fmt: skip
PROGRAM = """G21 G90 G17
G0 X40 Y30 Z25
G1 X45 Y35 F300
M3 S500
G0 Z25
G98 G87 X200 Y150 Z-30 R5 I2 J-1 K-12 F100
X-180 Y220
G99 G87 X-250 Y-200 Z-25 R4 I-1.5 J0 K-10
X260 Y-240
G98 G87 X300 Y280 Z-20 R2 I0 J1.5 K-8
G80
M5
M2
"""
# In G91 with repeats: X Y from where the control stands, R from the series' start level, Z from
# R, K from Z (rs274ngc's convert_cycle_g87 in G91); a block per hole is written
HOLES_G91 = [(230, 160, 5, 22, 12), (260, 180, 5, 22, 12), (290, 200, 5, 22, 12),
             (-290, 260, -15, 3, -7), (-320, 260, -15, 3, -7)]  # fmt: skip
PROGRAM_G91 = """G21 G90 G17
G0 X200 Y140 Z25
M3 S500
G91 G99 G87 X30 Y20 R-3 Z-17 I1 J1 K7 L3 F100
G90 G80
G0 X-260 Y260 Z20
G91 G98 G87 X-30 R-17 Z-18 I0 J-1 K8 L2
G90 G80
M5
M2
"""
# The G17 letters each plane's words take (rs274ngc's convert_cycle_zx and _yz: the plane's first and
# second axis and its normal in the places of X Y Z, and I J K with them)
LETTERS = {
    plane: letters + "".join("IJK"["XYZ".index(a)] for a in letters)
    for plane, letters in PLANE_LETTERS.items()
}


def in_plane(program: str, plane: int) -> str:
    """A G17 program moved to `plane`: its axis and offset letters renamed."""
    return program.replace("G17", f"G{plane}").translate(str.maketrans("XYZIJK", LETTERS[plane]))


def back_bored(path: Path, machine, plane: int = 17) -> list[tuple[np.ndarray, float, float]]:
    """Per G87 hole of `path` as rs274 runs it (mapped through `machine`, or as commanded: None):
    where the tool ends the cut (the feed up the plane's normal), the level it starts it at (the
    bottom) and the level it stands at before it goes over to the offset (R), along the normal."""
    first, second, normal = PLANE_INDICES[plane]
    across = [first, second]
    commanded = _moves(path)
    actual = [b for _, b, _ in commanded] if machine is None else [m[-1] for m in actual_moves(path, machine)]
    out = []
    for k, (start, end, feeds) in enumerate(commanded):
        up = np.allclose(start[across], end[across], atol=0.01) and end[normal] > start[normal] + 0.01
        if feeds and up:  # (before it: back from the offset, down at the offset, over to it at R)
            out.append((actual[k], float(actual[k - 1][normal]), float(actual[k - 4][normal])))
    return out


PROGRAMS = [
    (PROGRAM, HOLES, 17),
    (PROGRAM_G91, HOLES_G91, 17),
    *(
        (in_plane(p, plane), h, plane)
        for plane in (18, 19)
        for p, h in ((PROGRAM, HOLES), (PROGRAM_G91, HOLES_G91))
    ),
]


@pytest.mark.parametrize("machine_name", ["scales and squareness", "reversals"])
@pytest.mark.parametrize(
    "program, holes, plane",
    PROGRAMS,
    ids=["G90", "G91 repeats", "G18 G90", "G18 G91 repeats", "G19 G90", "G19 G91 repeats"],
)
def test_each_back_bore_cuts_to_its_top_and_stands_at_its_bottom_and_r(
    tmp_path, machine_name, program, holes, plane
):
    """The cut's end (X Y K) within 0.2 µm of the programmed point, the bottom (Z) and R levels
    within 0.2 µm, where the machine puts each cut's end more than 5 µm off uncompensated; the
    cycles stay G87 blocks, a block per hole; pathcheck passes."""
    if machine_name == "scales and squareness":
        machine_toml, machine = MACHINE, square
    else:
        machine_toml, machine = (REVERSAL, reversing) if plane == 17 else reversing_in(plane)
    original = tmp_path / "back.ngc"
    original.write_text(program)
    output = compensate_file(original, machine_toml, tmp_path)
    wanted = np.array(holes, dtype=float)  # (the plane's first and second axis, bottom, R, top)
    tops = np.zeros((len(holes), 3))
    tops[:, list(PLANE_INDICES[plane])] = wanted[:, [0, 1, 4]]
    as_programmed = back_bored(original, None, plane)
    assert np.allclose(
        [(*t, b, r) for t, b, r in as_programmed], np.column_stack([tops, wanted[:, 2:4]]), atol=1e-6
    )
    before, after = back_bored(original, machine, plane), back_bored(output, machine, plane)
    assert len(after) == len(holes)
    assert len(re.findall(r"G87", output.read_text())) == len(re.findall(r"G87", program))
    off_before = np.array([np.linalg.norm(t - w) for (t, _, _), w in zip(before, tops)]) * 1000
    off_after = np.array([np.linalg.norm(t - w) for (t, _, _), w in zip(after, tops)]) * 1000
    bottom_after = np.abs([b for _, b, _ in after] - wanted[:, 2]) * 1000
    r_after = np.abs([r for _, _, r in after] - wanted[:, 3]) * 1000
    assert off_before.min() > 5.0, off_before  # the machine is wrong enough to tell, at every hole
    assert off_after.max() < 0.2, off_after
    assert bottom_after.max() < 0.2, bottom_after
    assert r_after.max() < 0.2, r_after
    assert _passes_pathcheck(original, output)


# A Fanuc program's G87 (Fanuc Series 15i-MA operator's manual, "Back boring cycle (G87)": to X Y,
# shifted by I J with the spindle oriented, down to R below the part, back over the hole, feed up to
# Z, shifted again, up to the initial level, back over the hole; G98 only; G91: R from the initial
# level, Z from R), and the same moves written out by hand for rs274: each G87 block's lines
FANUC_BACK_BORES = {
    "G98 G87 X200 Y150 Z-10 R-45 I2 J-1 F100\n": "G0 X200 Y150\nX202 Y149\nZ-45\nX200 Y150\nG1 Z-10 F100\n"
    "G0 X202 Y149\nZ25\nX200 Y150\n",
    "X-180 Y220\n": "G0 X-180 Y220\nX-178 Y219\nZ-45\nX-180 Y220\nG1 Z-10\nG0 X-178 Y219\nZ25\nX-180 Y220\n",
    "G91 G98 G87 X10 Y5 R-60 Z20 I-1 K2\n": "G90 G0 X20 Y15\nX19\nZ-55\nX20\nG1 Z-35\nG0 X19\nZ5\n"
    "X20\nX30 Y20\nX29\nZ-55\nX30\nG1 Z-35\nG0 X29\nZ5\nX30\nG91\n",
}
FANUC_PROGRAM = """%
G21 G90 G17
G0 X40 Y30 Z25 S500 M3
G1 X60 Y50 F300
G98 G87 X200 Y150 Z-10 R-45 I2 J-1 F100
X-180 Y220
G80
G1 X10 Y10 Z5 F300
G91 G98 G87 X10 Y5 R-60 Z20 I-1 K2
G90 G80
G1 X-100 Y80 Z3
X-150 Y-120 Z-2
M30
%
"""


def _written_out(text: str) -> str:
    """`text` with its G87 blocks as the moves Fanuc makes of them (`FANUC_BACK_BORES`), for rs274."""
    lines = text.splitlines(keepends=True)
    return "".join(FANUC_BACK_BORES.get(line, line) for line in lines if line.strip() not in ("%", "G80"))


def test_around_a_fanuc_back_bore_left_as_programmed_the_moves_land_where_programmed(tmp_path):
    """Fanuc's G87 reads its words otherwise than rs274ngc: left as programmed, with the warning, and
    compensation resumes where the cycle leaves the tool, over the hole at the initial level.  Judged
    by rs274 running both programs with their G87 blocks written out by hand as Fanuc's moves, mapped
    through the hand-written machine: every feed end but the cycles' within 0.5 µm."""
    original = tmp_path / "back.nc"
    original.write_text(FANUC_PROGRAM)
    said = io.StringIO()
    output = compensate_file(original, MACHINE, tmp_path, warnings=Warnings(stream=said), dialect="fanuc")
    text = output.read_text()
    assert all(line in text for line in FANUC_BACK_BORES)  # (the cycles' blocks as they stand)
    assert "back.nc:5:1: warning: canned cycle" in said.getvalue()
    runs = []
    for path in (original, output):
        plain = tmp_path / (path.stem + "-moves.ngc")
        plain.write_text(_written_out(path.read_text()))
        runs.append(plain)
    wanted = np.array([b for _, b, feeds in _moves(runs[0]) if feeds])
    reached = np.array(
        [m[-1] for (_, _, feeds), m in zip(_moves(runs[1]), actual_moves(runs[1], square)) if feeds]
    )
    misses = np.linalg.norm(wanted[:, None, :] - reached[None, :, :], axis=2).min(axis=1) * 1000
    cut = np.isclose(wanted[:, 2], -10) | np.isclose(wanted[:, 2], -35)  # (the cycles' cuts, as programmed)
    assert misses[cut].min() > 1.0 and misses[~cut].max() <= 0.5, misses
