"""Klartext `RND R..` / `CHF ..` between two lines: the geometry, its scope, and compensation.

The fillet arc or chamfer line is the RND/CHF block's own event; compensated
output writes it as `CC` + `C ... DR±` or `L` and re-reads without corners,
tracing the same path as the ISO program with Fanuc `,R` / `,C` compensated.
"""

from __future__ import annotations

import io
import math
import subprocess
import sys

import numpy as np
import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.guard import without_guard
from ncpp.motion.segments import Arc, Line, Pass
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from ncpp.simulate import sample_events
from tests.conftest import ROOT

HEAD = "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S3000\n2 L X+0 Y+0 Z-2 R0 F500\n"
PART = (
    HEAD
    + """3 L X+40 Y+0
4 RND R5 F200
5 L X+40 Y+30
6 CHF 3
; the chamfer's comment
7 L X+10 Y+30
8 RND R2
9 L X+0 Y+10
10 RND R4
11 L X+0 Y+0
12 L Z+5 FMAX
13 END PGM T MM
"""
)
ISO = """G21 G90 G17
G1 X0 Y0 Z-2 F500
G1 X40 Y0 ,R5
G1 X40 Y30 ,C3
G1 X10 Y30 ,R2
G1 X0 Y10 ,R4
G1 X0 Y0
G0 Z5
M30
"""


def events(text: str, dialect: str = "heidenhain", **kw) -> list:
    interpreter, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(text.encode()), "t", dialect)
    return list(
        interpreter(without_guard(blocks), file="t", **kw)
    )  # (a compensated program's placement guard)


def moves(evs: list) -> list:
    return [e for e in evs if type(e) in (Line, Arc)]


def block_text(event) -> str:
    return event.block.raw.split(None, 1)[1]


def test_rnd_is_a_tangent_fillet_of_the_rnd_block() -> None:
    m = moves(events(PART))
    first, fillet, second = m[1], m[2], m[3]
    assert first.end == pytest.approx((35, 0, -2)) and block_text(first) == "L X+40 Y+0"
    assert type(fillet) is Arc and block_text(fillet) == "RND R5 F200"
    assert fillet.start == pytest.approx((35, 0, -2)) and fillet.end == pytest.approx((40, 5, -2))
    assert fillet.center == pytest.approx((35, 5, -2)) and fillet.turn == 1  # a left turn: counter-clockwise
    assert second.start == pytest.approx((40, 5, -2)) and block_text(second) == "L X+40 Y+30"
    # the RND's F holds for the fillet only
    assert (first.feed, fillet.feed, second.feed) == (500, 200, 500)


def test_rnd_at_an_oblique_corner_touches_both_lines() -> None:
    m = moves(events(PART))
    before, fillet, after = m[5], m[6], m[7]  # (10,30) -> (0,10): 2 mm fillet at the corner (10, 30)
    corner, r = np.array([10.0, 30.0]), 2.0
    u = np.array([-1.0, 0.0])
    v = np.array([-10.0, -20.0]) / math.hypot(10, 20)
    c = np.array(fillet.center[:2])
    for p, d in ((np.array(fillet.start[:2]), u), (np.array(fillet.end[:2]), v)):
        assert (
            abs(d[0] * (p - corner)[1] - d[1] * (p - corner)[0]) < 1e-12
        )  # the tangent point lies on its line
        assert np.linalg.norm(c - p) == pytest.approx(r)
        assert abs(np.dot(c - p, d)) < 1e-12  # the radius meets the line at a right angle
    assert before.end == fillet.start and after.start == fillet.end
    assert fillet.turn == 1
    # a right turn goes clockwise, its centre on the right
    right = moves(events(HEAD + "3 L X+10 Y+0\n4 RND R2\n5 L X+10 Y-10\n6 END PGM T MM\n"))
    assert right[2].turn == -1 and right[2].center == pytest.approx((8, -2, -2))


def test_chf_cuts_legs_of_its_length_along_each_line() -> None:
    evs = events(PART)
    m = moves(evs)
    chamfer = m[4]
    assert type(chamfer) is Line and block_text(chamfer) == "CHF 3"
    assert chamfer.start == pytest.approx((40, 27, -2)) and chamfer.end == pytest.approx((37, 30, -2))
    assert m[3].end == chamfer.start and m[5].start == chamfer.end
    # the comment between the chamfer and the next line keeps its place
    order = [block_text(e) for e in evs[evs.index(chamfer) :][:3]]
    assert order == ["CHF 3", "the chamfer's comment", "L X+10 Y+30"]


def test_the_nominal_path_is_the_iso_path() -> None:
    klartext = sample_events(iter(events(PART, strict=True)), 0.05).points
    iso = sample_events(iter(events(ISO, "iso", strict=True)), 0.05).points
    assert klartext.shape == iso.shape and np.abs(klartext - iso).max() < 1e-9


def test_corners_next_to_an_arc_stay_out_of_scope() -> None:
    after_arc = HEAD + "3 CC X+10 Y+0\n4 C X+10 Y+10 DR+\n5 RND R2\n6 L X+20 Y+10\n7 END PGM T MM\n"
    before_arc = HEAD + "3 L X+10 Y+0\n4 RND R2\n5 CC X+10 Y+10\n6 C X+20 Y+10 DR+\n7 END PGM T MM\n"
    # (program, file line warned at, first event passed through: the RND, or the line it would cut)
    for text, line, first_pass in ((after_arc, 6, 5), (before_arc, 5, 3)):
        stream = io.StringIO()
        evs = events(text, warnings=Warnings(stream=stream))
        assert (
            f"t:{line}:" in stream.getvalue()
            and "outside the motion interpreter's scope" in stream.getvalue()
        )
        assert all(type(e) is Pass for e in evs[first_pass:]) and type(evs[first_pass - 1]) is not Pass
        with pytest.raises(NcppError):
            events(text, strict=True)


@pytest.mark.parametrize("text, message", [
    (HEAD + "3 L X+10 Y+0\n4 RND R20\n5 L X+10 Y+10\n6 END PGM T MM\n", "does not fit"),
    (HEAD + "3 L X+10 Y+0\n4 CHF 1\n5 END PGM T MM\n", "CHF has no following move"),
    (HEAD + "3 L X+10 Y+0\n4 RND R1\n5 CHF 1\n6 L X+10 Y+10\n7 END PGM T MM\n", "after another RND/CHF"),
])  # fmt: skip
def test_impossible_corners_are_errors(text: str, message: str) -> None:
    with pytest.raises(NcppError, match=message):
        events(text)


def ncpp(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "ncpp", *args], capture_output=True, cwd=ROOT)


@pytest.fixture(scope="module")
def compensated(tmp_path_factory) -> dict[str, str]:
    folder = tmp_path_factory.mktemp("corners")
    outputs = {}
    for name, text in (("part.h", PART), ("part.ngc", ISO)):
        (folder / name).write_text(text)
        out = folder / ("out-" + name)
        proc = ncpp("compensate", "--machine", str(ROOT / "samples/machines/hr5b.toml"), "--work-offset",
                    "400,350,300", str(folder / name), "-o", str(out))  # fmt: skip
        assert proc.returncode == 0, proc.stderr.decode()
        outputs[name] = out.read_text()
    return outputs


def test_compensated_klartext_has_explicit_arcs_and_consistent_numbers(compensated) -> None:
    lines = compensated["part.h"].splitlines()
    assert not any(" RND " in line or " CHF " in line for line in lines)
    numbered = [line for line in lines if not line.startswith(";")]
    assert [int(line.split()[0]) for line in numbered] == list(range(len(numbered)))
    assert numbered[-1].split(None, 1)[1] == "END PGM T MM"
    assert "; the chamfer's comment" in lines
    fillet = next(line for line in lines if " C " in line and "F200" in line)  # the RND R5 F200 block
    after = lines[lines.index(fillet) + 1 :]
    assert "F500" in next(line for line in after if " L " in line)  # the program's feed comes back
    arcs = [e for e in events(compensated["part.h"], strict=True) if type(e) is Arc]
    radii = sorted(math.dist(a.start[:2], a.center[:2]) for a in arcs)
    assert radii == pytest.approx([2, 4, 5], abs=0.01)  # compensation moves points by micrometres
    assert all(
        abs(math.dist(a.start[:2], a.center[:2]) - math.dist(a.end[:2], a.center[:2])) < 1e-3 for a in arcs
    )


def test_compensated_klartext_traces_the_compensated_iso_path(compensated) -> None:
    klartext = moves(events(compensated["part.h"], strict=True))
    iso = moves(events(compensated["part.ngc"], "iso", strict=True))
    nominal = moves(events(PART))
    assert len(klartext) >= len(nominal)
    k = sample_events(iter(klartext), 0.05).points
    i = sample_events(iter(iso), 0.05).points
    assert k.shape == i.shape and np.abs(k - i).max() < 1e-4
    n = sample_events(iter(nominal), 0.05).points
    assert n.shape != k.shape or np.abs(n - k).max() > 0.005  # compensation really moved the path


def test_without_passes_the_program_is_byte_identical() -> None:
    from ncpp.pipeline import process

    out = io.BytesIO()
    process(io.BytesIO(PART.encode()), out, file="part.h")
    assert out.getvalue() == PART.encode()
