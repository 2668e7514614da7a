"""The verifier judges a written program against the original by their motion and actions.

Each test hands `verify` a program and a rewritten one by hand (no compensation runs):
what the verifier must let through (corrections within the bound) and what it must stop.
"""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pytest

from ncpp.errors import NcppError
from ncpp.verify import ROUNDING, Bound, Following, verify

ORIGINAL = """\
G21 G90 G17
T1 M6
S1000 M3
G0 X0 Y0 Z5
G1 Z-1 F200
X50 Y0
G2 X60 Y10 I0 J10
G1 Y40 F400
G0 Z5
M5
M30
"""


def check(original: str, written: str, bound: float = 0.05, dialect: str = "iso") -> int:
    return verify(io.BytesIO(original.encode()), io.BytesIO(written.encode()), file="part.ngc", dialect=dialect,
                  offsets=None, bound=Bound(bound))  # fmt: skip


def refused(original: str, written: str, bound: float = 0.05) -> NcppError:
    with pytest.raises(NcppError) as caught:
        check(original, written, bound)
    return caught.value


def test_the_same_program_passes():
    assert check(ORIGINAL, ORIGINAL) >= 4  # sections: between T1, M6, S1000, M3, M5, M30


def test_corrections_within_the_bound_and_pieces_pass():
    written = ORIGINAL.replace("X50 Y0", "X25.01 Y0.01\nX50.02 Y0.01").replace(
        "G1 Y40 F400", "G1 Y40.02 F400"
    )
    check(ORIGINAL, written)


def test_a_point_beyond_the_bound_is_refused_at_its_line():
    err = refused(ORIGINAL, ORIGINAL.replace("X50 Y0", "X50 Y0.2"))
    assert err.where.line == 6 and "leaves" in err.message


def test_a_following_bound_is_the_largest_correction_made_plus_the_tolerance():
    """A compensating run's bound (`Following`): corrections of 0.01 mm made, tolerance 0.001 mm;
    at most the machine file's max_correction_mm plus the tolerance."""
    made = [0.01]
    bound = Following(0.501, 0.001, lambda: made[0])
    assert bound().distance == pytest.approx(0.01 + 0.001 + ROUNDING)
    # (and the arc after it, in chords of the bound)
    check_with(ORIGINAL, ORIGINAL.replace("X50 Y0", "X50 Y0.01"), bound)
    with pytest.raises(NcppError) as caught:
        check_with(ORIGINAL, ORIGINAL.replace("X50 Y0", "X50 Y0.05"), bound)
    within = 1.25 * bound().distance  # (the chords')
    assert caught.value.where.line == 6 and f"by more than {within:.4f} mm" in caught.value.message
    made[0] = 2.0
    assert bound().distance == 0.501
    check_with(ORIGINAL, ORIGINAL.replace("X50 Y0", "X50 Y0.4"), bound)


def check_with(original: str, written: str, bound: Following) -> int:
    return verify(io.BytesIO(original.encode()), io.BytesIO(written.encode()), file="part.ngc", dialect="iso",
                  offsets=None, bound=bound)  # fmt: skip


def test_a_missing_move_is_refused():
    err = refused(ORIGINAL, ORIGINAL.replace("G1 Y40 F400\n", "F400\n"))
    assert err.where.line in (7, 8, 9)


def test_an_action_moved_along_the_path_is_refused():
    written = (
        ORIGINAL.replace("M5\n", "")
        .replace("G0 Z5\nM30", "G0 Z5\nM5\nM30")
        .replace("G1 Y40 F400", "G1 Y40 F400 M5")
    )
    err = refused(ORIGINAL, written)  # the path before M5 is not the original's
    assert err.where.line in (8, 9, 10)


def test_a_changed_action_is_refused():
    err = refused(ORIGINAL, ORIGINAL.replace("S1000 M3", "S1000 M4"))
    assert "'M4'" in err.message and "'M3'" in err.message and err.where.line == 3


def test_a_changed_feed_rate_is_refused():
    err = refused(ORIGINAL, ORIGINAL.replace("F400", "F401"))
    assert "401" in err.message and err.where.line == 8


def test_a_rapid_where_the_original_cuts_is_refused():
    err = refused(ORIGINAL, ORIGINAL.replace("X50 Y0", "G0 X50 Y0\nG1"))
    assert "rapid" in err.message


def test_a_feed_where_the_original_rapids_is_refused():
    err = refused(ORIGINAL, ORIGINAL.replace("G0 Z5\nM5", "G1 Z5\nM5"))
    assert "feed move where the original rapids" in err.message


def test_the_wrong_arc_direction_is_refused():
    err = refused(ORIGINAL, ORIGINAL.replace("G2 X60", "G3 X60"))
    assert err.where.line == 7


def test_a_rotation_carried_by_one_piece_is_refused():
    original = "G21 G90\nG0 X0 Y0 Z0 A0\nG1 X10 A90 F100\nM2\n"
    pieces = "G21 G90\nG0 X0 Y0 Z0 A0\nG1 X5 A45 F100\nX10 A90\nM2\n"
    check(original, pieces)
    err = refused(original, "G21 G90\nG0 X0 Y0 Z0 A0\nG1 X0.001 A90 F100\nX10\nM2\n")
    assert err.where.line == 3


def test_inverse_time_pieces_share_the_moves_time():
    original = "G21 G90\nG0 X0 Y0 Z0\nG93 G1 X10 F2\nG94\nM2\n"
    check(original, "G21 G90\nG0 X0 Y0 Z0\nG93 G1 X5 F4\nX10 F4\nG94\nM2\n")
    err = refused(original, "G21 G90\nG0 X0 Y0 Z0\nG93 G1 X5 F2\nX10 F2\nG94\nM2\n")
    assert "inverse-time" in err.message


def test_a_written_program_ncpp_cannot_read_is_refused_with_its_text():
    err = refused(ORIGINAL, ORIGINAL.replace("X50 Y0", "G28 G0 X50 Y0"))
    assert "G28 G0 X50 Y0" in err.message


def test_a_written_program_that_ends_early_is_refused():
    err = refused(ORIGINAL, ORIGINAL.replace("M5\nM30\n", ""))
    assert "M5" in err.message


def test_units_are_compared_in_mm():
    inch = ORIGINAL.replace("G21", "G20")
    check(inch, inch.replace("X50 Y0", "X50.0008 Y0"))  # 0.02 mm
    err = refused(inch, inch.replace("G1 Y40", "G1 X60.004 Y40"))  # 0.1 mm
    assert err.where.line == 8


def test_heidenhain_tool_calls_are_actions():
    original = (
        "0 BEGIN PGM P MM\n1 TOOL CALL 1 Z S2000\n2 L X+0 Y+0 Z+5 R0 FMAX M3\n3 L Z-1 F200\n"
        "4 L X+50\n5 TOOL CALL 2 Z S3000\n6 L X+0\n7 END PGM P MM\n"
    )
    check(original, original, dialect="heidenhain")
    with pytest.raises(NcppError) as caught:
        check(original, original.replace("TOOL CALL 2 Z S3000", "TOOL CALL 3 Z S3000"), dialect="heidenhain")
    assert "TOOLCALL3" in caught.value.message


def test_a_helix_of_a_thousand_turns_in_one_place_is_verified(tmp_path, capsys):
    """Its segments lie over one another a thousand times: each is proven along the turn its
    ends lie near, and the program is written."""
    from ncpp.cli import main

    path = tmp_path / "helix.ngc"
    path.write_text("G17 G21 G90\nG0 X0 Y0 Z0\nG2 X0 Y0 I10 J0 Z1 P1000 F100\nM2\n")
    machine = str(Path(__file__).resolve().parents[2] / "samples/machines/hr5b.toml")
    out = tmp_path / "out.ngc"
    assert (
        main(["compensate", "--machine", machine, "--work-offset", "400,350,300", str(path), "-o", str(out)])
        == 0
    )
    assert out.exists() and "verification" not in capsys.readouterr().err


def test_a_path_over_itself_too_often_is_refused_with_a_way_out(monkeypatch):
    """A ring of a thousand short segments, and a written path that also runs into its middle:
    the points there have every segment of the ring within the lookup's reach, looked at one by
    one; past `LOOKED_AT` the verifier says so at the line, rather than pass it unseen."""
    from ncpp.verify import _Nearby

    monkeypatch.setattr(_Nearby, "LOOKED_AT", 500)
    ring = "".join(
        f"X{0.1 * math.cos(a):.5f} Y{0.1 * math.sin(a):.5f}\n" for a in np.linspace(0, 2 * math.pi, 1001)
    )
    original = f"G21 G90 G17\nG0 X0.1 Y0 Z5\nG1 Z-1 F200\n{ring}M30\n"
    err = refused(original, original.replace("M30", "X0 Y0\nX0.1 Y0\nM30"))
    assert "lies over itself too often" in err.message and "--no-verify" in err.message and err.where.line


LOOP = """G21 G90 G17
G0 X0 Y0 Z5
G1 Z-1 F200
o100 repeat [500]
G1 X50 Y0
G1 X50 Y{y}
G1 X0 Y0
o100 endrepeat
M2
"""


def test_a_loop_is_verified_run_by_run():
    """Five hundred runs of one body: each distinct segment is looked up once, and a body
    that leaves the path is refused all the same."""
    assert check(LOOP.format(y=20), LOOP.format(y=20.04)) >= 1
    assert "verification" in str(refused(LOOP.format(y=20), LOOP.format(y=20.2)))


def test_equal_segments_are_looked_up_once():
    from ncpp.verify import _first_of_each

    starts = np.array([[0.0, 0, 0], [1, 0, 0], [0, 0, 0], [2, 0, 0], [1, 0, 0]])
    ends = np.array([[1.0, 0, 0], [2, 0, 0], [1, 0, 0], [3, 0, 0], [2, 0, 0]])
    assert _first_of_each(starts, ends).tolist() == [0, 1, 3]


CORNER = """\
G21 G90 G17
G0 X0 Y0 Z5
G1 Z-1 F200
X10 Y0
{corner}X10 Y10
M30
"""


@pytest.mark.parametrize("cut", [0.06, 0.3])
def test_a_segment_across_a_corner_is_judged_by_its_middle(cut):
    """Both ends of the written segment lie on the original path, one each side of its corner:
    its middle lies cut / 2 from the path, within the bound (0.0625 mm with the chords) or not.
    The written path comes back to the corner, so the original's points all lie on it."""
    written = CORNER.format(corner=f"X{10 - cut:g} Y0\nX10 Y{cut:g}\nX10 Y0\n")
    if cut / 2 <= Bound(0.05).within:
        check(CORNER.format(corner=""), written)
    else:
        assert "leaves" in refused(CORNER.format(corner=""), written).message


def test_a_segment_across_a_turn_of_several_segments_is_judged_by_its_middle():
    """The original turns back 0.2 mm over (two segments); the written program runs along all of
    it, and once straight across the turn from the first segment to the third: both ends of that
    segment lie on the original path, its middle 0.1 mm from it."""
    original = "G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F200\nX10 Y0\nX10 Y0.2\nX0 Y0.2\nM30\n"
    written = original.replace("X10 Y0.2\n", "X5 Y0\nX5 Y0.2\nX10 Y0.2\nX10 Y0\nX10 Y0.2\n")
    check(original, original.replace("X10 Y0.2\n", "X5 Y0\nX5 Y0.02\nX5 Y0\nX10 Y0\nX10 Y0.2\n"))
    assert "leaves" in refused(original, written).message


def test_what_the_prefilter_proves_lies_within_the_bound_along_its_length():
    """Random zigzags with gaps, and paths near them whose segments span up to a few of theirs:
    every segment the prefilter sets aside as proven lies within the bound at every point (by
    brute force), and the prefilter proves many of them."""
    from ncpp.verify import _Nearby, _to_segments

    bound = Bound(0.05)
    within = bound.within
    rng = np.random.default_rng(7)
    proven_share = []
    for _ in range(8):
        turns = rng.normal(0.0, 1.0, (200, 3)) * np.array([0.3, 0.3, 0.05])
        path = np.hstack((np.cumsum(turns, axis=0), np.zeros((200, 1))))  # (the kinds' column: all feeds)
        kept = np.arange(199) % 17 != 8  # segments left out: the path jumps there
        a, b = path[:-1][kept], path[1:][kept]
        picked = np.sort(rng.choice(len(path), 80, replace=False))
        points = path[picked] + rng.normal(0.0, within / 2, (80, 4)) * np.array([1, 1, 1, 0])
        starts, ends = points[:-1], points[1:]
        proven = _Nearby(a, b, bound)._along_the_nearest(starts, ends, within)
        proven_share.append(proven.mean())
        t = np.linspace(0.0, 1.0, 65)[:, None, None]
        samples = (starts[proven] + t * (ends[proven] - starts[proven])).reshape(-1, 4)
        shape = (len(samples), len(a), 4)
        distance, _ = _to_segments(samples, np.broadcast_to(a, shape), np.broadcast_to(b, shape))
        assert distance.min(axis=1).max() <= within + 1e-12
    assert np.mean(proven_share) > 0.2
