"""Canned cycles (G73 G74 G81-G87 G89) against LinuxCNC's rs274, and in compensation.

The corpus has LinuxCNC's own G81 tests (three planes, G98 and G99, run by
test_oracle.py); these cover the other cycles, sticky words, repeats,
incremental mode, inch pecks, the spindle the tapping and boring cycles
need, and the errors rs274 stops at.
"""

from __future__ import annotations

import io
import random
import re

import pytest

from ncpp.errors import Location, NcppError, Warnings
from ncpp.motion import interpret
from ncpp.motion.fanuc import interpret as interpret_fanuc
from ncpp.motion.segments import HOLE, Line
from ncpp.program.parser import parse_stream
from tests.compensation.accuracy import rs274_calls
from tests.conftest import RS274
from tests.motion.compensating import compensate
from tests.motion.test_oracle import (
    assert_agrees_with_rs274,
    assert_refused_like_rs274,
    ours,
    read_canon,
    rs274,
    rs274_error,
    same_calls,
    write_program,
)

HEAD = "G21 G90 G17 G54\nG0 X0 Y0 Z10 F200\n"

AGREE = {
    "g81 g98 series": HEAD + "G98 G81 X10 Y5 Z-3 R2\nX20\nY15\nG80\nG0 X0\n",
    "g99 from below r": "G21 G90\nG0 X1 Y1 Z1 F100\nG99 G81 X5 Y5 Z-3 R2\nX6\nM2\n",
    "g82 dwell, g85, g89": HEAD
    + "G99 G82 X1 Y1 Z-3 R2 P0.5\nX2\nG98 G85 X3 Z-4 R2\nG89 X4 Z-3 R2 P1\nX5\nG80\n",
    "g83 peck, sticky q": HEAD + "G83 X1 Y1 Z-7 R1 Q2.5\nX2 Q1.5\nX3 Z-2\nG80\n",
    "g73 chip break": HEAD + "G98 G73 X5 Y1 Z-3 R2 Q1\nX6\nG80\n",
    "inch peck": "G20 G90\nG0 X0 Y0 Z1 F10\nG83 X1 Y1 Z-0.3 R0.1 Q0.1\nG80\n",
    "incremental repeats": HEAD
    + "G0 Z1\nG91 G81 X5 Y5 Z-3 R2 L3\nG90 G80\nG0 X0 Y0\nG91 G98 G83 X-2 Z-4 R3 Q1.5 L2\nG90 G80\n",
    "absolute repeats": HEAD + "G81 X3 Y3 Z-1 R0.5 L2\nG80\n",
    "g18 and g19": HEAD + "G18 G98 G81 X1 Z1 Y-3 R2\nG19 G83 Y1 Z1 X-3 R2 Q1\nG17 G80\n",
    "a series across cycles": HEAD
    + "G98 G81 X1 Y1 Z-3 R2\nG99 G83 X2 Z-3 R1 Q1\nG98 G82 X3 Z-3 R2 P1\nG80\n",
    "arcs after a cycle": HEAD
    + "G81 X10 Y10 Z-2 R1\nG0 X20\nG1 Z-1\nG2 X30 Y20 I10 J0\nG3 X20 Y10 R10\nM2\n",
    "tapping and boring": HEAD
    + "S500 M3\nG99 G84 X1 Y1 Z-3 R2\nX2\nG98 G86 X3 Z-3 R2 P1\nG87 X4 Y4 Z-5 R2 I1 J0 K-3\nX6\nG80\nM4\nG74 X5 Y5 Z-2 R1\nG80\nM5\n",
    "incremental back bore, g18 boring": HEAD
    + "M3\nG91 G87 X1 Y1 Z-3 R2 I1 J1 K1 L2\nG90 G80\nG18 G86 X1 Z1 Y-3 R2 P1\nG17 G80\n",
    # G87 in G18 and G19: I J K offset X Y Z, the normal's letter is the top of the bore
    "back bore in g18 and g19": HEAD + "M3\nG18 G98 G87 X1 Z1 Y-3 R2 I0.5 J-1 K-0.7\nX2\nG80\n"
    "G19 G99 G87 Y1 Z2 X-3 R2 I-1.5 J0.4 K0.6\nG91 G87 Y1 R-1 X-2 I1 L2\nG90 G80 G17\n",
    # the levels a series crosses at and retracts to (found by probing rs274)
    "g99 series changing r": "G21 G90\nG0 X0 Y0 Z7.077 F100\nG89 G99 X1 Y-1 R1.541 Z-2.5 P0.3\nG83 X-3 Y-1 R2.271 Z-1.2 Q1.2\nX-2 R1\nM2\n",
    "g98 after g99, higher r": "G21 G90\nG0 X0 Y0 Z10 F100\nG99 G81 X1 Z-3 R2\nG98 G82 X3 Z-3 R5 P1\nX4\nM2\n",
    "g98 series from below r": "G21 G90\nG0 X0 Y0 Z1 F100\nG98 G81 X1 Z-3 R2\nG82 X3 Z-3 R2 P1\nX4\nM2\n",
    # a G98 series lowering its R plane retracts to where it started (above R) or to R (below)
    "g98 series lowering r": HEAD + "G98 G81 X1 Y1 Z-3 R2\nG82 X2 Z-3 R1 P1\nG80\nG0 Z6\n"
    "G98 G81 X3 R5 Z-3\nX4 R7\nX5 R5.5\nX6 R3.5\nG80\nG0 Z1\nG98 G81 X7 R5 Z-5\nX8 R4\nX9 R4.5\nG80\n",
}

OUT_OF_SCOPE = {
    "tapping in g18": (HEAD + "M3 G18\nG84 X1 Z1 Y-3 R2\n", 4, "G84 outside the XY plane"),
    "manual retract": (HEAD + "M3\nG88 X1 Y1 Z-3 R2 P1\n", 4, "canned cycle G88"),
}

REFUSED = {
    "r missing": (HEAD + "G81 X1 Y1 Z-3\n", 3),
    "r not sticky across cycles": (HEAD + "G81 X1 Y1 Z-3 R2\nG82 X2 P1\n", 4),
    "z missing": (HEAD + "G81 X1 Y1 R2\n", 3),
    "r below z": (HEAD + "G81 X1 Y1 Z3 R2\n", 3),
    "y missing in g18": (HEAD + "G18 G81 X1 Z1 R2\n", 3),
    "zero repeats": (HEAD + "G81 X1 Y1 Z-3 R2 L0\n", 3),
    "negative repeats": (HEAD + "G81 X1 Y1 Z-3 R2 L-2\n", 3),
    "fractional repeats": (HEAD + "G81 X1 Y1 Z-3 R2 L2.5\n", 3),
    "zero feed": ("G21 G90\nG0 Z1\nG81 X1 Y1 Z-3 R2\n", 3),
    "inverse time": (HEAD + "G93 G81 X1 Y1 Z-3 R2\n", 3),
    "p missing": (HEAD + "G82 X1 Y1 Z-3 R2\n", 3),
    "q missing": (HEAD + "G73 X1 Y1 Z-3 R2\n", 3),
    "axes with g80": (HEAD + "G81 X1 Y1 Z-3 R2\nG80 X2\n", 4),
    "tapping, spindle stopped": (HEAD + "G84 X1 Y1 Z-3 R2\n", 3),
    "right-hand tap, spindle reversed": (HEAD + "M4\nG84 X1 Y1 Z-3 R2\n", 4),
    "left-hand tap, spindle forward": (HEAD + "M3\nG74 X1 Y1 Z-3 R2\n", 4),
    "boring, spindle oriented": (HEAD + "M3\nM19\nG86 X1 Y1 Z-3 R2 P1\n", 5),
    "back bore without j": (HEAD + "M3\nG87 X1 Y1 Z-3 R2 I1 K-1\n", 4),
    "boring without p": (HEAD + "M3\nG86 X1 Y1 Z-3 R2\n", 4),
}


@pytest.mark.parametrize("name", AGREE)
def test_cycles_move_as_rs274_does(tmp_path, name):
    assert_agrees_with_rs274(write_program(tmp_path, AGREE[name], "cycle.ngc"))


@pytest.mark.parametrize("name", REFUSED)
def test_cycles_refused_where_rs274_refuses(tmp_path, name):
    text, line = REFUSED[name]
    assert_refused_like_rs274(write_program(tmp_path, text, "cycle.ngc"), line)


@pytest.mark.parametrize("name", OUT_OF_SCOPE)
def test_cycles_out_of_scope(name):
    text, line, reason = OUT_OF_SCOPE[name]
    warned = io.StringIO()
    list(
        interpret(
            parse_stream(io.BytesIO(text.encode()), "t.ngc"), file="t.ngc", warnings=Warnings(stream=warned)
        )
    )
    assert f"t.ngc:{line}:" in warned.getvalue() and reason in warned.getvalue(), warned.getvalue()


@pytest.mark.parametrize(
    "plane, block, moves",
    [(18, "G84 X1 Z2 Y-3 R2", [(1, 5, 2, True), (1, 2, 2, True), (1, -3, 2, False), (1, 2, 2, False)]),
     (19, "G84 Y1 Z2 X-3 R2", [(5, 1, 2, True), (2, 1, 2, True), (-3, 1, 2, False), (2, 1, 2, False)])],
    ids=["G18", "G19"],
)  # fmt: skip
def test_fanuc_taps_in_g18_and_g19_feed_along_the_planes_normal(plane, block, moves):
    """Fanuc drills along the axis normal to the plane, and taps so too (G18 Y, G19 X): over the hole
    at the level it stands at, down to R, a feed to the bottom and one back out to R (G99), as holes
    compensation corrects; where rs274ngc's taps feed other axes (LinuxCNC's stay out of scope)."""
    text = f"G21 G90 G{plane}\nG0 X5 Y5 Z5\nM3 S500\nG99 {block} F100\nG80\nM30\n"
    warned = io.StringIO()
    events = interpret_fanuc(parse_stream(io.BytesIO(text.encode()), "t.nc"), file="t.nc",
                             warnings=Warnings(stream=warned))  # fmt: skip
    holes = [e for e in events if type(e) is Line and e.fixed == HOLE]
    assert [(*e.end[:3], e.rapid) for e in holes] == moves and not warned.getvalue()


def test_rs274_taps_in_g18_and_g19_feed_other_axes(tmp_path):
    """Why LinuxCNC's taps outside G17 stay out of scope: rs274 feeds a G18 tap over X Y Z to the Y,
    Z and X words (the bottom on X), and a G19 one to the Z, X and Y words, not along the normal."""
    text = HEAD + "M3\nG18 G84 X1 Z2 Y-3 R4\nG80\nG19 G84 Y5 Z6 X-7 R8\nG80 G17\n"
    feeds = [args[:3] for name, args in rs274_calls(write_program(tmp_path, text, "taps.ngc"))
             if name == "STRAIGHT_FEED"]  # fmt: skip
    assert feeds == [[-3, 2, 1], [4, 2, 1], [6, -7, 5], [6, 8, 5]]


def _random_program(rng: random.Random) -> str:
    """Cycles of every kind with random words, repeats, G91, G98/G99 and plane changes."""
    lines, plane = (
        [rng.choice(["G21", "G20"]) + " G90 G17", f"G0 X0 Y0 Z{rng.uniform(-2, 12):.3f} F100", "M3"],
        17,
    )
    for _ in range(rng.randint(2, 7)):
        if rng.random() < 0.2:
            extra = rng.choice(
                ["G80", "G0 X1 Y-2", "G80 G0 Z4", "G90", "G91", "G98", "G99", "G80 G18", "G80 G19", "G80 G17"]
            )
            plane = {"G80 G18": 18, "G80 G19": 19, "G80 G17": 17}.get(extra, plane)
            lines.append(extra)
            continue
        code = rng.choice(
            ["G73", "G81", "G82", "G83", "G85", "G86", "G87", "G89"] + (["G84"] if plane == 17 else [])
        )
        normal = {17: "Z", 18: "Y", 19: "X"}[plane]
        top = "IJK"["XYZ".index(normal)]
        incremental, r = rng.random() < 0.3, rng.uniform(0, 4)
        words = [code, rng.choice(["", "G98", "G99"]), "G91" if incremental else "G90"]
        words += [a + f"{rng.uniform(-5, 5):.3f}" for a in "XYZ" if a != normal and rng.random() < 0.8]
        words.append(f"R{rng.uniform(-1, 3) if incremental else r:.3f}")
        words.append(normal + f"{-rng.uniform(0.5, 5) if incremental else r - rng.uniform(0.5, 6):.3f}")
        words += {
            "G73": ["Q0.9"],
            "G83": ["Q1.3"],
            "G82": ["P0.2"],
            "G86": ["P0.2"],
            "G89": ["P0.2"],
            # (the normal's letter is the top of the bore: `_back_bore_words`)
            "G87": [f"{letter}{rng.uniform(-1, 1):.3f}" for letter in "IJK" if letter != top]
            + [top + ("0.5" if incremental else "-1")],
        }.get(code, [])
        if rng.random() < 0.25:
            words.append(f"L{rng.randint(1, 3)}")
        lines.append(" ".join(w for w in words if w))
        lines += [
            " ".join(a + f"{rng.uniform(-5, 5):.3f}" for a in "XYZ" if a != normal)
            for _ in range(rng.randint(0, 2))
        ]
    return "\n".join(lines + ["M2"]) + "\n"


def test_random_cycle_programs_agree_with_rs274(tmp_path):
    """40 random programs: in scope ones move as rs274 does, refused ones on the same line."""
    rng, compared = random.Random(20261122), 0
    for n in range(40):
        text = _random_program(rng)
        path = tmp_path / f"random{n}.ngc"
        path.write_text(text)
        calls, messages = rs274(str(path))
        reference, refused = read_canon(calls), rs274_error(messages)
        mine, error, warning = ours(path)
        assert same_calls(reference, mine), text
        if warning:
            continue
        if refused is None:
            assert error is None and len(mine) == len(reference), (text, error)
            compared += 1
        else:
            assert (
                error is not None and text.splitlines()[error.where.line - 1].strip() == refused[1].strip()
            ), (text, refused, error)
    assert compared >= 10  # enough programs stay in scope to mean something


@pytest.mark.parametrize("cycle, why, holes", [("G81 X1 Y1 Z-3 R2", HOLE, 1), ("G81 X1 Y1 Z-3 R2 L1", HOLE, 1),
                                               ("G81 X1 Y1 Z-3 R2 L2", HOLE, 2), ("G91 G81 X1 Y1 Z-3 R-2 L3", HOLE, 3),
                                               ("G81 @1 ^45 Z-3 R2", HOLE, 1), ("G18 G81 X1 Z1 Y-3 R2", HOLE, 1),
                                               ("G19 G83 Y1 Z1 X-3 R2 Q1 L2", HOLE, 2),
                                               ("G87 X1 Y1 Z-3 R2 I1 J0 K-1", HOLE, 1),
                                               ("G19 G91 G87 Y1 Z1 X-3 R-2 I-1 J1 K0.5 L2", HOLE, 2),
                                               ("fanuc G98 G87 X1 Y1 Z-1 R-3 I1 J0 K2", HOLE, 2)])  # fmt: skip
def test_cycle_moves_are_fixed(cycle, why, holes):
    """A hole is compensated as a whole (HOLE) in any plane, each of a block's repeats its own,
    rs274ngc's back bore G87 too, and Fanuc's G87, whose words read otherwise."""
    fanuc, cycle = cycle.startswith("fanuc "), cycle.removeprefix("fanuc ")
    text = HEAD + "M3 S1000\n" + cycle + "\nG80\nG1 X5\n"
    read = interpret_fanuc if fanuc else interpret
    events = list(read(parse_stream(io.BytesIO(text.encode()), "t.ngc")))
    lines = [e for e in events if type(e) is Line]
    assert lines[0].fixed == lines[-1].fixed == "" and {e.fixed for e in lines[1:-1]} == {why}
    assert all((e.hole is not None) == (why == HOLE) for e in lines[1:-1])
    assert len({id(e.hole) for e in lines[1:-1] if e.hole is not None}) == holes
    assert [e.hole.repeat for e in lines[1:-1] if e.hole is not None][-1:] == ([holes - 1] if holes else [])


def _compensate(text: str, strict: bool = False) -> tuple[str, str]:
    """`text` compensated as a Fanuc program: its subprogram's cycle, run twice by `M98 P100 L2` (each run
    may need a correction of its own), stands for a canned cycle left as programmed."""
    return compensate(text, "drill.ngc", strict, dialect="fanuc")


SERIES = "G98 G81 X20 Y20 Z-1 R3 L2\nX30\n(between)\nX40 Y25\nG80\n"
DRILL = (
    HEAD
    + "G1 Z-1\nX40 Y12\nG0 Z5 M3\nM98 P100 L2\nG0 X50 Y50\nG1 Z-1\nX70 Y40\nG3 X80 Y60 R15\nG0 Z10\nM30\n"
    + "O100\n" + SERIES + "M99\n"
)  # fmt: skip


def test_cycles_pass_through_and_compensation_resumes():
    out, warned = _compensate(DRILL)
    lines = out.splitlines()
    cycle = SERIES.splitlines()
    start = lines.index(cycle[0])
    assert lines[start : start + len(cycle)] == cycle  # verbatim
    # one warning, naming the line that runs the series
    assert warned.count("warning") == 1 and "drill.ngc:6:1: warning: canned cycle" in warned
    after = lines[lines.index("M98 P100 L2") + 1 :]
    assert after[0].startswith("G0 X50.0") and "Z" in after[0]  # compensated, every axis said after the cycle
    assert any(line.startswith("G3 ") and "I" in line for line in after)  # the arc after it is replaced too


def test_a_warning_repeated_hundreds_of_times_is_printed_five_times_then_counted():
    """A drilling program warns at each of its 300 cycle series: five are printed (the fifth
    says the rest are counted), then one line at the end tells how many and where."""
    holes = "".join(
        f"G0 X{k % 20 * 5} Y{k // 20 * 5}\nM98 P100 L2\nG1 X{k % 20 * 5 + 2}\n" for k in range(300)
    )
    out, warned = _compensate(HEAD + "M3\n" + holes + "M30\nO100\nG98 G81 Z-1 R3 F100\nG80\nM99\n")
    said = warned.splitlines()
    series = [n + 1 for n, line in enumerate((HEAD + "M3\n" + holes).splitlines()) if line.startswith("M98")]
    assert [line.split(": warning: ")[0] for line in said] == [
        f"drill.ngc:{n}:1" for n in (*series[:5], series[-1])
    ]
    assert said[4].endswith("(warned 5 times: more of these are counted, not printed)")
    assert said[5].endswith(f"(295 not printed, from line {series[5]} to this one)")
    assert out.count("M98 P100 L2") == 300


def test_warnings_of_other_texts_are_printed_whatever_one_text_repeats():
    stream = io.StringIO()
    warnings = Warnings(stream=stream)
    for n in range(1, 21):
        warnings.warn("again", Location("t.ngc", n))
    warnings.warn("once", Location("t.ngc", 21))
    warnings.finish()
    said = stream.getvalue().splitlines()
    assert warnings.count == 21 and len(said) == 7
    assert (
        said[5] == "t.ngc:21:1: warning: once"
        and said[6] == "t.ngc:20:1: warning: again (15 not printed, from line 6 to this one)"
    )
    with pytest.raises(NcppError, match="refused in strict mode"):
        Warnings(strict=True, stream=stream).warn("again", Location("t.ngc", 1))


def test_the_block_after_a_cycle_says_every_axis():
    """Even an axis whose compensated target writes as the cycle's nominal end: the control may
    be elsewhere (G98 retracts to the compensated level the series started at)."""
    from ncpp.program.dialects.iso import IsoWriter

    events = list(
        interpret(parse_stream(io.BytesIO((HEAD + "G81 X1 Y1 Z-3 R2\nG80\nG1 X5\n").encode()), "t.ngc"))
    )
    move = events[-1]
    events[-1] = Line(
        move.start, (5.00001, 1.0, 2.0), False, move.feed, move.block, move.context, changed=True
    )
    assert list(IsoWriter().write(events))[-1] == "G1 X5.0000 Y1.0000 Z2.0000\n"


def test_strict_refuses_cycles():
    with pytest.raises(NcppError, match="drill.ngc:6:1: canned cycle"):
        _compensate(DRILL, strict=True)


def test_a_g91_move_right_after_a_g90_cycle_ends_compensation():
    """The G90 cycle's G98 retract ends at the compensated level it started from, not at its
    programmed one: the increments after it would carry that difference."""
    text, line = HEAD + "G1 Z-1\nX40 Y12\nG0 Z5\nG98 G81 X20 Y20 Z-3 R2\nG80\nG91 G1 X5\nX5 Y5\n", 8
    out, warned = _compensate(text)
    assert f"drill.ngc:{line}:1: warning: a G91 move right after a canned cycle in G90" in warned
    original, written = text.splitlines(), out.splitlines()
    assert written[-(len(original) - line + 1) :] == original[line - 1 :]  # the rest verbatim
    assert written[3] != original[2]  # compensated before it
    with pytest.raises(NcppError, match=f"drill.ngc:{line}:1: .*canned cycle"):
        _compensate(text, strict=True)


@pytest.mark.parametrize("after", ["G90 G80\nG1 X50 Y50\n", "G80\nG1 X-5 Y5\nX5\n"])
def test_compensation_goes_on_after_a_g91_cycle(after):
    """A G91 cycle runs its increments from where the control stands, its G98 retract to the
    level it started from: apply_error_map carries it (test_exact_model measures the moves
    after it on the machine), and compensates the moves after it, in G90 or G91."""
    text = (
        HEAD
        + "G1 Z-1\nX40 Y12\nG0 Z5 M3\nM98 P100 L2\nG17\n"
        + after
        + "M30\nO100\nG91 G98 G81 X10 Y10 R-8 Z-3\nM99\n"
    )
    out, warned = _compensate(text)
    assert (
        "in G91" not in warned
        and "G91 move" not in warned
        and "drill.ngc:6:1: warning: canned cycle" in warned
    )
    original, written = text.splitlines(), out.splitlines()
    last = written[written.index("M30") - 1]
    wanted = original[original.index("M30") - 1]
    found = re.search(r"X(-?[\d.]+)", last)  # compensated: the X the block says, moved by microns
    assert found is not None and last != wanted
    assert 0 < abs(float(found[1]) - float(wanted.split("X")[1].split()[0])) < 0.1
    assert "G91 G98 G81 X10 Y10 R-8 Z-3" in written


def test_a_call_whose_text_starts_with_a_g91_cycle_is_stepped_to_its_programmed_start_first():
    """A subprogram whose text starts with a G91 cycle, run twice: the cycle runs from where the control
    stands, so the step to its programmed start (`apply_error_map._lead_in`) is written before the call
    (inside the text it would run with each run), and the G91 moves after the call start from the
    cycle's programmed end (without the step they would carry the correction twice, which the
    verifier refuses: 26 µm past the corrected point in Y, by rs274 on the written program)."""
    text = HEAD + "G1 Z-1\nX40 Y12\nG0 Z5 M3\nM98 P100 L2\nG17\nG80\nG1 X-5 Y5\nX5\nM30\nO100\n"
    out, _ = _compensate(text + "G91 G98 G81 X10 Y10 R-8 Z-3\nM99\n")
    written = out.splitlines()
    assert written[written.index("M98 P100 L2") - 1] == "X40.0000 Y12.0000 Z5.0000"


@pytest.mark.skipif(not RS274.exists(), reason="no rs274")
def test_rs274_accepts_the_compensated_cycles(tmp_path):
    """The program around a series left as programmed (a cycle in a loop, which runs twice) is written so
    that rs274 runs it."""
    looped = DRILL.split("M98")[0] + "o1 repeat [2]\n" + SERIES + "o1 endrepeat\n" + DRILL.split("L2\n", 1)[1]
    looped = looped.split("M30")[0] + "M2\n"
    out, warned = compensate(looped, "drill.ngc", False)
    assert "warning: canned cycle" in warned
    path = tmp_path / "out.ngc"
    path.write_text(out)
    _, messages = rs274(str(path))
    assert rs274_error(messages) is None, messages


@pytest.mark.parametrize(
    "cycle, col, what",
    [
        ("G81 X10 Y10 Z-5 R1 L99999999", 20, "99,999,999 hole(s)"),
        ("G83 X10 Y10 Z-5 R1 Q0.0000001", 20, "1 hole(s) of 60,000,000 pecks each"),
        ("G73 X10 Y10 Z-500 R1 Q0.0001", 22, "1 hole(s) of 5,010,000 pecks each"),
    ],
)
def test_a_cycle_of_millions_of_moves_is_refused_before_they_are_made(cycle, col, what):
    """rs274ngc would drill for days; these took 3 GB and a MemoryError (or, with a peck below
    the float resolution, looped for ever)."""
    with pytest.raises(NcppError) as err:
        list(
            interpret(
                parse_stream(io.BytesIO(f"G21 G90 G17 F100\nG0 X0 Y0 Z10\n{cycle}\n".encode()), "c.ngc"),
                file="c.ngc",
            )
        )
    assert (err.value.where.line, err.value.where.col) == (3, col)
    assert err.value.message == f"a canned cycle of {what}: ncpp takes 1,000,000 moves in one block at most"
