"""`ncpp post`: APT CL data of the corpus posted in every dialect, checked
against LinuxCNC's interpreter and the dialect parsers."""

from __future__ import annotations

import io
import math
import re
import subprocess
import sys

import numpy as np
import pytest

from ncpp.cldata import motion, read_cldata
from ncpp.errors import NcppError, Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import Arc, Context, Line
from ncpp.post import GENERATORS, post
from ncpp.post.generator import single_turns
from ncpp.program.blocks import Block
from tests.conftest import CORPUS, ROOT, corpus_files, corpus_id
from tests.rs274 import canon, end_points

CL_FILES = corpus_files("apt_cldata")
MACHINE = ROOT / "samples/machines/hr5b.toml"
OFFSET = (400.0, 350.0, 300.0)


def posted(path, dialect: str, source=None) -> str:
    out = io.BytesIO()
    with open(path, encoding="latin-1") as stream:
        post(
            stream,
            out,
            file=str(path),
            dialect=dialect,
            source=source,
            warnings=Warnings(stream=io.StringIO()),
            offsets=WorkOffsets.at(OFFSET),
        )
    return out.getvalue().decode("latin-1")


def cl_end_points(path) -> list[tuple[float, float, float]]:
    """End points of the CL motion (GOTOs, arcs collapsed to their last GOTO)."""
    with open(path, encoding="latin-1") as stream:
        events = list(motion(read_cldata(stream, str(path)), Warnings(stream=io.StringIO())))
    return [e.end for e in events if type(e) in (Line, Arc)]


def distinct(points, tol=1e-4):
    """Points with repeats of the previous one removed (a zero-length move writes nothing)."""
    kept = []
    for p in points:
        if not kept or max(abs(a - b) for a, b in zip(p, kept[-1])) > tol:
            kept.append(p)
    return kept


def test_corpus_holds_cl_files(corpus):
    assert len(CL_FILES) >= 4


@pytest.mark.parametrize("dialect", tuple(GENERATORS))
@pytest.mark.parametrize("path", CL_FILES, ids=corpus_id)
def test_every_cl_file_posts_in_every_dialect(path, dialect):
    text = posted(path, dialect)
    moves = [ln for ln in text.splitlines() if any(w in ln.split() for w in ("G0", "G1", "L"))]
    assert moves, "no motion written"
    if dialect in ("heidenhain", "sinumerik"):
        from ncpp.program.dialects import parse_program

        name, blocks = parse_program(io.BytesIO(text.encode("latin-1")), "posted", dialect)
        assert len(list(blocks)) == len(text.splitlines())


@pytest.mark.parametrize("dialect", ("iso", "linuxcnc", "fanuc"))
@pytest.mark.parametrize("path", CL_FILES, ids=corpus_id)
def test_linuxcnc_runs_the_post_to_the_cl_end_points(path, dialect, tmp_path):
    program = tmp_path / "posted.ngc"
    program.write_text(posted(path, dialect))
    got = distinct(end_points(canon(program, timeout=300)))
    want = distinct(cl_end_points(path))
    assert len(got) == len(want)
    assert np.abs(np.array(got) - np.array(want)).max() <= 1e-4


def test_arcs_are_posted_as_arcs(corpus):
    path = CORPUS / "apt_cldata/creo_ncl/profilfraesen_2.ncl.1"
    circles = path.read_text(encoding="latin-1").count("CIRCLE")
    iso = posted(path, "linuxcnc")
    assert sum(" I" in ln and " J" in ln for ln in iso.splitlines()) == circles
    klartext = posted(path, "heidenhain").splitlines()
    cc = [n for n, ln in enumerate(klartext) if ln.split()[1] == "CC"]
    assert len(cc) == circles
    assert all(
        klartext[n + 1].split()[1] == "C" and klartext[n + 1].split()[-1] in ("DR-", "DR+") for n in cc
    )
    assert klartext[0] == "0 BEGIN PGM MFG0004 MM" and klartext[-1].endswith("END PGM MFG0004 MM")
    assert [int(ln.split()[0]) for ln in klartext] == list(range(len(klartext)))
    sinumerik = posted(path, "sinumerik")
    assert (
        sum(" I" in ln and " J" in ln for ln in sinumerik.splitlines()) == circles
        and "\n; PARTNO MFG0004" in sinumerik
    )


@pytest.mark.parametrize("path", CL_FILES[:2] + CL_FILES[-1:], ids=corpus_id)
def test_posted_with_a_machine_file_is_compensated(path, tmp_path):
    from ncpp.pipeline import HEADER_TAG, ErrorSource

    source = ErrorSource.from_machine_file(str(MACHINE))
    text = posted(path, "linuxcnc", source)
    assert text.splitlines()[0].startswith(f"({HEADER_TAG} for hr5b.toml")
    program = tmp_path / "compensated.ngc"
    program.write_text(text)
    got = np.array(end_points(canon(program, timeout=300)))
    want = np.array(distinct(cl_end_points(path)))
    # Compensated lines may be subdivided: every CL end point is still reached, moved by the correction.
    nearest = np.array([np.abs(got - w).max(axis=1).min() for w in want])
    assert nearest.max() < 0.1  # within the machine's correction
    assert nearest.max() > 1e-3  # and really moved (HR5B errors are tens of µm)


def test_post_command_writes_a_file(corpus, tmp_path):
    out = tmp_path / "part.h"
    path = CORPUS / "apt_cldata/rybakov25/test.apt"
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "post", str(path), "--dialect", "heidenhain", "-o", str(out)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stderr
    assert "DELAY" not in proc.stderr
    lines = out.read_text().splitlines()
    assert lines[0] == "0 BEGIN PGM TEST_MACRO_LOAD MM"
    assert [ln.split(" ", 1)[1] for ln in lines if "CYCL DEF 9" in ln] == [
        "CYCL DEF 9.0 DWELL TIME",
        "CYCL DEF 9.1 DWELL 2.5",
    ]


def test_changing_tool_vector_is_refused():
    cl = "MULTAX\nFEDRAT / 100\nGOTO / 0, 0, 10, 0, 0, 1\nGOTO / 5, 0, 10, 0, 0.6, 0.8\nFINI\n"
    with pytest.raises(NcppError, match="tool vector changes"):
        post(io.StringIO(cl), io.BytesIO(), file="five.cls", dialect="iso")
    constant = "MULTAX\nFEDRAT / 100\nGOTO / 0, 0, 10, 0, 0, 1\nGOTO / 5, 0, 10, 0, 0, 1\nFINI\n"
    out = io.BytesIO()
    post(io.StringIO(constant), out, dialect="iso")
    assert out.getvalue().decode().splitlines()[3:5] == ["G1 X0. Y0. Z10. F100.", "X5."]


def test_feed_move_without_feed_rate_is_refused():
    with pytest.raises(NcppError, match="no feed rate"):
        post(
            io.StringIO("GOTO / 0, 0, 10\nGOTO / 5, 0, 10\n"),
            io.BytesIO(),
            file="nofeed.cls",
            dialect="sinumerik",
        )


def test_error_stops_the_command_with_no_output(tmp_path):
    bad = tmp_path / "bad.cls"
    bad.write_text("FROM / 0, 0, 0\nCIRCLE / 0, 0, 0, 0, 0, 1, 5\nGOTO / 5, 0, 0\n")
    out = tmp_path / "out.ngc"
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "post", str(bad), "--dialect", "iso", "-o", str(out)],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert proc.returncode == 2 and f"{bad}:2:1:" in proc.stderr
    assert not out.exists()


def test_multi_turn_helix_splits_into_single_turns_keeping_the_pitch():
    block = Block(raw="", eol="\n", items=(), line=1)
    helix = Arc(
        start=(5, 0, 0), end=(0, 5, -9), center=(0, 0, 0), turn=3, feed=100, block=block, context=Context()
    )
    pieces = list(single_turns(helix))
    assert len(pieces) == 3 and all(p.turn == 1 for p in pieces)
    assert pieces[-1].end == helix.end
    total = sum(p.sweep() for p in pieces)
    assert math.isclose(total, helix.sweep())
    rises = [p.end[2] - p.start[2] for p in pieces]
    assert all(math.isclose(r / p.sweep(), -9 / helix.sweep()) for r, p in zip(rises, pieces))


@pytest.mark.parametrize(
    "record, message",
    [
        ("UNITS / FURLONG", r"p\.cls:1:1: UNITS/FURLONG: expected MM or INCHES"),
        ("LOADTL / 1.5", r"p\.cls:1:1: LOADTL: expected a tool number"),
        ("LOADTL / abc", r"p\.cls:1:1: LOADTL: expected a tool number"),
        ("LOADTL / 1e300", r"p\.cls:1:1: LOADTL: expected a tool number"),
        ("SPINDL / -1e308, CLW", r"p\.cls:1:1: SPINDL: expected a spindle speed from 0"),
        ("SPINDL / -1200, CCLW", r"p\.cls:1:1: SPINDL: expected a spindle speed from 0"),
        ("FEDRAT / -100", r"p\.cls:1:1: FEDRAT: expected a feed rate above 0"),
        ("FEDRAT / 0", r"p\.cls:1:1: FEDRAT: expected a feed rate above 0"),
    ],
)
def test_a_unit_or_tool_the_post_cannot_write_is_refused(record, message):
    with pytest.raises(NcppError, match=message):
        post(
            io.StringIO(f"{record}\nFEDRAT / 100\nGOTO / 1, 2, 3\nFINI\n"),
            io.BytesIO(),
            file="p.cls",
            dialect="iso",
        )


def test_units_inches_and_mm_are_read():
    for unit in ("MM", "INCHES"):
        out = io.BytesIO()
        post(
            io.StringIO(f"UNITS / {unit}\nLOADTL / 3\nFEDRAT / 100\nGOTO / 1, 2, 3\nFINI\n"),
            out,
            file="p.cls",
            dialect="iso",
        )
        assert b"G20" in out.getvalue() if unit == "INCHES" else b"G21" in out.getvalue()


@pytest.mark.parametrize("dialect", sorted(GENERATORS))
@pytest.mark.parametrize("rpm", ["1000", "9000", "0", "12500"])
def test_spindle_speed_is_written_as_given(dialect, rpm):
    """`SPINDL / 1000` was posted as S1 (trailing zeros dropped from a whole number)."""
    out = io.BytesIO()
    post(
        io.StringIO(f"UNITS / MM\nSPINDL / RPM, {rpm}, CLW\nFEDRAT / 100\nGOTO / 0, 0, 0\nFINI\n"),
        out,
        file="s.cls",
        dialect=dialect,
    )
    assert re.search(rf"\bS{rpm}\b", out.getvalue().decode()), out.getvalue().decode()


def test_the_corpus_spindle_speeds_are_posted(corpus):
    text = posted(CORPUS / "apt_cldata/creo_ncl/bohren_1.ncl.8", "iso")
    assert "S9000 M3" in text


def test_a_change_of_units_after_the_first_motion_is_refused():
    """The header sets the program's unit: GOTO / 1,0,0 after UNITS / INCHES was posted as X1. under G21."""
    cl = "FEDRAT / 20\nGOTO / 0, 0, 0\nUNITS / INCHES\nGOTO / 1, 0, 0\nFINI\n"
    with pytest.raises(NcppError, match=r"u\.cls:3:1: UNITS/INCHES after the first motion"):
        post(io.StringIO(cl), io.BytesIO(), file="u.cls", dialect="iso")
    out = io.BytesIO()  # the same unit again changes nothing
    post(io.StringIO("UNITS / INCHES\n" + cl), out, file="u.cls", dialect="iso")
    assert b"G20" in out.getvalue() and b"X1." in out.getvalue()
