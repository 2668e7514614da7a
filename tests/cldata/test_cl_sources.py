"""CL data as NX (CLSF, APT source) and SolidWorks CAM write it, posted and read back by LinuxCNC's
rs274.  Each case is a short excerpt of a real CL file; its docstring names the repository."""

from __future__ import annotations

import io
import math
import re

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.post import post
from tests import rs274
from tests.rs274 import end_points

ARC = re.compile(r"ARC_FEED\((.*)\)")


def posted(text: str, name: str = "part.cls", dialect: str = "linuxcnc") -> str:
    out = io.BytesIO()
    post(io.StringIO(text), out, file=name, dialect=dialect, warnings=Warnings(stream=io.StringIO()))
    return out.getvalue().decode("latin-1")


def canon(tmp_path, text: str) -> str:
    """rs274's canonical calls for the program posted from `text` (fails on any rs274 error)."""
    program = tmp_path / "part.ngc"
    program.write_text(posted(text))
    return rs274.canon(program, timeout=300)


def arcs(calls: str) -> list[tuple[float, ...]]:
    """ARC_FEED arguments: end x, end y, centre x, centre y, rotation (+1 CCW, -1 CW), end z, ..."""
    return [tuple(float(v) for v in args.split(",")) for args in ARC.findall(calls)]


def sweep(start: tuple[float, ...], arc: tuple[float, ...]) -> float:
    """Degrees an XY ARC_FEED from `start` turns (positive: counterclockwise)."""
    a0 = math.atan2(start[1] - arc[3], start[0] - arc[2])
    a1 = math.atan2(arc[1] - arc[3], arc[0] - arc[2])
    turn = math.degrees(a1 - a0) % 360.0
    return turn if arc[4] > 0 else turn - 360.0


NX_CONTOUR = """TOOL PATH/8_KONTUR_NAR_40_N2,TOOL,FACE_MILL_1
TLDATA/MILL,40.0000,1.0000,50.0000,0.0000,0.0000
MSYS/393.0000,-297.5000,3.0000,0.0000000,1.0000000,0.0000000,1.0000000,0.0000000,0.0000000
$$ centerline data
PAINT/PATH
RAPID
GOTO/1221.5423,14.3929,478.0000,0.0000000,0.0000000,1.0000000
FEDRAT/MMPM,621.0000
GOTO/1221.5423,14.3929,466.0000
CIRCLE/1245.5000,-458.0000,466.0000,0.0000000,0.0000000,1.0000000,473.0000,0.0600,0.5000,40.0000,1.0000
GOTO/1563.1794,-107.5591,466.0000
CIRCLE/1749.2200,97.6673,466.0000,0.0000000,0.0000000,-1.0000000,277.0000,0.0600,0.5000,40.0000,1.0000
GOTO/1597.8754,-134.3323,466.0000
PAINT/TOOL,NOMORE
END-OF-PATH
"""


def test_nx_clsf_operation_header_is_read(tmp_path):
    """NX CLSF opens each operation with `TOOL PATH/name,TOOL,tool` (HumMan/CLSFProcessor,
    samples/_1_KONTUR_NAR_40_N2.cls): a comment, not an unreadable record."""
    text = posted(NX_CONTOUR)
    assert "(TOOL PATH/8_KONTUR_NAR_40_N2,TOOL,FACE_MILL_1)" in text
    ends = end_points(canon(tmp_path, NX_CONTOUR))
    assert ends[-1] == pytest.approx((1597.8754, -134.3323, 466.0), abs=1e-4)


def test_nx_circle_turns_clockwise_about_its_axis(tmp_path):
    """NX's 11-value CIRCLE (HumMan/CLSFProcessor, samples/_1_KONTUR_NAR_40_N2.cls): about +Z the
    tool turns clockwise, 45 degrees along the contour, not 315 degrees across the part; about -Z
    counterclockwise."""
    body = NX_CONTOUR.split("\n", 1)[1]  # without the header: the arcs alone
    calls = canon(tmp_path, body)
    first, second = arcs(calls)
    assert sweep((1221.5423, 14.3929), first) == pytest.approx(-45.07, abs=0.05)
    assert sweep(first, second) == pytest.approx(9.07, abs=0.05)
    assert (first[2], first[3]) == pytest.approx((1245.5, -458.0), abs=1e-4)


SOLIDWORKS_BOSS = """PARTNO/1
UNIT/MM
INSERT/[HOLDER=C40-M06EM2] 6MM CRB 2FL 19 LOC
CUTTER/6.,0,3.,0,0,0,51.
LOAD/TOOL,1
SPINDL/12000,RPM,CLW
INSERT/Stock Size X95. Y150. Z120.
RAPID/
GOTO/96.4375,-1.4375,2.5
FEDRAT/411.48,MMPM
GOTO/96.4375,41.334899,-3.
CIRCLE/95.,44.249705,-3.,0,0,-1.
GOTO/95.,40.999705,-3.
GOTO/78.25,40.999705,-3.
GOTO/78.25,0,-3.
CIRCLE/75.,0,-3.,0,0,-1.
GOTO/77.914806,-1.4375,-3.
RAPID/
GOTO/77.914806,-1.4375,25.
FINI
"""


def test_solidworks_circle_without_radius_and_its_descriptions(tmp_path):
    """SolidWorks CAM (aamorim1913/AptPostProcessor, parts-tools/boss.apt) writes `UNIT/MM`,
    `CIRCLE/x,y,z,i,j,k` without the radius (the tool is on the circle) and tool and stock
    descriptions as `INSERT/` text: short clockwise arcs about the centres, the text as comments."""
    calls = canon(tmp_path, SOLIDWORKS_BOSS)
    first, second = arcs(calls)
    assert (first[2], first[3]) == pytest.approx((95.0, 44.249705), abs=1e-4)
    assert sweep((96.4375, 41.334899), first) == pytest.approx(-26.26, abs=0.05)
    assert sweep((78.25, 0.0), second) == pytest.approx(-26.25, abs=0.05)
    text = posted(SOLIDWORKS_BOSS)
    assert "G21" in text and "(Stock Size X95. Y150. Z120.)" in text


def test_solidworks_inch_unit_posts_inches():
    """`UNIT/` is SolidWorks CAM's spelling of `UNITS/` (aamorim1913/AptPostProcessor writes UNIT/MM):
    an inch program must not be posted as millimetres."""
    text = posted("PARTNO/1\nUNIT/INCH\nLOAD/TOOL,1\nRAPID/\nGOTO/3.5,0.25,1.\nFINI\n")
    assert "G20" in text and "G21" not in text


def test_nx_gohome_goes_to_the_point_it_names(tmp_path):
    """NX's `GOHOME/x,y,z` names the home point (HumMan/CLSFProcessor, samples/_4_SVERL_63_N2.cls):
    the last move ends there, not at the FROM point."""
    text = """FROM/1558.4057,-837.0281,471.0000,0.0000000,0.0000000,1.0000000
RAPID
GOTO/1484.9948,-28.7978,411.0000
FEDRAT/MMPM,120.0000
GOTO/1484.9948,-28.7978,228.0000
RAPID
GOTO/1484.9948,-28.7978,418.0000
GOHOME/1484.9948,-28.7978,471.0000
"""
    ends = end_points(canon(tmp_path, text))
    assert ends[-1] == pytest.approx((1484.9948, -28.7978, 471.0), abs=1e-4)


@pytest.mark.parametrize(
    ("excerpt", "line", "says"),
    [
        (  # HumMan/CLSFProcessor, samples/nurbs.clsf
            "GOTO/-254.9774,466.5681,206.8891\nNURBS/\nKNOT/0.0416667,0.3750000,0.6250000,0.9583333,1.0000000\n"
            "CNTRL/-254.9774,466.2698,206.9401\nCNTRL/-254.9779,452.8642,221.3100\n"
            "GOTO/-254.9779,452.7940,223.3200\n",
            2,
            "NURBS/",
        ),
        (  # HumMan/CLSFProcessor, samples/_2_KONTUR_VNUT_40_N2.cls: a helix of two turns
            "GOTO/1269.5920,-420.1821,471.0000\nCIRCLE/1287.5000,-422.0000,466.0000,0.0000000,0.0000000,"
            "-1.0000000,18.0000,0.0600,0.5000,40.0000,1.0000,TIMES,2\nGOTO/1287.4886,-440.0000,466.0000\n",
            2,
            "TIMES",
        ),
    ],
    ids=["nurbs", "circle-times"],
)
def test_nx_motion_ncpp_cannot_follow_is_refused_at_its_line(excerpt, line, says):
    """Passed through as comments, these would leave their moves out of the program."""
    with pytest.raises(NcppError) as err:
        posted("FEDRAT/MMPM,250.0000\n" + excerpt)
    assert f"part.cls:{line + 1}:" in str(err.value) and says in str(err.value)


def test_solidworks_cycle_init_is_no_cycle():
    """SolidWorks CAM writes `CYCLE/INIT` before each cycle (aamorim1913/AptPostProcessor,
    parts-2025/Paralelipipedo-furos.apt): no machine function, the cycle after it is posted."""
    text = (
        "RAPID/\nGOTO/8.,15.,25.\nCYCLE/INIT\nCYCLE/DRILL,FEDTO,7.85788,MMPM,326.770115,RAPTO,3.,RTRCTO,25.\n"
    )
    program = posted(text + "GOTO/8.,15.,0\nCYCLE/OFF\n")
    assert "G98 G81 X8. Y15. Z-7.8579 R3." in program.replace("  ", " ")


def test_a_repeated_point_on_an_arc_adds_no_turn(tmp_path):
    """A GOTO repeating the last point of an arc (CAM systems repeat points where they join
    segments) adds nothing: the quarter circle stays a quarter circle."""
    text = """FEDRAT/MMPM,500
GOTO/10,0,0
CIRCLE/0,0,0,0,0,1,10
GOTO/0,10,0
GOTO/0,10,0
GOTO/-10,0,0
"""
    calls = canon(tmp_path, text)
    (arc,) = arcs(calls)
    assert sweep((10.0, 0.0), arc) == pytest.approx(180.0, abs=1e-3)


def test_gohome_without_a_home_is_refused():
    """APT's GOHOME returns to the FROM point; without one (and without NX's x, y, z) the post
    cannot know where the tool goes, and left out the move home would be missing."""
    with pytest.raises(NcppError, match="GOHOME without a FROM point") as err:
        posted("RAPID\nGOTO/10,0,50\nGOHOME\nGOTO/0,0,50\n")
    assert "part.cls:3:" in str(err.value)


def test_insert_text_no_control_reads_becomes_a_comment(tmp_path):
    """SolidWorks CAM puts tool descriptions and operator notes into `INSERT/` (aamorim1913/
    AptPostProcessor, parts-2021/basemach.apt); APT's INSERT text that is a block stays a block."""
    text = """UNIT/MM
INSERT/8MM CRB 2FL 20 LOC
LOAD/TOOL,1
RAPID/
GOTO/46.615938,92.030152,25.
INSERT/STOP  change fixture
INSERT/M1
RAPID/
GOTO/17.969848,33.384062,25.
FINI
"""
    program = posted(text).splitlines()
    assert "(8MM CRB 2FL 20 LOC)" in program and "(STOP  change fixture)" in program and "M1" in program
    ends = end_points(canon(tmp_path, text))
    assert ends[-1] == pytest.approx((17.969848, 33.384062, 25.0), abs=1e-4)


SOLIDWORKS_DRILL = """PARTNO/1
UNIT/MM
INSERT/[HOLDER=C40-32ERP412] 14MM X 60DEG HSS CENTERDRILL
LOAD/TOOL,1
SPINDL/4948,RPM,CLW
RAPID/
GOTO/8.,15.,25.
CYCLE/INIT
CYCLE/DRILL,FEDTO,7.85788,MMPM,326.770115,RAPTO,3.,RTRCTO,25.,DWELL,0
GOTO/8.,15.,0
GOTO/27.,15.,0
GOTO/43.,15.,-38.
CYCLE/OFF
FINI
"""


def test_solidworks_drill_cycle_depth_and_retract(tmp_path):
    """SolidWorks CAM's `CYCLE/DRILL, FEDTO, d, ..., RAPTO, r, RTRCTO, v` (aamorim1913/
    AptPostProcessor, parts-2025/Paralelipipedo-furos.apt; a hole 38 below as in
    parts-2024/Suporte-parede-side-drill.apt, whose RTRCTO there is 63): each hole drilled `d`
    below its top from `r` above it, and left at the level the cycle started from."""
    text = SOLIDWORKS_DRILL.replace("GOTO/43.,15.,-38.\n", "")
    ends = end_points(canon(tmp_path, text))
    for x in (8.0, 27.0):
        assert (x, 15.0, -7.85788) in [pytest.approx(e, abs=1e-4) for e in ends]
    assert ends[-1] == pytest.approx((27.0, 15.0, 25.0), abs=1e-4)
    with pytest.raises(NcppError, match=r"RTRCTO, 25 retracts to -13, not to the level") as err:
        posted(SOLIDWORKS_DRILL)
    assert "part.cls:9:" in str(err.value)


def test_solidworks_variable_peck_cycle_is_refused_by_name():
    """SolidWorks CAM's `CYCLE/DEEP2` pecks `1STPECK` first and `SUBPECK` after (aamorim1913/
    AptPostProcessor, parts-2024/Suporte-parede-side-drill.apt): no one canned cycle does that;
    the record is read (a word may start with digits) and refused by its cycle's name."""
    text = "RAPID/\nGOTO/20.,125.,25.\nCYCLE/DEEP2,FEDTO,5.03163,1STPECK,5.,SUBPECK,2.,MMPM,382.27,RAPTO,3.\n"
    with pytest.raises(NcppError, match=r"part\.cls:3:1: CYCLE/DEEP2: ncpp posts the cycles"):
        posted(text + "GOTO/20.,125.,0\nCYCLE/OFF\n")


@pytest.mark.parametrize("dialect", ["heidenhain", "sinumerik", "fanuc"])
def test_insert_descriptions_are_comments_in_every_dialect(dialect):
    """The Heidenhain parser refuses what it cannot read where the ISO one marks it: either way
    SolidWorks CAM's tool description (aamorim1913/AptPostProcessor, parts-tools/boss.apt) is a comment."""
    text = "UNIT/MM\nINSERT/[HOLDER=C40-M06EM2] 6MM CRB 2FL 19 LOC\nLOAD/TOOL,1\nRAPID/\nGOTO/89.2375,5.7625,25.\n"
    program = posted(text, dialect=dialect)
    assert any(
        "6MM CRB 2FL 19 LOC" in line and line != "[HOLDER=C40-M06EM2] 6MM CRB 2FL 19 LOC"
        for line in program.splitlines()
    )
