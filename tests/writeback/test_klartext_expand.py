"""`--expand` on Klartext: subprograms (`CALL LBL n`), program-section repeats (`CALL LBL n REP k`)
and the jumps FN 9-12 written out as straight code, each run's moves compensated.

There is no oracle that runs Klartext: the judge is closed form.  The test computes by hand
where each run of a body puts the tool (a REP 3 of a square 1 mm deeper each run: 4 squares at
Z-1 ... Z-4), reads the numbers of the written program with a reader of its own (`points`),
and maps them through the formula of a machine whose errors are linear in position (`AFFINE`,
`machine`): each programmed corner must be reached within 0.5 µm.  Without --expand the
same corners miss by microns (the bodies' moves pass through uncompensated), so the tests
fail on a Klartext --expand that writes nothing out.  ncpp's own interpreter, reading the
original with --expand and the written program without it, is a consistency check only."""

from __future__ import annotations

import io
import math
import re
from pathlib import Path

import numpy as np
import pytest

import ncpp.motion.expand as expand_module
from ncpp.cli import main
from ncpp.errors import Warnings
from ncpp.motion.segments import PLANE_AXES, Arc, Line
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests.compensation.test_dialect_cutter_comp import compensated, machine
from tests.conftest import CORPUS, SHARED
from tests.writeback.closed_form import end_points, landed, squares
from tests.writeback.conftest import misses

# a square 40 x 40 at Z-1, its section run 3 more times, each 1 mm deeper (Q1 counts down)
REPEATED = """0 BEGIN PGM REP MM
1 BLK FORM 0.1 Z X-10 Y-10 Z-10
2 BLK FORM 0.2 X+60 Y+60 Z+0
3 TOOL CALL 1 Z S3000
4 L X-5 Y-5 Z+5 R0 FMAX
5 Q1 = 0
6 LBL 1
7 Q1 = Q1 - 1
8 L X+0 Y+0 Z+Q1 F300
9 L X+40
10 L Y+40
11 L X+0
12 L Y+0
13 CALL LBL 1 REP 3
14 L Z+5 FMAX
15 L Z+50 FMAX M30
16 END PGM REP MM
"""
# a subprogram after the program's end, called at X 100 and X 200 (Q2), with an arc about its pole
SUBPROGRAM = """0 BEGIN PGM SUB MM
1 TOOL CALL 1 Z S3000
2 L X-5 Y-5 Z+5 R0 FMAX
3 Q2 = 100
4 CALL LBL 5
5 Q2 = 200
6 CALL LBL 5
7 L Z+50 FMAX M30
8 LBL 5
9 L X+Q2 Y+20 Z-2 F300
10 CC X+Q2 Y+40
11 C X+Q2 Y+60 DR+
12 L Y+80
13 L Z+5 FMAX
14 LBL 0
15 END PGM SUB MM
"""
CALLED_AT = [(100, 20, -2), (100, 60, -2), (100, 80, -2), (200, 20, -2), (200, 60, -2), (200, 80, -2)]
# a loop of FN 12 with a Q counter (X 10 ... 50), a line after it that reads the counter, and a
# forward jump FN 9 over a line that must not run
LOOP = """0 BEGIN PGM LOOP MM
1 TOOL CALL 1 Z S3000
2 L X-5 Y-5 Z+5 R0 FMAX
3 FN 0: Q1 = +0
4 LBL 2
5 FN 1: Q1 = +Q1 + +10
6 L X+Q1 Y+0 Z-1 F200
7 FN 12: IF +Q1 LT +50 GOTO LBL 2
8 L X+Q1 Y+10 F200
9 FN 9: IF +Q1 EQU +50 GOTO LBL 7
10 L X+999 Y+999
11 LBL 7
12 L Z+50 FMAX M30
13 END PGM LOOP MM
"""
LOOPED = [(10, 0, -1), (20, 0, -1), (30, 0, -1), (40, 0, -1), (50, 0, -1), (50, 10, -1)]
_WORD = re.compile(r"\b(X|Y|Z)([+-]\d+(?:\.\d*)?)")


def points(text: str) -> np.ndarray:
    """Where each `L` and `C` block of a Klartext program ends: the test's own reading of the numbers."""
    return end_points(text, _WORD, lambda code: code.split()[1:2] in (["L"], ["C"]))


@pytest.mark.parametrize(
    "text, name, wanted",
    [(REPEATED, "rep.h", squares(4)), (SUBPROGRAM, "sub.h", CALLED_AT), (LOOP, "loop.h", LOOPED)],
    ids=["repeat", "subprogram", "jumps"],
)
def test_every_run_of_a_body_lands_on_its_programmed_points_within_half_a_micron(
    tmp_path, text, name, wanted
):
    """Each corner of each run, the written numbers mapped through the machine's formula, within
    0.5 µm of the point the test computes; the program as written misses them by microns."""
    written, _ = compensated(tmp_path, name, text, "--expand")
    assert landed(points(written), wanted).max() < 0.5e-3
    plain, _ = compensated(tmp_path, "plain-" + name, text)
    assert landed(points(plain), wanted).max() > 5e-3  # (the bodies left as programmed: the measure can fail)


def test_a_repeat_is_written_as_four_squares_without_its_call_and_its_q_parameter(tmp_path):
    """REP 3 runs the section 3 more times (TNC 640 Klartext manual, "Program section repeats"):
    four squares at Z-1 ... Z-4, the call and the assignments of the counter left out, the
    blocks numbered one after another."""
    written = _expanded(tmp_path, REPEATED)
    assert "CALL LBL" not in written and "Q1 - 1" not in written
    assert sorted({round(z, 3) for z in points(written)[:, 2]} - {5.0, 50.0}) == [-4.0, -3.0, -2.0, -1.0]
    numbers = [int(line.split()[0]) for line in written.splitlines()]
    assert numbers == list(range(len(numbers)))


def test_subprograms_stay_after_the_end_and_the_calls_go(tmp_path):
    written = _expanded(tmp_path, SUBPROGRAM)
    main_part, _, after = written.partition("M30")
    assert "CALL LBL" not in main_part and "Q2" not in main_part.split("Q2 = 200")[1]
    assert "LBL 5" in after and "L X+Q2 Y+20 Z-2 F300" in after and "LBL 0" in after
    assert "CC X+100 Y+40" in main_part and "CC X+200 Y+40" in main_part  # (each run's pole as numbers)


def test_a_loops_counter_is_set_before_the_line_that_reads_it_and_a_jumped_line_is_left_out(tmp_path):
    written = _expanded(tmp_path, LOOP)
    lines = written.splitlines()
    settle = next(n for n, line in enumerate(lines) if "FN 0: Q1 = +50" in line)
    assert "Y+10" in lines[settle + 1]
    assert not any(f"FN {n}:" in written for n in (1, 9, 12)) and "999" not in written
    assert "LBL 2" in written and "LBL 7" in written  # (labels stay where they stand)


CYCLE_IN_REPEAT = """0 BEGIN PGM CYC MM
1 TOOL CALL 1 Z S3000
2 L X+0 Y+0 Z+20 R0 FMAX
3 Q5 = 0
4 LBL 1
5 Q5 = Q5 - 2
6 CYCL DEF 200 DRILLING ~
  Q200=+2 ;SAFETY CLEARANCE ~
  Q201=+Q5 ;DEPTH ~
  Q206=+150 ;FEED RATE FOR PLNGNG ~
  Q202=+5 ;PLUNGING DEPTH ~
  Q210=+0 ;DWELL TIME AT TOP ~
  Q203=+0 ;SURFACE COORDINATE ~
  Q204=+50 ;2ND SET-UP CLEARANCE ~
  Q211=+0 ;DWELL TIME AT DEPTH
7 L X-Q5 Y+10 Z+5 FMAX
8 CYCL CALL
9 CALL LBL 1 REP 2
10 L Z+Q5 FMAX
11 FN 14: ERROR = 1000
12 L Z+50 FMAX M30
13 END PGM CYC MM
"""


def test_a_cycle_defined_in_a_repeated_section_keeps_its_parameters_as_each_runs_numbers(tmp_path):
    """The cycle's own parameters stay in its definition, as the numbers of each run (Q201 = Q5:
    -2, -4, -6); the program sets them there, so they are not set again after the stretch, but
    the counter Q5 that the next line reads is.  The FN 14 after it, out of the interpreter's
    scope in the main program, passes through as it is."""
    written, messages = compensated(tmp_path, "cyc.h", CYCLE_IN_REPEAT, "--expand")
    assert re.findall(r"Q201=([+-]\d+)", written) == ["-2", "-4", "-6"]
    assert "FN 0: Q201" not in written and "CYCL CALL" in written and "CALL LBL" not in written
    lines = written.splitlines()
    settle = next(n for n, line in enumerate(lines) if "FN 0: Q5 = -6" in line)
    assert " L Z-" in lines[settle + 1] and lines[settle + 2].endswith("FN 14: ERROR = 1000")
    assert "FN 14 is outside the motion interpreter's scope" in messages


@pytest.mark.parametrize("text", [REPEATED, SUBPROGRAM, LOOP], ids=["repeat", "subprogram", "jumps"])
def test_ncpps_interpreter_reads_the_same_moves_from_both_texts(tmp_path, text):
    """Consistency: the moves ncpp's interpreter reads from the original with --expand are the
    ones it reads from the written program, mapped through the machine (every end point of the
    first within 0.5 µm of one of the second's, none of which is left as programmed)."""
    interpret, _ = dialect_tools("heidenhain")
    original = _ends(interpret(_blocks(text), expand=True))
    written = _ends(interpret(_blocks(_expanded(tmp_path, text))))
    assert len(original) and not any(fixed for _, fixed in written)
    ends = machine(np.array([end for end, _ in written]))
    assert all(np.min(np.linalg.norm(ends - end, axis=1)) < 0.5e-3 for end, _ in original)


@pytest.mark.parametrize(
    "body, message",
    [
        ("10 CALL PGM OTHER.H\n", r"sub\.h:11:4: --expand: CALL PGM OTHER\.H \(its file not found"),
        (
            "10 CYCL DEF 8.0 MIRROR IMAGE\n",
            r"sub\.h:11:4: --expand: CYCL DEF 8\.0 \(a mirror image of the coordinate system\) is "
            r"outside the motion interpreter's scope, inside a loop",
        ),
        ("10 TOOL CALL Q2 Z\n", r"sub\.h:11:4: --expand: a Q parameter in this statement cannot be written"),
    ],
    ids=["call-pgm", "datum-shift", "q-tool"],
)
def test_what_cannot_be_written_out_is_refused_with_its_line(tmp_path, capsys, body, message):
    text = SUBPROGRAM.replace("10 CC X+Q2 Y+40\n", body + "10 CC X+Q2 Y+40\n")
    program = tmp_path / "sub.h"
    program.write_text(text)
    code = main(["compensate", "--machine", str(_wide(tmp_path)), "--expand", str(program),
                 "-o", str(tmp_path / "out.h")])  # fmt: skip
    assert code != 0 and re.search(message, capsys.readouterr().err)
    assert (
        main(["compensate", "--machine", str(_wide(tmp_path)), str(program), "-o", str(tmp_path / "o.h")])
        == 0
    )


def test_more_blocks_written_out_than_the_bound_are_refused(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(expand_module, "MAX_EXPANDED", 10)
    program = tmp_path / "rep.h"
    program.write_text(REPEATED)
    code = main(["compensate", "--machine", str(_wide(tmp_path)), "--expand", str(program),
                 "-o", str(tmp_path / "out.h")])  # fmt: skip
    assert code != 0
    assert re.search(
        r"rep\.h:\d+:1: --expand: the loops and subroutines make more than 10 ", capsys.readouterr().err
    )


def test_the_command_line_writes_out_and_verifies_on_the_wide_machine(tmp_path):
    """`ncpp compensate --machine wide.toml --expand prog.h -o out.h`: the verifier reads the written
    program back and accepts it."""
    for name, text in (("rep.h", REPEATED), ("sub.h", SUBPROGRAM), ("loop.h", LOOP)):
        program, out = tmp_path / name, tmp_path / f"out-{name}"
        program.write_text(text)
        assert (
            main(["compensate", "--machine", str(_wide(tmp_path)), "--expand", str(program), "-o", str(out)])
            == 0
        )
        assert "CALL LBL" not in out.read_text().partition("M30")[0]


# a program that calls another twice, which reads the caller's Q2 and repeats a section itself
CALLER = """0 BEGIN PGM CALLER MM
1 TOOL CALL 1 Z S3000
2 L X-5 Y-5 Z+5 R0 FMAX
3 Q2 = 100
4 CALL PGM TNC:\\PARTS\\SLOT.H
5 Q2 = 200
6 CALL PGM SLOT
7 L X+300 Y+0 Z+50 FMAX M30
8 END PGM CALLER MM
"""
SLOT = """0 BEGIN PGM SLOT MM
1 Q5 = 0
2 LBL 1
3 Q5 = Q5 + 20
4 Q6 = Q2 + 10
5 L X+Q2 Y+Q5 Z-2 F300
6 L X+Q6
7 CALL LBL 1 REP 1
8 L Z+5 FMAX
9 END PGM SLOT MM
"""
SLOTS = [(x + dx, y, -2) for x in (100, 200) for y in (20, 40) for dx in (0, 10)] + [(300, 0, 50)]


def test_a_called_program_is_written_where_each_call_runs_it(tmp_path):
    """CALL PGM (TNC 640 Klartext manual, "Calling any program as a subprogram") runs the called
    program's blocks with the caller's Q parameters: with --expand each call is written in its
    place, every point within 0.5 µm, the call lines, the called program's BEGIN PGM / END PGM
    and its repeat gone, the Q parameters it set set after it, and the caller's last move after
    both."""
    (tmp_path / "SLOT.H").write_text(SLOT)
    written, _ = compensated(tmp_path, "caller.h", CALLER, "--expand", "--subroutine-path", str(tmp_path))
    assert landed(points(written), SLOTS).max() < 0.5e-3
    assert not re.search(r"CALL PGM|LBL|BEGIN PGM SLOT|END PGM SLOT", written)
    assert "FN 0: Q5 = +40" in written  # (Q parameters are global: the caller's as the call left them)
    assert written.index("X+299") > written.rindex("X+209")
    plain, _ = compensated(tmp_path, "plain.h", CALLER, "--subroutine-path", str(tmp_path))
    assert "CALL PGM SLOT" in plain and landed(points(plain), SLOTS[:-1]).max() > 5e-3  # (left as programmed)


def test_a_called_program_in_other_units_is_refused_with_expand(tmp_path, capsys):
    (tmp_path / "SLOT.H").write_text(SLOT.replace(" MM\n", " INCH\n"))
    program = tmp_path / "caller.h"
    program.write_text(CALLER)
    code = main(["compensate", "--machine", str(_wide(tmp_path)), "--expand", "--subroutine-path",
                 str(tmp_path), str(program), "-o", str(tmp_path / "out.h")])  # fmt: skip
    assert code != 0
    assert re.search(r"SLOT\.H:1:1: --expand: a called program in inches \(its caller's units differ\)",
                     capsys.readouterr().err)  # fmt: skip


PLAN = CORPUS / "heidenhain" / "jstjst_Heidenhain-Cycles"
PLAN_TOOL_T = """BEGIN TOOL    .T       MM
T    NAME             L          R          DL      DR      TL RT
1    FACEMILL         +50,000    +20,000    +0,000  +0,000
[END]
"""


def test_the_corpus_face_milling_call_is_written_out_and_follows_the_original(tmp_path):
    """Plan-Beispiel.h as it stands: it sets the cycle's parameters and calls Plan.h (FN 9-12
    loops, a stepover from the tool radius Q108) by CALL PGM TNC:\\Plan.h.  With the folder on the
    subroutine path and a tool table, --expand writes it all out, verified; its moves, read back,
    lie within 20 µm of the original's as ncpp reads the original without --expand, and the
    other way round (the largest correction on wide.toml is 12 µm)."""
    if not PLAN.is_dir():
        pytest.skip(f"corpus not found at {PLAN}")
    (tmp_path / "TOOL.T").write_text(PLAN_TOOL_T)
    options = ["--subroutine-path", str(PLAN), "--tool-table", str(tmp_path / "TOOL.T")]
    out = tmp_path / "out.h"
    code = main(["compensate", "--machine", str(_wide(tmp_path)), "--expand", *options,
                 str(PLAN / "Plan-Beispiel.h"), "-o", str(out)])  # fmt: skip
    assert code == 0
    written = out.read_text(encoding="latin-1")
    assert not re.search(r"CALL PGM|FN 1[0-2]:|FN 9:|[XYZF][+-]?Q\d", written)
    original = _moves(PLAN / "Plan-Beispiel.h", options)
    back = _moves(out, options)
    assert len(original) > 100 and not any(fixed for _, fixed in back)
    ours, theirs = np.array([end for end, _ in back]), np.array([end for end, _ in original])
    assert misses(ours, [tuple(p) for p in theirs]).max() < 0.02
    path = _along(_moves(PLAN / "Plan-Beispiel.h", options, events=True))
    assert _off_the_path(ours, path).max() < 0.02  # (the written moves add split points)


def _off_the_path(points: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """How far (mm) each point lies from the path through `ends` in order (straight between them)."""
    a, b = ends[:-1], ends[1:]
    ab = b - a
    length2 = np.maximum((ab * ab).sum(axis=1), 1e-30)
    t = np.clip(((points[:, None, :] - a[None]) * ab[None]).sum(axis=2) / length2, 0.0, 1.0)
    nearest = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - nearest, axis=2).min(axis=1)


def test_the_corpus_face_milling_cycle_is_written_out_and_verified(tmp_path):
    """Plan.h (a face-milling cycle of FN 9-12 loops) with the parameters Plan-Beispiel.h gives it
    and the tool radius Q108 the control would: every loop written out, verified, nothing left
    as programmed, no jump or counter left."""
    if not PLAN.is_dir():
        pytest.skip(f"corpus not found at {PLAN}")
    caller = (PLAN / "Plan-Beispiel.h").read_text().splitlines()
    given = [line.split(None, 1)[1] for line in caller if re.match(r"\d+ +Q18\d\d =", line)]
    plan = (PLAN / "Plan.h").read_text().splitlines()
    lines = [plan[0]] + [
        f"{n} {text}" for n, text in enumerate(given + ["TOOL CALL 1 Z S800", "Q108 = 5"], 1)
    ]
    for line in plan[1:]:  # (renumbered after the lines put first; continuation lines as they are)
        number, _, text = line.partition(" ")
        lines.append(f"{len(lines)} {text.lstrip()}" if number.isdigit() else line)
    program = tmp_path / "plan.h"
    program.write_text("\n".join(lines) + "\n")
    out = tmp_path / "out.h"
    assert (
        main(["compensate", "--machine", str(_wide(tmp_path)), "--expand", str(program), "-o", str(out)]) == 0
    )
    written = out.read_text()
    assert not re.search(r"FN 1[0-2]:|FN 9:|CALL LBL|[XYZF][+-]?Q\d", written)
    interpret, _ = dialect_tools("heidenhain")
    assert not any(fixed for _, fixed in _ends(interpret(_blocks(written))))


# ---- helpers ---------------------------------------------------------------------------------


def _wide(tmp_path: Path) -> Path:
    wide = SHARED / "machines" / "wide.toml"
    if not wide.is_file():
        pytest.skip(f"{wide} not found")
    return wide


def _moves(path: Path, options: list[str], events: bool = False) -> list:
    """The moves of the Klartext program at `path` as ncpp reads it (no --expand), with the
    subroutine path and tool table of `options`: (end, fixed) each, or the events."""
    from dataclasses import replace

    from ncpp.motion.offsets import WorkOffsets
    from ncpp.motion.tools import ToolTable

    offsets = replace(WorkOffsets.at((0.0, 0.0, 0.0)), tools=ToolTable.from_file(Path(options[3])),
                      subroutine_path=(Path(options[1]),))  # fmt: skip
    interpret, _ = dialect_tools("heidenhain")
    _, parsed = parse_program(io.BytesIO(path.read_bytes()), str(path), "heidenhain")
    read = interpret(parsed, file=str(path), warnings=Warnings(stream=io.StringIO()), offsets=offsets)
    return [e for e in read if type(e) is Line or type(e) is Arc] if events else _ends(read)


def _along(moves: list) -> np.ndarray:
    """The path of `moves` as points in order: each line's ends, each arc at 128 points per turn."""
    points = [np.array(moves[0].start)]
    for move in moves:
        if type(move) is Arc:
            i, j, _ = PLANE_AXES[move.context.plane]
            sweep, radius = move.sweep(), move.radius()
            start = math.atan2(move.start[j] - move.center[j], move.start[i] - move.center[i])
            for t in np.linspace(0.0, 1.0, max(2, int(abs(sweep) / (2 * math.pi) * 128) + 2))[1:]:
                point = np.array(move.start) + t * (np.array(move.end) - np.array(move.start))
                point[i] = move.center[i] + radius * math.cos(start + t * sweep)
                point[j] = move.center[j] + radius * math.sin(start + t * sweep)
                points.append(point)
        else:
            points.append(np.array(move.end))
    return np.array(points)


def _blocks(text: str):
    _, parsed = parse_program(io.BytesIO(text.encode("latin-1")), "prog.h", "heidenhain")
    return parsed


def _ends(events) -> list[tuple[np.ndarray, object]]:
    return [(np.array(e.end), e.fixed) for e in events if type(e) is Line or type(e) is Arc]


def _expanded(tmp_path: Path, text: str, name: str = "prog.h") -> str:
    """The program ncpp writes with --expand for AFFINE's machine (`compensated`)."""
    return compensated(tmp_path, name, text, "--expand")[0]
