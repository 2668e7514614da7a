"""Heidenhain and Sinumerik tool lengths, as LinuxCNC's G43 (test_tool_lengths.py).

Heidenhain: TOOL CALL applies L + DL from the TNC's tool table (TOOL.T, --tool-table)
or from the program's own TOOL DEF, plus the call's DL, along the tool axis.
Sinumerik: M6 loads the tool T selected with cutting edge D1, D picks another edge;
the edge's lengths 1-3 from the control's tool offsets (_N_TO_INI) act along the
plane's axes.  A longer tool is a longer Abbe arm in both."""

import io
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.tools import ToolTable
from ncpp.pipeline import ErrorSource, dialect_tools, process
from ncpp.program.dialects import parse_program
from ncpp.simulate import contour_error, sample_events
from tests.compensation.conftest import QUIET, repeatable_machine

ROOT = Path(__file__).resolve().parents[2]
MACHINE = ROOT / "samples/machines/hr5b.toml"
ZERO = (400.0, 350.0, 300.0)
# TOOL.T as the TNC writes it: fixed columns under the header, a decimal comma, names, [END]
TOOL_T = """BEGIN TOOL    .T       MM
T    NAME             L          R          DL      DR      TL RT  TIME1 TIME2 CUR.TIME DOC
0                     +0,000     +0,000     +0,000  +0,000         0     0     0
1    D10_ENDMILL      +150,020   +5,000     -0,020  +0,000         0     0     0
2    DRILL_6          +40,5      +3,000     +0,000  +0,000         0     0     0
3    D10_ENDMILL      +90,000    +5,000     +0,000  +0,000         0     0     0
[END]
"""


def _table(tmp_path: Path, text: str = TOOL_T) -> ToolTable:
    path = tmp_path / "TOOL.T"
    path.write_text(text, encoding="latin-1")
    return ToolTable.from_file(path, unit_mm=25.4)  # the file's own units win over the machine's


def test_tool_t_lengths_are_l_plus_dl_in_its_units(tmp_path):
    tools = _table(tmp_path)  # each tool one edge, its length 1 along the tool axis
    assert tools.edges == {
        (0, 1): (0, 0, 0),
        (1, 1): (pytest.approx(150.0), 0, 0),
        (2, 1): (40.5, 0, 0),
        (3, 1): (90.0, 0, 0),
    }
    assert tools.names == {"D10_ENDMILL": 1.0, "DRILL_6": 2.0}  # a name listed twice: its first tool
    inch = _table(tmp_path, TOOL_T.replace("MM\n", "INCH\n", 1).replace("+40,5 ", "+2,0  "))
    assert inch.edges[2, 1][0] == pytest.approx(50.8)
    header = TOOL_T.splitlines()[:2]
    for lines, message in (
        (
            [*header, "1                     +1,0", "1                     +2,0"],
            r"TOOL.T:4:1: tool 1 is listed twice",
        ),
        ([*header, "5                     +1,x"], r"TOOL.T:3:23: expected a number, got '\+1.x'"),
        ([header[0], "T    NAME             R"], r"TOOL.T:2:1: TOOL.T header without a L column"),
    ):
        with pytest.raises(NcppError, match=message):
            _table(tmp_path, "\n".join(lines) + "\n")


PROGRAM = b"""0 BEGIN PGM P MM
1 TOOL CALL 1 Z S800
2 L X+10 Y+10 Z+5 R0 FMAX
3 TOOL CALL "DRILL_6" Z DL+0.5
4 L Z+5 FMAX
5 TOOL DEF 7 L+55 R+2
6 TOOL CALL 7 Z
7 L Z+5
8 TOOL CALL Z S100
9 L Z+6
10 TOOL CALL 2 X
11 L X+20
12 TOOL CALL 0 Z
13 L Z+7
14 END PGM P MM
"""


def _events(program: bytes, offsets: WorkOffsets, dialect: str = "heidenhain") -> list:
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(program), "p.h", dialect)
    return [
        e
        for e in interpret(blocks, file="p.h", warnings=QUIET, offsets=offsets)
        if type(e).__name__ in ("Line", "Arc")
    ]


def test_tool_call_applies_the_tools_length_along_the_tool_axis(tmp_path):
    """By number, by name (plus the call's DL), defined by TOOL DEF, kept by a call without a
    tool, along X for a TOOL CALL .. X, none for tool 0."""
    events = _events(PROGRAM, replace(WorkOffsets.at(ZERO), tools=_table(tmp_path)))
    assert [e.context.tool for e in events] == [
        pytest.approx(t)
        for t in ((0, 0, 150.0), (0, 0, 41.0), (0, 0, 55.0), (0, 0, 55.0), (40.5, 0, 0), (0, 0, 0))
    ]
    first = events[0]
    assert first.context.to_machine(first.end) == pytest.approx(
        (410.0, 360.0, 300.0 + 5.0 + 150.0)
    )  # the gauge line above the tip


def test_a_tool_the_table_lacks_is_a_located_error(tmp_path):
    told = replace(WorkOffsets.at(ZERO), tools=_table(tmp_path))
    with pytest.raises(
        NcppError, match=r"p.h:2:3: tool 9 is not defined: neither in .*TOOL.T nor by TOOL DEF"
    ):
        _events(b"0 BEGIN PGM P MM\n1 TOOL CALL 9 Z\n2 END PGM P MM\n", told)
    with pytest.raises(NcppError, match=r'p.h:2:3: tool "FLY" is not in .*TOOL.T'):
        _events(b'0 BEGIN PGM P MM\n1 TOOL CALL "FLY" Z\n2 END PGM P MM\n', told)


def _warnings(program: bytes, offsets: WorkOffsets, strict: bool = False, dialect: str = "heidenhain") -> str:
    said = io.StringIO()
    process(io.BytesIO(program), io.BytesIO(), file="t", source=ErrorSource.from_machine_file(str(MACHINE)),
            warnings=Warnings(strict, said), dialect=dialect, offsets=offsets)  # fmt: skip
    return said.getvalue()


UNTOLD = b"0 BEGIN PGM P MM\n1 TOOL CALL 1 Z S800\n2 L X+10 Y+10 Z+50 FMAX\n3 TOOL CALL 2 Z\n4 END PGM P MM\n"


def test_without_a_tool_table_tool_call_is_warned_once(tmp_path):
    lines = _warnings(UNTOLD, WorkOffsets.at(ZERO)).splitlines()
    assert (
        len(lines) == 1
        and lines[0].startswith("t:2:3: warning: TOOL CALL applies a tool length")
        and "tool length 0" in lines[0]
    )
    assert _warnings(UNTOLD, replace(WorkOffsets.at(ZERO), tools=_table(tmp_path))) == ""
    defined = UNTOLD.replace(b"1 TOOL CALL", b"1 TOOL DEF 1 L+100 R+5\n1 TOOL DEF 2 L+50 R+3\n1 TOOL CALL")
    assert _warnings(defined, WorkOffsets.at(ZERO)) == ""  # the program says its tools' lengths
    with pytest.raises(NcppError, match=r"t:2:3: TOOL CALL applies a tool length"):
        _warnings(UNTOLD, WorkOffsets.at(ZERO), strict=True)


# Sinumerik's tool offsets as the control saves them; tool 2's edge 1 also has a length 2
TO_INI = """CHANDATA(1)
$TC_TP2[1]="D10_ENDMILL"
$TC_DP1[1,1]=120
$TC_DP3[1,1]=150.02 ; length 1 (geometry)
$TC_DP12[1,1]=-0.02 ; its wear
$TC_DP6[1,1]=5
$TC_DP1[1,2]=120
$TC_DP3[1,2]=100
$TC_TP2[2]="DRILL_6"
$TC_DP1[2,1]=200
$TC_DP3[2,1]=40
$TC_DP21[2,1]=0.5 ; adapter length 1
$TC_DP4[2,1]=1.5
M17
"""


def _offsets(tmp_path: Path, text: str = TO_INI) -> ToolTable:
    path = tmp_path / "_N_TO_INI"
    path.write_text(text)
    return ToolTable.from_file(path)


def test_sinumerik_tool_offsets_are_per_edge_geometry_plus_wear_plus_adapter(tmp_path):
    tools = _offsets(tmp_path)
    assert tools.edges == {
        (1, 1): pytest.approx((150.0, 0, 0)),
        (1, 2): (100.0, 0, 0),
        (2, 1): pytest.approx((40.5, 1.5, 0)),
    }
    assert tools.names == {"D10_ENDMILL": 1, "DRILL_6": 2}
    with pytest.raises(NcppError, match=r"_N_TO_INI:2:14: expected a number, got 'x'"):
        _offsets(tmp_path, "CHANDATA(1)\n$TC_DP3[1,1]=x\n")


SINUMERIK = b"""N10 G90 G17 G71
N20 T="D10_ENDMILL" M6
N30 G0 X10 Y10 Z5
N40 D1 M6 T2
N50 G1 Z5 F100
N60 G18
N70 G1 Z6
N80 G17 D0
N90 G1 Z7
N100 T1 M6 D2
N110 G1 Z8
N120 M30
"""


def test_sinumerik_m6_loads_d1_and_d_picks_an_edge_along_the_planes_axes(tmp_path):
    """By name; M6 with the D of its block, wherever it stands; G18 turns length 1 to Y;
    D0 none; another edge."""
    events = _events(SINUMERIK, replace(WorkOffsets.at(ZERO), tools=_offsets(tmp_path)), "sinumerik")
    assert [e.context.tool for e in events] == [
        pytest.approx(t) for t in ((0, 0, 150.0), (0, 1.5, 40.5), (1.5, 40.5, 0), (0, 0, 0), (0, 0, 100.0))
    ]
    first = events[0]
    assert first.context.to_machine(first.end) == pytest.approx((410.0, 360.0, 300.0 + 5.0 + 150.0))


def test_sinumerik_a_tool_or_edge_the_offsets_lack_is_a_located_error(tmp_path):
    told = replace(WorkOffsets.at(ZERO), tools=_offsets(tmp_path))
    with pytest.raises(NcppError, match=r"p.h:1:7: tool 2 has no cutting edge D3 in .*_N_TO_INI"):
        _events(b"T2 M6 D3\nM30\n", told, "sinumerik")
    with pytest.raises(NcppError, match=r'p.h:1:9: tool "FLY" is not in .*_N_TO_INI'):
        _events(b'T="FLY" M6\nM30\n', told, "sinumerik")


@pytest.mark.parametrize(
    "program, where",
    [
        (b'G0 X10 Y10 Z50\nT="MILL" M6\nD1\nG1 X20 F100\nM30\n', "t:2:10"),
        (b"G0 X10 Y10 Z50\nD0\nG1 X20 D2 F100\nM30\n", "t:3:8"),
    ],
)
def test_sinumerik_without_tool_offsets_the_first_length_applied_is_warned(tmp_path, program, where):
    lines = _warnings(program, WorkOffsets.at(ZERO), dialect="sinumerik").splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"{where}: warning: ") and "tool length 0" in lines[0], (
        lines
    )
    told = replace(
        WorkOffsets.at(ZERO),
        tools=_offsets(tmp_path, '$TC_TP2[1]="MILL"\n$TC_DP3[1,1]=50\n$TC_DP3[1,2]=60\n'),
    )
    assert _warnings(program.replace(b"D2", b"D1"), told, dialect="sinumerik") == ""


# The sample pocket, cut with a 150 mm and a 40.5 mm tool, in Klartext and in Sinumerik's G code
KLARTEXT_POCKET = [
    "L Z+5 R0 FMAX",
    "L X-20 Y-10 FMAX",
    "L Z-2 F200",
    "L X+20 F600",
    "CC X+20 Y+0",
    "C X+30 Y+0 DR+",
    "L Y+10",
    "CC X+20 Y+10",
    "C X+20 Y+20 DR+",
    "L X-20",
    "CC X-20 Y+10",
    "C X-30 Y+10 DR+",
    "L Y+0",
    "CC X-20 Y+0",
    "C X-20 Y-10 DR+",
    "L Z+5 FMAX",
    "L X+75 Y+0 FMAX",
    "L Z-2 F200",
    "CC X+0 Y+0",
    "C X+75 Y+0 DR- F600",
    "L Z+5 FMAX",
]
KLARTEXT = [
    "BEGIN PGM POCKET MM",
    "TOOL CALL 1 Z S3000",
    *KLARTEXT_POCKET,
    "TOOL CALL 2 Z S3000",
    *KLARTEXT_POCKET,
    "END PGM POCKET MM",
]
G_POCKET = [
    line.decode() for line in (ROOT / "samples/programs/pocket.ngc").read_bytes().splitlines()[3:-2]
]  # its moves
TWO_TOOLS = {
    "heidenhain": ("".join(f"{n} {line}\n" for n, line in enumerate(KLARTEXT)).encode(), "TOOL.T", TOOL_T),
    "sinumerik": (
        "\n".join(["G90 G17 G71", "T1 M6", *G_POCKET, "T2 M6", *G_POCKET, "M30", ""]).encode(),
        "_N_TO_INI",
        TO_INI,
    ),
}


def _placed(dialect: str, tmp_path: Path | None) -> WorkOffsets:
    """The pocket's zero, with the dialect's tool table (None: no table)."""
    if tmp_path is None:
        return WorkOffsets.at(ZERO)
    _, name, text = TWO_TOOLS[dialect]
    (tmp_path / name).write_text(text)
    return replace(WorkOffsets.at(ZERO), tools=ToolTable.from_file(tmp_path / name))


def _compensated(dialect: str, offsets: WorkOffsets, machine) -> bytes:
    source = ErrorSource(machine, "model", "0" * 16, machine.max_correction_mm, dict(machine.limits))
    out = io.BytesIO()
    process(
        io.BytesIO(TWO_TOOLS[dialect][0]),
        out,
        file="p",
        source=source,
        warnings=QUIET,
        dialect=dialect,
        offsets=offsets,
    )
    return out.getvalue()


def _contour_um(machine, dialect: str, program: bytes, offsets: WorkOffsets) -> float:
    run, nominal = (
        sample_events(_events(program, offsets, dialect)),
        sample_events(_events(TWO_TOOLS[dialect][0], offsets, dialect)),
    )
    return contour_error(machine, run, nominal, feed_effects=False).max_um


@pytest.mark.parametrize("dialect", TWO_TOOLS)
def test_each_tool_is_compensated_at_its_length(tmp_path, dialect):
    """Compensated with the tool table the simulated contour error is within the tolerance
    + 0.5 µm; compensated at length 0 (no table) it is several times the tolerance."""
    machine = repeatable_machine(MACHINE)
    told = _placed(dialect, tmp_path)
    before = _contour_um(machine, dialect, TWO_TOOLS[dialect][0], told)
    after = _contour_um(machine, dialect, _compensated(dialect, told, machine), told)
    at_length_0 = _contour_um(machine, dialect, _compensated(dialect, _placed(dialect, None), machine), told)
    assert before > 20.0 and after <= 1.5 and at_length_0 > 4.0, (before, after, at_length_0)


@pytest.mark.parametrize("dialect, suffix", [("heidenhain", ".h"), ("sinumerik", ".mpf")])
def test_command_line_tool_table(tmp_path, dialect, suffix):
    program, name, text = TWO_TOOLS[dialect]
    (tmp_path / name).write_text(text)
    (tmp_path / f"pocket{suffix}").write_bytes(program)

    def run(*placement: str) -> subprocess.CompletedProcess:
        # (--no-guard: a Klartext program gets none, which is warned; the warnings here are the tool table's)
        command = [sys.executable, "-m", "ncpp", "compensate", "--machine", str(MACHINE), "--work-offset", "400,350,300",
                   "--no-guard", "--dialect", dialect, str(tmp_path / f"pocket{suffix}"), *placement]  # fmt: skip
        return subprocess.run(command, capture_output=True, cwd=ROOT)

    told, untold = run("--tool-table", str(tmp_path / name)), run()
    assert told.returncode == 0 and b"warning" not in told.stderr, told.stderr  # (the run's summary alone)
    assert untold.returncode == 0 and b"tool length 0" in untold.stderr
    assert told.stdout != untold.stdout


def test_motion_and_simulate_take_the_dialect_and_its_tool_table(tmp_path):
    """The Sinumerik pocket reads as ISO G code too (nothing in it is Sinumerik's alone): --dialect says."""
    import json

    program, name, text = TWO_TOOLS["sinumerik"]
    (tmp_path / name).write_text(text)
    (tmp_path / "pocket.mpf").write_bytes(program)
    placed = [
        "--work-offset",
        "400,350,300",
        "--tool-table",
        str(tmp_path / name),
        "--dialect",
        "sinumerik",
        str(tmp_path / "pocket.mpf"),
    ]
    motion = subprocess.run(
        [sys.executable, "-m", "ncpp", "motion", "--format", "json", *placed], capture_output=True, cwd=ROOT
    )
    assert motion.returncode == 0, motion.stderr
    tools = {tuple(json.loads(line)["tool"]) for line in motion.stdout.splitlines()}
    assert tools == {(0.0, 0.0, 150.0), (0.0, 1.5, 40.5)}
    simulated = subprocess.run(
        [sys.executable, "-m", "ncpp", "simulate", "--machine", str(MACHINE), *placed],
        capture_output=True,
        cwd=ROOT,
    )
    assert simulated.returncode == 0, simulated.stderr
    assert (
        b"at [400.0, 350.0, 448.0]" in simulated.stdout and b"at [400.0, 351.5, 338.5]" in simulated.stdout
    )  # each tool's circle
