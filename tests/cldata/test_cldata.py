"""APT CL data reader and motion events, on the corpus CL files and small cases."""

from __future__ import annotations

import io
import math
from pathlib import Path

import pytest

from ncpp.cldata import motion, read_cldata
from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import PLANE_AXES, Arc, Line, Pass

CORPUS = Path("/work/shared/corpus/apt_cldata")
if not CORPUS.exists():
    CORPUS = Path(__file__).resolve().parents[3] / "shared/corpus/apt_cldata"
CL_FILES = sorted(p for p in CORPUS.rglob("*") if p.is_file())


def events_of(text: str, warnings: Warnings | None = None):
    return list(motion(read_cldata(io.StringIO(text), "t.cls"), warnings))


def goto_points(path: Path):
    return [r.numbers[:3] for r in read_cldata(path.open(), str(path)) if r.major == "GOTO"]


def test_corpus_is_there():
    assert len(CL_FILES) >= 4


@pytest.mark.parametrize("path", CL_FILES, ids=lambda p: p.name)
def test_corpus_file_reads_and_moves_where_the_gotos_say(path):
    events = list(motion(read_cldata(path.open(), str(path)), Warnings(stream=io.StringIO())))
    moves = [e for e in events if not isinstance(e, Pass)]
    gotos = goto_points(path)
    assert moves and gotos
    assert moves[0].end == pytest.approx(gotos[0]) if isinstance(moves[0], Line) else True
    from_gotos = [e for e in moves if e.block.raw.lstrip().upper().startswith(("GOTO", "CIRCLE"))]
    assert from_gotos[-1].end == pytest.approx(gotos[-1])
    # Continuity: every move starts where the previous one ended.
    for a, b in zip(moves, moves[1:]):
        assert b.start == pytest.approx(a.end)
    for arc in (e for e in moves if isinstance(e, Arc)):
        i, j, _ = PLANE_AXES[arc.context.plane]
        end_radius = math.hypot(arc.end[i] - arc.center[i], arc.end[j] - arc.center[j])
        assert abs(end_radius - arc.radius()) <= 1e-3  # 1 um
        # The Creo 7-value CIRCLE's last value is the radius.
        circle = [float(v) for v in arc.block.raw.replace("$", "").split("/", 1)[1].split(",")]
        assert arc.radius() == pytest.approx(circle[6], abs=1e-3)


def test_creo_profile_arcs_turn_clockwise_about_minus_z():
    path = CORPUS / "creo_ncl/profilfraesen_2.ncl.1"
    arcs = [e for e in motion(read_cldata(path.open(), str(path))) if isinstance(e, Arc)]
    first = arcs[0]
    assert first.context.plane == 17 and first.turn == -1
    assert first.start == pytest.approx((0, 1.5, -1.5)) and first.end == pytest.approx((1.5, 0, -1.5))
    assert math.degrees(first.sweep()) == pytest.approx(-90)
    assert len(arcs) == 20


def test_continuation_and_comments():
    records = list(
        read_cldata(io.StringIO("$$ a comment $\n  still the comment\nGOTO / 1, $\n 2, 3 $$ tail\nFINI\n"))
    )
    assert [r.major for r in records] == ["$$", "GOTO", "FINI"]
    assert records[1].numbers == (1.0, 2.0, 3.0) and records[1].line == 3


NX_ARC = """UNITS/MM
FROM/0,0,50
RAPID
GOTO/10,0,0
FEDRAT/MMPM,300
CIRCLE/0,0,0,0,0,-1,10,0.01,0.5,10,0
GOTO/0,10,0
GOTO/-10,0,0
GOTO/0,-10,0
GOTO/10,0,0
GOTO/20,0,0
GOHOME
FINI
"""


def test_nx_circle_gotos_collapse_into_one_full_turn():
    # NX's 11-value CIRCLE turns clockwise about its axis: about -Z, counterclockwise in XY.
    events = events_of(NX_ARC)
    moves = [e for e in events if not isinstance(e, Pass)]
    kinds = [type(e).__name__ for e in moves]
    assert kinds == ["Line", "Arc", "Line", "Line"]
    arc = moves[1]
    assert arc.turn == 1 and arc.end == pytest.approx((10, 0, 0))
    assert math.degrees(arc.sweep()) == pytest.approx(360)
    assert moves[0].rapid and not moves[2].rapid and moves[2].feed == 300
    assert moves[3].end == (0, 0, 50) and moves[3].rapid  # GOHOME returns to FROM


def test_xz_arc_and_direction():
    events = events_of("FROM/10,0,0\nCIRCLE/0,0,0,0,1,0,10\nGOTO/0,0,10\n")
    arc = next(e for e in events if isinstance(e, Arc))
    assert arc.context.plane == 18 and arc.turn == 1
    # About +Y, a point on +X turns towards -Z: reaching +Z takes 270 degrees.
    assert abs(math.degrees(arc.sweep())) == pytest.approx(270)


def test_tilted_circle_axis_is_refused():
    with pytest.raises(NcppError, match="not along X, Y or Z") as err:
        events_of("FROM/10,0,0\nCIRCLE/0,0,0,0,0.6,0.8,10\nGOTO/0,10,0\n")
    assert err.value.where.line == 2


def test_constant_tool_vector_posts_changing_vector_is_refused():
    ok = events_of("MULTAX\nGOTO/0,0,5,0,0,1\nGOTO/10,0,5,0,0,1\n")
    assert sum(isinstance(e, Line) for e in ok) == 2
    with pytest.raises(NcppError, match="tool vector changes") as err:
        events_of("MULTAX\nGOTO/0,0,5,0,0,1\nGOTO/10,0,5,0,0.1,0.995\n")
    assert err.value.where.line == 3 and "line 2" in err.value.message


@pytest.mark.parametrize(
    "cl, line",
    [
        ("MULTAX\nGOTO/0,0,5,1,0,0\n", 2),  # a horizontal spindle
        ("MULTAX\nGOTO/0,0,5,0,0,-1\n", 2),  # the tool pointing up
        ("MULTAX\nGOTO/0,0,5,0,0,0\n", 2),  # no vector
        ("TLAXIS/0,0.6,0.8\nGOTO/0,0,5\n", 1),
    ],
)
def test_a_tool_vector_not_along_z_is_refused(cl, line):
    """A 3-axis post drives a tool along +Z: posting CL data for another tool axis as is would
    put the tool's length, and so the part, elsewhere."""
    with pytest.raises(NcppError, match="is not along [+]Z") as err:
        events_of(cl)
    assert err.value.where.line == line


def test_a_tool_vector_along_z_of_any_length_posts():
    assert (
        sum(isinstance(e, Line) for e in events_of("MULTAX\nGOTO/0,0,5,0,0,2\nTLAXIS/0,0,1\nGOTO/1,0,5\n"))
        == 2
    )


@pytest.mark.parametrize(
    "cl, line",
    [
        ("GOTO/0,0,0\nGOTO/1e308,0,0\n", 2),
        ("FROM/0,0,-1e9\n", 1),
        ("GOTO/0,0,0\nCIRCLE/1e200,0,0,0,0,1,5\nGOTO/5,0,0\n", 2),
    ],
)
def test_a_coordinate_no_nc_word_holds_is_refused(cl, line):
    """GOTO / 1e308 was posted as an X word of 309 digits."""
    with pytest.raises(NcppError, match="a coordinate beyond ±99,999,999") as err:
        events_of(cl)
    assert err.value.where.line == line


def test_vendor_words_pass_with_a_warning():
    out = io.StringIO()
    events = events_of((CORPUS / "rybakov25/test.apt").read_text(), Warnings(stream=out))
    warned = out.getvalue()
    for word in ("CYCLE81", "CALLSUB", "TLCOMP"):
        assert f"{word}/ is not understood" in warned
    assert "DELAY/" not in warned  # a dwell (ncpp.post)
    assert any(isinstance(e, Pass) and e.block.raw.startswith("CYCLE83") for e in events)


def test_bad_record_names_its_line():
    with pytest.raises(NcppError) as err:
        events_of("UNITS/MM\nGOTO/1,2,3\nGOTO/1,#2,3\n")
    assert err.value.where.line == 3


def test_gohome_with_axis_words_moves_only_those_axes():
    path = CORPUS / "rybakov25/test.apt"
    moves = [e for e in motion(read_cldata(path.open(), str(path))) if isinstance(e, Line)]
    assert moves[-1].block.raw.startswith("GOHOME")
    assert moves[-1].start == (150, 150, 0) and moves[-1].end == (150, 150, 100)


SETUP = """UNIT/MM
TRNTYP/WORLD,0,0,0
CSYS/{}
RAPID/
GOTO/10.,20.,25.
FEDRAT/500.,MMPM
GOTO/10.,20.,-1.
GOTO/30.,20.,-1.
"""


def test_a_turned_setup_csys_is_refused_and_the_identity_posts():
    """SolidWorks CAM writes each operation's setup as `CSYS/` (aamorim1913/AptPostProcessor,
    parts-2022/shimemcunha.apt: `CSYS/0,.999987,.005061,0,-1.,0,0,0,0,-0.005061,.999987,0`, its GOTO tool
    vector the setup's Z in the part's frame).  A setup turned 90 degrees about Z keeps the tool along +Z:
    posted untransformed its points land turned by 90 degrees on the machine."""
    turned = "0,1.,0,0,-1.,0,0,0,0,0,1.,0"
    with pytest.raises(NcppError, match="CSYS/ places the GOTO points") as err:
        events_of(SETUP.format(turned))
    assert err.value.where.line == 3
    moves = [e for e in events_of(SETUP.format("1.,0,0,0,0,1.,0,0,0,0,1.,0")) if isinstance(e, Line)]
    assert [m.end for m in moves] == [(10.0, 20.0, 25.0), (10.0, 20.0, -1.0), (30.0, 20.0, -1.0)]
