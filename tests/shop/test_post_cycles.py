"""`ncpp post` of CL hole-making cycles (`CYCLE/`), dwells (`DELAY`) and cutter compensation
(`CUTCOM`): the holes are drilled to the CL data's depth, judged by LinuxCNC's rs274 and by
the numbers of the CL records (Creo's and NX's couplet forms)."""

from __future__ import annotations

import io
import re
import subprocess
import sys
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.post import post
from tests.conftest import CORPUS, ROOT, SHARED
from tests.rs274 import canon

BOHREN = CORPUS / "apt_cldata/creo_ncl/bohren_1.ncl.8"  # Creo: CYCLE/DEEP, DEPTH 3.5, STEP 1, CLEAR 1
WIDE = SHARED / "machines/wide.toml"
FEED = re.compile(r"(STRAIGHT_FEED|STRAIGHT_TRAVERSE)\(([^,]+), ([^,]+), ([^,]+),")

# NX's forms: the bottom FEDTO below the GOTO, R at RAPTO (else CLEAR) above it, RTRCTO AUTO back
# to where the cycle started; a Creo BORE with a dwell; a dwell, cutter compensation
NX = """PARTNO / HOLES
UNITS / MM
LOADTL / 1
SPINDL / RPM, 1500, CLW
FROM / 0, 0, 80
RAPID
GOTO / 20.0, 100.0, 50.0
CYCLE/DRILL,CLEAR,3.0000,FEDTO,-10.0000,RTRCTO,AUTO,MMPM,250.0000
GOTO / 20.0, 100.0, 10.0
GOTO / 80.0, 100.0, 10.0
CYCLE/OFF
CYCLE/DRILL,DEEP,RAPTO,2,FEDTO,-22,STEP,5,MMPM,120
GOTO / 120.0, 100.0, 4.0
CYCLE/OFF
CYCLE/DRILL,BRKCHP,RAPTO,2,FEDTO,-9,STEP,2,MMPM,120
GOTO / 140.0, 100.0, 4.0
CYCLE/OFF
CYCLE / BORE, DEPTH, 6, MMPM, 60, CLEAR, 1.5, DWELL, 0.75
GOTO / 160.0, 100.0, 0.0
CYCLE / OFF
DELAY / 2.5
FEDRAT / 400, MMPM
RAPID
GOTO / 190.0, 90.0, 5.0
GOTO / 190.0, 90.0, -3.0
CUTCOM / LEFT
GOTO / 200.0, 100.0, -3.0
GOTO / 200.0, 140.0, -3.0
CUTCOM / OFF
GOTO / 190.0, 150.0, -3.0
RAPID
GOTO / 190.0, 150.0, 50.0
FINI
"""
# (x, y): (bottom z, the R plane z) from the records above
NX_HOLES = {(20.0, 100.0): (0.0, 13.0), (80.0, 100.0): (0.0, 13.0), (120.0, 100.0): (-18.0, 6.0),
            (140.0, 100.0): (-5.0, 6.0), (160.0, 100.0): (-6.0, 1.5)}  # fmt: skip


def _post(
    text: str, dialect: str, machine: Path | None = None, tmp_path: Path | None = None
) -> tuple[str, str]:
    """(program, warnings) as `ncpp post` writes them."""
    source = None
    if machine is not None:
        from ncpp.pipeline import ErrorSource

        source = ErrorSource.from_machine_file(str(machine))
    out, told = io.BytesIO(), io.StringIO()
    post(
        io.StringIO(text),
        out,
        file="holes.cls",
        dialect=dialect,
        source=source,
        warnings=Warnings(stream=told),
    )
    return out.getvalue().decode("latin-1"), told.getvalue()


def _moves(canon: str) -> list[tuple[str, float, float, float]]:
    return [(kind, float(x), float(y), float(z)) for kind, x, y, z in FEED.findall(canon)]


def _drilled(moves: list[tuple[str, float, float, float]]) -> dict[tuple[float, float], float]:
    """The deepest feed move at each XY a feed moves straight down at."""
    deepest: dict[tuple[float, float], float] = {}
    last = None
    for kind, x, y, z in moves:
        if kind == "STRAIGHT_FEED" and last is not None and (last[1], last[2]) == (x, y) and z < last[3]:
            deepest[(x, y)] = min(z, deepest.get((x, y), z))
        last = (kind, x, y, z)
    return deepest


@pytest.fixture(autouse=True)
def small_tool(tmp_path, monkeypatch):
    """rs274 started with T1 of 0.5 mm diameter (its tool table is in inches), so that the
    CUTCOM moves are longer than the tool radius, as LinuxCNC wants them."""
    table = tmp_path / "small.tbl"
    table.write_text("T1 P1 D0.02 Z0\n")
    monkeypatch.setenv("RS274_TOOL_TABLE", str(table))


def _rs274(tmp_path: Path, program: str, name: str = "holes.ngc") -> list[tuple[str, float, float, float]]:
    path = tmp_path / name
    path.write_text(program)
    return _moves(canon(path, timeout=300))


@pytest.mark.parametrize("dialect", ["linuxcnc", "iso"])
def test_creo_deep_holes_are_drilled_to_their_depth_in_rs274(tmp_path, dialect):
    """CYCLE/DEEP, DEPTH 3.5, STEP 1, CLEAR 1 at hole tops Z0.5: pecks of 1 mm down to Z-3 from R1.5."""
    program, _ = _post(BOHREN.read_text(encoding="latin-1"), dialect)
    assert "G99 G83 X-7.2291 Y-23. Z-3. R1.5 Q1. F50." in program.splitlines()
    moves = _rs274(tmp_path, program.replace("%\n", ""))
    assert _drilled(moves) == {(-7.2291, -23.0): -3.0, (-16.7804, -23.0): -3.0}
    pecks = [z for kind, x, _, z in moves if kind == "STRAIGHT_FEED" and x == -7.2291]
    assert pecks == [0.5, -0.5, -1.5, -2.5, -3.0]


def test_nx_holes_reach_their_bottoms_and_retract_as_the_records_say(tmp_path):
    program, _ = _post(NX, "linuxcnc")
    moves = _rs274(tmp_path, program)
    drilled = _drilled(moves)
    assert {xy: drilled.get(xy) for xy in NX_HOLES} == {xy: bottom for xy, (bottom, _) in NX_HOLES.items()}
    for (x, y), (_, r) in NX_HOLES.items():  # every hole starts feeding at its R plane
        k = next(k for k, m in enumerate(moves) if m[0] == "STRAIGHT_FEED" and m[1:3] == (x, y))
        assert moves[k - 1] == ("STRAIGHT_TRAVERSE", x, y, r)
    # RTRCTO AUTO: the first drill returns to Z50, where the cycle started (G98)
    after_first = next(k for k, m in enumerate(moves) if m[1:] == (20.0, 100.0, 0.0)) + 1
    assert moves[after_first] == ("STRAIGHT_TRAVERSE", 20.0, 100.0, 50.0)
    lines = program.splitlines()
    assert "G98 G81 X20. Y100. Z0. R13. F250." in lines and "G89" in program  # BORE with DWELL
    assert "G4 P2.5" in lines and lines.index("G41") < lines.index("G40")


def test_rs274_dwells_where_the_cl_data_delays(tmp_path):
    program, _ = _post(NX, "linuxcnc")
    path = tmp_path / "holes.ngc"
    path.write_text(program)
    dwells = re.findall(r"DWELL\(([\d.]+)\)", canon(path, timeout=300))
    assert dwells == ["0.7500", "2.5000"]  # the bore's, the DELAY


def test_compensated_holes_stay_where_programmed_with_the_pipeline_warning(tmp_path):
    plain, _ = _post(NX, "linuxcnc")
    compensated, warned = _post(NX, "linuxcnc", machine=WIDE)
    assert "canned cycle: its moves pass through uncompensated" in warned
    assert "cutter compensation: its moves pass through uncompensated" in warned
    cycles = [ln for ln in plain.splitlines() if re.match(r"(G9[89] G\d\d )?X.*R", ln)]
    assert len(cycles) == 5 and all(ln in compensated.splitlines() for ln in cycles)
    drilled = _drilled(_rs274(tmp_path, compensated))
    assert {xy: drilled.get(xy) for xy in NX_HOLES} == {xy: bottom for xy, (bottom, _) in NX_HOLES.items()}
    assert compensated != plain  # the moves between the holes are compensated


@pytest.mark.parametrize("dialect", ["heidenhain", "sinumerik", "fanuc"])
def test_every_dialect_posts_the_holes_compensated_and_verified(dialect):
    plain, _ = _post(NX, dialect)
    compensated, warned = _post(NX, dialect, machine=WIDE)
    assert "canned cycle" in warned
    unnumbered = lambda text: [re.sub(r"^\d+ ", "", ln) for ln in text.splitlines()]  # noqa: E731
    holes = [ln for ln in unnumbered(plain) if re.search(r"CYCL DEF 20|Q2\d\d=|M99|CYCLE8|G8[1-9] |G73 ", ln)]
    assert len(holes) >= 4 and all(ln in unnumbered(compensated) for ln in holes)


def test_heidenhain_cycle_parameters_are_the_cl_numbers():
    program, _ = _post(BOHREN.read_text(encoding="latin-1"), "heidenhain")
    q = dict(re.findall(r"Q(\d+)=([+-][\d.]+)", program))
    assert "CYCL DEF 203 UNIVERSAL DRILLING" in program
    assert (q["200"], q["201"], q["202"], q["203"], q["206"], q["213"]) == (
        "+1",
        "-3.5",
        "+1",
        "+0.5",
        "+50",
        "+0",
    )
    assert re.search(r"^\d+ L X-7.2291 Y-23 R0 FMAX M99$", program, re.M)
    program, _ = _post(NX, "heidenhain")
    assert re.search(r"^\d+ CYCL DEF 9.1 DWELL 2.5$", program, re.M)
    assert re.search(r"^\d+ L X\+200 Y\+100 RL$", program, re.M) and re.search(
        r"^\d+ L X\+190 Y\+150 R0$", program, re.M
    )


def test_sinumerik_calls_the_cycle_over_each_hole():
    program, _ = _post(BOHREN.read_text(encoding="latin-1"), "sinumerik")
    lines = program.splitlines()
    # RTP 1.5 (G99: the R plane), RFP 0.5, SDIS 1, DP -3; FDEP -0.5, DAM 1; VARI 1: out to clear the chips
    call = "CYCLE83(1.5, 0.5, 1, -3, , -0.5, , 1, , , 1, 1)"
    assert lines[lines.index("G0 X-16.7804 Y-23") + 1] == call
    program, _ = _post(NX, "sinumerik")
    assert "CYCLE81(50, 10, 3, 0)" in program and "G4 F2.5" in program  # RTRCTO AUTO: back to Z50


def test_fanuc_dwells_in_milliseconds():
    program, _ = _post(NX, "fanuc")
    assert "P750" in program and "G4 P2500" in program


CL_HEAD = "UNITS / MM\nSPINDL / RPM, 1000, CLW\nFEDRAT / 100\nRAPID\nGOTO / 0, 0, 20\n"


@pytest.mark.parametrize(
    ("record", "message"),
    [("CYCLE/DRILL, 126.0, 85.0, 1.0, MMPR", "a value 126 without its keyword"),
     ("CYCLE/CSINK, DEPTH, 2, MMPM, 50, CLEAR, 1", "CYCLE/CSINK: ncpp posts the cycles"),
     ("CYCLE/DRILL, FEDTO, -5, RAPTO, 2, RTRCTO, 10, MMPM, 50", "RTRCTO, 10 retracts elsewhere"),
     ("CYCLE/DEEP, DEPTH, 5, MMPM, 50, CLEAR, 1", "needs its peck depth as STEP"),
     ("CYCLE/DEEP, DEPTH, 9, STEP, 3, STEP, 2, MMPM, 50", "variable pecks are not posted"),
     ("CYCLE/DRILL, DEPTH, 5, MMPM, 50, CLEAR, 1, TIMES, 3", "TIMES, 3.0 is not followed"),
     ("CYCLE/DRILL, RAPTO, 2, MMPM, 50", "expected the hole's depth"),
     ("DELAY / REV, 3", "DELAY: expected a dwell time in seconds"),
     ("CUTCOM / LEFT\nCYCLE/DRILL, DEPTH, 5, MMPM, 50, CLEAR, 1", "CYCLE/DRILL under CUTCOM/LEFT or RIGHT")],
)  # fmt: skip
def test_cycles_ncpp_cannot_follow_are_refused_at_their_line(record, message):
    with pytest.raises(NcppError, match=re.escape(message)) as err:
        _post(CL_HEAD + record + "\nGOTO / 5, 5, 0\nCYCLE / OFF\nFINI\n", "linuxcnc")
    assert err.value.where.line == 5 + record.count("\n") + 1


def test_the_post_command_drills_the_creo_holes(tmp_path):
    out = tmp_path / "bohren.ngc"
    command = [sys.executable, "-m", "ncpp", "post", str(BOHREN), "--dialect", "linuxcnc", "-o", str(out)]
    proc = subprocess.run([*command, "--machine", str(WIDE)], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    assert "canned cycle: its moves pass through uncompensated" in proc.stderr
    assert "CYCLE/ is not understood" not in proc.stderr
    assert "X-16.7804 Y-23. Z-3. R1.5 Q1." in out.read_text().splitlines()


def _without_repeats(points: list[tuple[float, ...]]) -> list[tuple[float, ...]]:
    return [p for k, p in enumerate(points) if k == 0 or _apart(p[:3], points[k - 1][:3]) > 1e-6]


def _apart(p: tuple[float, ...], q: tuple[float, ...]) -> float:
    return max(abs(a - b) for a, b in zip(p, q, strict=True))


def test_the_holes_moves_compensation_sees_are_the_ones_rs274_makes(tmp_path):
    """The moves `ncpp.cldata.motion` gives the passes for each hole (left as programmed, but
    the next move starts where they end) are the canned cycles' moves in rs274, in order."""
    from ncpp.cldata import motion, read_cldata
    from ncpp.motion.segments import Line

    cl = "".join(ln + "\n" for ln in NX.splitlines() if not ln.startswith("CUTCOM"))  # rs274 offsets those
    events = motion(read_cldata(io.StringIO(cl), "holes.cls"))
    ours = [(*e.end, e.rapid) for e in events if isinstance(e, Line)]
    program, _ = _post(cl, "linuxcnc")
    theirs = [(x, y, z, kind == "STRAIGHT_TRAVERSE") for kind, x, y, z in _rs274(tmp_path, program)]
    assert len(theirs) > 40
    drilled = _drilled(
        [("STRAIGHT_TRAVERSE" if fast else "STRAIGHT_FEED", x, y, z) for x, y, z, fast in ours]
    )
    assert {xy: drilled.get(xy) for xy in NX_HOLES} == {xy: bottom for xy, (bottom, _) in NX_HOLES.items()}
    ours, theirs = _without_repeats(ours), _without_repeats(theirs)
    assert len(ours) == len(theirs)
    assert all(a[3] == b[3] and _apart(a[:3], b[:3]) < 1e-4 for a, b in zip(ours, theirs, strict=True))
