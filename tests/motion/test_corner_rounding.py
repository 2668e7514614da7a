"""Fanuc corner rounding (`,R`, `G1 ... R`) and chamfering (`,C`) between two lines."""

from __future__ import annotations

import math
import subprocess
import sys

import pytest

from ncpp.errors import NcppError
from ncpp.motion import interpret
from ncpp.motion.segments import Arc, Line
from ncpp.program.parser import parse_text
from tests import rs274
from tests.conftest import ROOT, RS274

SQUARE = "G21 G17 G90 F100\nG1 X0 Y0\nG1 X10 ,R2\n(held comment)\nY10 ,C1\nX0\nG1 X-10 R1\nY0\nM2\n"


def moves(text: str):
    return [e for e in interpret(parse_text(text)) if type(e) in (Line, Arc)]


def test_fillet_is_tangent_to_both_lines_and_chamfer_cuts_equal_legs():
    m = moves(SQUARE)
    first, fillet, second = m[1], m[2], m[3]
    assert first.end == pytest.approx((8.0, 0.0, 0.0))
    assert type(fillet) is Arc and fillet.turn == 1 and fillet.center[:2] == pytest.approx((8.0, 2.0))
    assert fillet.radius() == pytest.approx(2.0) and fillet.sweep() == pytest.approx(math.pi / 2)
    assert second.start == pytest.approx((10.0, 2.0, 0.0)) and second.end == pytest.approx((10.0, 9.0, 0.0))
    chamfer = m[4]
    assert (chamfer.start, chamfer.end) == (pytest.approx((10.0, 9.0, 0.0)), pytest.approx((9.0, 10.0, 0.0)))
    assert (
        m[-3].end == pytest.approx((-9.0, 10.0, 0.0))
        and type(m[-2]) is Arc
        and m[-1].start == pytest.approx((-10.0, 9.0, 0.0))
    )


def test_clockwise_corner_gets_a_clockwise_fillet():
    m = moves("G21 G90 F100\nG1 X0 Y0\nX10 ,R1\nY-10\nM2\n")
    assert type(m[2]) is Arc and m[2].turn == -1 and m[2].center[:2] == pytest.approx((9.0, -1.0))


def test_radius_too_large_is_refused_with_its_location():
    with pytest.raises(NcppError) as err:
        list(interpret(parse_text("G21 G90 F100\nG1 X0 Y0\nX2 ,R5\nY2\nM2\n"), file="p.nc"))
    assert (err.value.where.line, err.value.where.col) == (3, 4)


def test_corner_before_an_arc_passes_through_with_a_warning(capsys):
    events = list(interpret(parse_text("G21 G90 F100\nG1 X0 Y0\nX10 ,R1\nG3 X10 Y10 I0 J5\nM2\n")))
    assert type(events[-3]).__name__ == "Pass" and "outside" in capsys.readouterr().err


@pytest.mark.skipif(not RS274.exists(), reason="rs274 oracle not available")
def test_compensated_corners_are_plain_arcs_linuxcnc_accepts(tmp_path):
    program = tmp_path / "corners.ngc"
    program.write_text(SQUARE.replace("G21 G17 G90 F100", "G21 G17 G90 G0 X0 Y0 Z0\nF100"))
    out = tmp_path / "out.ngc"
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "ncpp",
            "compensate",
            "--machine",
            str(ROOT / "samples/machines/hr5b.toml"),
            "--work-offset",
            "400,350,300",
            "--no-guard",  # (rs274 runs it from G54 at 0)
            str(program),
            "-o",
            str(out),
        ],  # fmt: skip
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    text = out.read_text()
    assert ",R" not in text and ",C" not in text and " R1" not in text
    oracle = rs274.run(out)
    assert oracle.stdout.count("ARC_FEED") == 2 and "error" not in (oracle.stdout + oracle.stderr).lower()


def test_corner_before_a_rapid_warns_once_and_strict_refuses():
    import io

    from ncpp.errors import Warnings

    stream = io.StringIO()
    text = "G21 G90 F1\nG0 X1\nG1 X10 ,C1\nG0 X2\nG0 X3\n"
    events = list(interpret(parse_text(text), file="t.nc", warnings=Warnings(stream=stream)))
    assert [type(e).__name__ for e in events] == ["Pass", "Line", "Pass", "Pass", "Pass"]
    assert stream.getvalue().count("warning") == 1 and "t.nc:3:" in stream.getvalue()
    with pytest.raises(NcppError) as err:
        list(interpret(parse_text(text), file="t.nc", strict=True))
    assert err.value.where.line == 3 and "strict" in err.value.message


def test_corner_on_the_last_move_is_refused():
    with pytest.raises(NcppError) as err:
        list(interpret(parse_text("G21 G90 F1\nG1 X10 ,R1\n"), file="t.nc"))
    assert err.value.where.line == 2 and "no following move" in err.value.message
