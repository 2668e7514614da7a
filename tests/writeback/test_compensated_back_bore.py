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
# level, Z from R; I J modal in the cycle, K the repeats): (X, Y, Z top, R) of each hole
FANUC_HOLES = [(200, 150, -10, -45), (-180, 220, -10, -45), (220, -185, -35, -55), (230, -180, -35, -55)]
FANUC_PROGRAM = """%
G21 G90 G17
G0 X40 Y30 Z25 S500 M3
G1 X60 Y50 F300
G98 G87 X200 Y150 Z-10 R-45 I2 J-1 F100
X-180 Y220
G80
G1 X210 Y-190 Z5 F300
G91 G98 G87 X10 Y5 R-60 Z20 I-1 K2
G90 G80
G1 X-100 Y80 Z3
X-150 Y-120 Z-2
M30
%
"""
_FANUC_WORD = re.compile(r"([A-Z])\s*(-?[\d.]+)")


def fanuc_back_bores_written_out(text: str) -> str:
    """`text` (this test's words: G0/G1 moves, G90/G91, G80 and G87) with each G87 hole as the moves the
    manual gives, in G90 G0/G1 blocks for rs274, read from its words here (not by ncpp)."""
    pos, absolute, cycle, out = np.zeros(3), True, False, []
    initial = r = top = shift_i = shift_j = 0.0
    for line in text.splitlines():
        words = [
            (letter, float(value))
            for letter, value in _FANUC_WORD.findall(re.sub(r"\(.*?\)", "", line.upper()))
        ]
        codes = [value for letter, value in words if letter == "G"]
        absolute = False if 91 in codes else True if 90 in codes else absolute
        given = {letter: value for letter, value in words if letter in "XYZRIJKF"}
        if 80 in codes or line.strip() == "%":
            cycle = False
            out += ["G90" if absolute else "G91"] if line.strip() != "%" else []
            continue
        if 87 in codes and not cycle:
            cycle, initial, shift_i, shift_j = True, pos[2], 0.0, 0.0
        if not cycle:
            out.append(line)
            step = np.array(
                [given.get(axis, 0.0 if not absolute else pos[k]) for k, axis in enumerate("XYZ")]
            )
            pos = step if absolute else pos + step
            continue
        shift_i, shift_j = given.get("I", shift_i), given.get("J", shift_j)
        r = given.get("R", r)  # (the words as written: G91's R from the initial level, Z from R)
        top = given.get("Z", top)
        bottom, cut = (r, top) if absolute else (initial + r, initial + r + top)
        feed = f" F{given['F']:g}" if "F" in given else ""
        for _ in range(int(given.get("K", 1))):
            x = given.get("X", pos[0]) if absolute else pos[0] + given.get("X", 0.0)
            y = given.get("Y", pos[1]) if absolute else pos[1] + given.get("Y", 0.0)
            sx, sy = x + shift_i, y + shift_j
            out += [f"G90 G0 X{x:.6f} Y{y:.6f}", f"X{sx:.6f} Y{sy:.6f}", f"Z{bottom:.6f}", f"X{x:.6f} Y{y:.6f}",
                    f"G1 Z{cut:.6f}{feed}", f"G0 X{sx:.6f} Y{sy:.6f}", f"Z{initial:.6f}", f"X{x:.6f} Y{y:.6f}"]  # fmt: skip
            pos = np.array([x, y, initial])
        out.append("G90" if absolute else "G91")
    return "\n".join(out) + "\n"


@pytest.mark.parametrize(
    "machine_toml, machine", [(MACHINE, square), (REVERSAL, reversing)], ids=["square", "reversals"]
)
def test_fanuc_back_bores_cut_to_their_top_and_start_at_their_r(tmp_path, machine_toml, machine):
    """Fanuc's G87 is compensated hole by hole, a G87 block per hole: each cut ends on its programmed X Y
    Z within 0.5 µm and starts at its R there, every other feed end too.  Judged by rs274 running both
    programs with their G87 holes written out by hand as Fanuc's moves, mapped through the hand-written
    machine, where the program as written misses each cut's end by more than 1 µm."""
    original = tmp_path / "back.nc"
    original.write_text(FANUC_PROGRAM)
    said = io.StringIO()
    output = compensate_file(
        original, machine_toml, tmp_path, warnings=Warnings(stream=said), dialect="fanuc"
    )
    text = output.read_text()
    assert "warning" not in said.getvalue(), said.getvalue()
    assert len(re.findall(r"^(G98 G87|G91 G98 G87|X)", text, re.M)) >= 4 and "K2" not in text
    runs = []
    for path in (original, output):
        plain = tmp_path / (path.stem + "-moves.ngc")
        plain.write_text(fanuc_back_bores_written_out(path.read_text()))
        runs.append(plain)
    commanded = _moves(runs[0])
    wanted = np.array([b for _, b, feeds in commanded if feeds])
    cuts = [
        k
        for k, (a, b, feeds) in enumerate(commanded)
        if feeds and b[2] > a[2] + 0.01 and np.allclose(a[:2], b[:2])
    ]
    assert np.allclose([commanded[k][1] for k in cuts], [h[:3] for h in FANUC_HOLES], atol=1e-6)
    assert np.allclose([commanded[k][0][2] for k in cuts], [h[3] for h in FANUC_HOLES], atol=1e-6)
    ran = [(a, b, feeds, m[-1]) for (a, b, feeds), m in zip(_moves(runs[1]), actual_moves(runs[1], machine))]
    reached = np.array([m for _, _, feeds, m in ran if feeds])
    misses = np.linalg.norm(wanted[:, None, :] - reached[None, :, :], axis=2).min(axis=1) * 1000
    assert misses.max() <= 0.5, misses
    ups = [k for k, (a, b, feeds, _) in enumerate(ran) if feeds and b[2] > a[2] + 0.01]
    starts = np.array([ran[k - 1][3][2] for k in ups])  # (the level the tool stands at below each cut)
    assert len(ups) == len(FANUC_HOLES)
    assert np.abs(starts - [h[3] for h in FANUC_HOLES]).max() * 1000 <= 0.5
    actual_before = actual_moves(runs[0], machine)
    off_before = [np.linalg.norm(actual_before[k][-1] - np.array(h[:3])) for k, h in zip(cuts, FANUC_HOLES)]
    assert min(off_before) * 1000 > 1.0, off_before  # (the machine is wrong enough to tell, at every cut)
