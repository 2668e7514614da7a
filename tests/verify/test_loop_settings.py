"""A loop or subroutine that sets an offset from where the control stands (LinuxCNC G-code manual:
G92 "makes the current point have the coordinates you want", G10 L20 and G10 L10/L11 likewise from
the current position; Fanuc's and Haas's G92 "setting for workpiece coordinate system") ends
interpretation: each run would set its offset from another point.  The control reaches it where the
last compensated move left it, off the programmed point by that move's correction, so ncpp writes a
step back to the programmed point before the construct's first line (`ncpp.motion.entries`), or,
where an action (an M function, a tool change, a dwell, a tool length) stands between the last move
and that line, right after the move, in its frame: the control stands at the programmed point
through the actions and into the construct, as the original's does.

Judged by LinuxCNC's rs274 (oracle tier): the output sets the offsets the original sets, and every
move after them ends where the original's does.  The fast tests read the written text: the step's
numbers are the input's programmed point, the construct and all after it are the input's lines."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from tests import rs274
from tests.compensation.test_cutter_comp_accuracy import AFFINE, AFFINE_XZ
from tests.conftest import ROOT

TO = "G21 G90 G17\nG0 X10 Y10 Z5\nG1 X150 Y130 F300\n"  # the compensated move: it ends at X150 Y130 Z5
# LinuxCNC programs: a construct after TO whose run sets an offset from where the control stands
LINUXCNC = {
    "while": TO + "#1 = 0\no100 while [#1 LT 2]\nG92 X0 Y0\nG1 X5 Y5\n#1 = [#1 + 1]\no100 endwhile\n"
    "G92.1\nG0 X0 Y0\nM2\n",
    "call of a sub defined before": "o200 sub\nG92 X0 Y0\nG1 X5 Y5\nG92.1\no200 endsub\n"
    + TO
    + "o200 call\nG0 X0 Y0\nM2\n",
    "call of a sub defined after": TO + "o200 call\nG0 X0 Y0\nM2\no200 sub\nG92 X0 Y0\nG1 X5 Y5\nG92.1\n"
    "o200 endsub\n",
    "second call of a sub": "o200 sub\nG1 X[#1] Y[#1]\nG92 X0 Y0\nG1 X5 Y5\nG92.1\no200 endsub\n"
    + TO
    + "o200 call [20]\nG1 X100 Y40\no200 call [30]\nG0 X0 Y0\nM2\n",
    "set in the second pass": TO + "#1 = 0\no100 while [#1 LT 3]\no101 if [#1 EQ 1]\nG92 X0 Y0\no101 endif\n"
    "G91 G1 X5\nG90\n#1 = [#1 + 1]\no100 endwhile\nG92.1\nG0 X0 Y0\nM2\n",
    "G10 L20 in a repeat": TO + "o100 repeat [2]\nG10 L20 P1 X0 Y0\nG91 G1 X5 Y5\nG90\no100 endrepeat\n"
    "G10 L2 P1 X0 Y0\nG0 X0 Y0\nM2\n",
    "G10 L10 in a do loop": "G21 G90 G17\nT1 M6 G43\nG0 X10 Y10 Z5\nG1 X150 Y130 Z3 F300\no100 do\n"
    "G10 L10 P1 Z0\nG43\nG1 X5 Y5\no100 while [0]\nG0 X0 Y0\nM2\n",
    "a call in a loop": TO + "o300 sub\nG92 X0 Y0\nG1 X5\nG92.1\no300 endsub\n#1 = 0\no100 while [#1 LT 2]\n"
    "G1 X[100+#1] Y100\n#1 = [#1 + 1]\no300 call\no100 endwhile\nG0 X0 Y0\nM2\n",
    "after a control line": TO + "o1 if [1]\no1 endif\no100 repeat [2]\nG92 X0 Y0\nG1 X5 Y5\nG92.1\n"
    "o100 endrepeat\nG0 X0 Y0\nM2\n",
    "G91 move before": "G21 G90 G17\nG0 X10 Y10 Z5\nG91 G1 X140 Y120 F300\no100 repeat [2]\nG92 X0 Y0\n"
    "G1 X5 Y5\no100 endrepeat\nG90 G92.1\nG0 X0 Y0\nM2\n",
    "a file ncpp is not given": TO + "o100 repeat [2]\no<touchoff> call\no100 endrepeat\nG0 X0 Y0\nM2\n",
}
TOUCHOFF = "o<touchoff> sub\nG92 X0 Y0\nG1 X5 Y5\nG92.1\no<touchoff> endsub\n"
# Fanuc and Haas: a subprogram call, a WHILE loop, a backward GOTO, a Haas local subprogram
FANUC = {
    "M98": (
        "fanuc",
        "%\nO1000\n" + TO + "M98 P2000 L2\nG0 X0 Y0\nM30\n%\nO2000\nG92 X0 Y0\nG91 G1 X5 Y5\nG90\nM99\n%\n",
    ),
    "WHILE": (
        "fanuc",
        "%\nO1000\n" + TO + "#1 = 0\nWHILE [#1 LT 2] DO1\nG92 X0 Y0\nG1 X5 Y5\n#1 = #1 + 1\n"
        "END1\nG92 X150 Y130\nG0 X0 Y0\nM30\n%\n",
    ),
    "GOTO": (
        "fanuc",
        "%\nO1000\n" + TO + "#1 = 0\nN10 G92 X0 Y0\nG1 X5 Y5\n#1 = #1 + 1\nIF [#1 LT 2] GOTO10\n"
        "G92 X150 Y130\nG0 X0 Y0\nM30\n%\n",
    ),
    "M97": (
        "haas",
        "%\nO1000\n" + TO + "M97 P100 L2\nG0 X0 Y0\nM30\nN100 G92 X0 Y0\nG91 G1 X5 Y5\nG90\nM99\n%\n",
    ),
}
_SETS = re.compile(r"(SET_G92_OFFSET|SET_G5X_OFFSET|SET_TOOL_TABLE_ENTRY)\((.*)\)")
_MOVES = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED)\(([^)]*)\)")
_NUMBER = re.compile(r"-?\d+(?:\.\d*)?")
_STEP = re.compile(r"^(?:G[01] )?X(-?[\d.]+) Y(-?[\d.]+)(?: Z(-?[\d.]+))?$")


@pytest.fixture(scope="module")
def affine(tmp_path_factory) -> ErrorSource:
    path = tmp_path_factory.mktemp("machine") / "affine.toml"
    path.write_text(AFFINE)
    return ErrorSource.from_machine_file(str(path))


def _compensated(
    source: ErrorSource, text: str, dialect: str | None = None, name: str = "t.ngc"
) -> tuple[str, str]:
    """(the program compensated on AFFINE, whose corrections here are about 10 µm; the warnings)."""
    warned, out = io.StringIO(), io.BytesIO()
    process(io.BytesIO(text.encode()), out, file=name, source=source, warnings=Warnings(stream=warned),
            offsets=WorkOffsets.at((0.0, 0.0, 0.0)), dialect=dialect)  # fmt: skip
    return out.getvalue().decode(), warned.getvalue()


def _lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.strip() and not line.startswith(("(ncpp", "; ncpp"))]


def _assert_stepped_back(original: str, written: str, at: tuple[float, float]) -> int:
    """The written program is the input with one more line, a step to `at` (the input's programmed
    point there) right before the line from which all of the input's lines come as they are: the
    number of that line among the input's (`_lines`)."""
    before, after = _lines(original), _lines(written)
    assert len(after) == len(before) + 1, written
    tail = next(n for n in range(len(before)) if after[n + 1 :] == before[n:])
    step = _STEP.match(after[tail])
    assert step is not None, (after[tail], written)
    assert (float(step.group(1)), float(step.group(2))) == at, written
    assert after[:tail] != before[:tail]  # (the compensated moves before it)
    return tail


@pytest.mark.parametrize("name", sorted(set(LINUXCNC) - {"G91 move before"}))
def test_a_step_back_to_the_programmed_point_comes_before_the_construct(affine, name):
    original = LINUXCNC[name]
    written, warned = _compensated(affine, original)
    _assert_stepped_back(original, written, (150.0, 130.0))
    assert "in a loop or subroutine" in warned or "o<touchoff>" in warned, warned
    assert "no step" not in warned and "cannot write a step" not in warned, warned


def test_in_g91_the_step_back_is_the_increment_to_the_programmed_point(affine):
    original = LINUXCNC["G91 move before"]
    written = _lines(_compensated(affine, original)[0])
    at = written.index("o100 repeat [2]")
    increments = [re.search(r"X(-?[\d.]+) Y(-?[\d.]+)", line) for line in written[at - 3 : at]]
    assert [m is not None for m in increments] == [True] * 3, written
    assert (sum(float(m.group(1)) for m in increments), sum(float(m.group(2)) for m in increments)) == (
        pytest.approx(150.0, abs=1e-9),
        pytest.approx(130.0, abs=1e-9),
    )
    assert written[at:] == _lines(original)[at - 1 :]


@pytest.mark.parametrize("name", sorted(FANUC))
def test_fanuc_and_haas_calls_and_loops_get_the_step_back(affine, name):
    dialect, original = FANUC[name]
    written, warned = _compensated(affine, original, dialect, "t.nc")
    _assert_stepped_back(original, written, (150.0, 130.0))
    assert "in a loop or subroutine" in warned, warned


def test_an_offset_set_in_an_untaken_branch_takes_no_step(affine):
    original = TO + "#1 = 0\no100 while [#1 LT 2]\no101 if [#1 GT 5]\nG92 X0 Y0\no101 endif\nG91 G1 X5\nG90\n"
    original += "#1 = [#1 + 1]\no100 endwhile\nG1 X0 Y0\nM2\n"
    written, warned = _compensated(affine, original)
    assert len(_lines(written)) == len(_lines(original)) and "G92 X0 Y0" in written, written


@pytest.mark.parametrize(
    "before, said",
    [
        ("G2 X160 Y140 R10\n", "in a mode other than G0 or G1"),  # (a step would end the arc mode)
        ("o5 repeat [2]\nG1 X200 Y200\no5 endrepeat\n", "right after moves left as programmed in G90"),
        # (after an action, where a step right after the last move cannot be proven right either)
        ("G2 X160 Y140 R10\nM8\n", "would change the arc's or canned cycle's mode"),
        ("M8\nG92 X140 Y120\nG92.1\n", "would come before a G92 or G10 L10/L11/L20"),
        (
            "o5 repeat [2]\nM7\no5 endrepeat\nM8\n",
            "would come before other code than blocks run in their place",
        ),
    ],
)
def test_where_no_step_can_be_proven_right_it_is_warned_of(affine, before, said):
    original = TO + before + "o100 repeat [2]\nG92 X0 Y0\nG1 X5 Y5\nG92.1\no100 endrepeat\nG0 X0 Y0\nM2\n"
    written, warned = _compensated(affine, original)
    assert said in warned and "may carry" in warned, warned
    assert len(_lines(written)) == len(_lines(original)), written


# Actions between the last move (TO's) and a construct's first line: the step back comes right
# after the move, before them (a step after them would move where the original stands still)
ACTIONS = {
    "coolant": "M8\n",
    "tool change": "T2 M6 G43 H2\n",
    "spindle, dwell, comment, parameter": "S1000 M3\nG4 P0.5\n(spindle up)\n#1 = 2\nM8\n",
    "G91 after coolant": "M8\nG91\n",
}
LOOP = "o100 repeat [2]\nG92 X0 Y0\nG1 X5 Y5\no100 endrepeat\nG90 G92.1\nG0 X0 Y0\nM9\nM2\n"


@pytest.mark.parametrize("name", sorted(ACTIONS))
def test_after_an_action_the_step_back_comes_right_after_the_last_move(affine, name):
    original = TO + ACTIONS[name] + LOOP
    written, warned = _compensated(affine, original)
    tail = _assert_stepped_back(original, written, (150.0, 130.0))
    assert _lines(original)[tail - 1] == "G1 X150 Y130 F300", written
    assert "cannot write a step" not in warned, warned


@pytest.mark.parametrize("name", sorted(FANUC))
def test_fanuc_and_haas_calls_and_loops_after_an_action_get_the_step_back_after_the_move(affine, name):
    dialect, original = FANUC[name]
    original = original.replace(TO, TO + "M8\n")
    written, warned = _compensated(affine, original, dialect, "t.nc")
    tail = _assert_stepped_back(original, written, (150.0, 130.0))
    assert _lines(original)[tail] == "M8", written
    assert "cannot write a step" not in warned, warned


def test_past_the_blocks_held_since_the_last_move_an_action_gets_a_warning(affine, monkeypatch):
    """The blocks without motion since the last move are held to a bound (memory): a construct
    after more of them has no step back, and says why."""
    import ncpp.motion.entries as entries

    monkeypatch.setattr(entries, "MAX_SINCE", 3)
    original = TO + "(a)\n(b)\n(c)\n(d)\nM8\n" + LOOP
    written, warned = _compensated(affine, original)
    assert "more than 3 blocks without motion stand between the last move and it" in warned, warned
    assert len(_lines(written)) == len(_lines(original)), written
    within = TO + "(a)\n(b)\nM8\n" + LOOP
    written, warned = _compensated(affine, within)
    assert "cannot write a step" not in warned and len(_lines(written)) == len(_lines(within)) + 1, warned


def _rs274(program: Path, tmp_path: Path, ini: Path | None = None) -> tuple[list, list]:
    """rs274's offset and tool table settings, and its moves' end points, 7 decimals."""
    out = rs274.run(program, digits=7, home=tmp_path, ini=ini, tool_table=tmp_path / "t.tbl").stdout
    sets = [(m.group(1), [float(v) for v in _NUMBER.findall(m.group(2))]) for m in _SETS.finditer(out)]
    moves = [[float(v) for v in m.group(2).split(",")[:3]] for m in _MOVES.finditer(out)]
    return sets, moves


def _same(written: list, original: list) -> bool:
    """The same settings, each value to 1e-7."""
    return [n for n, _ in written] == [n for n, _ in original] and all(
        np.allclose(a, b, rtol=0, atol=1e-7) for (_, a), (_, b) in zip(written, original)
    )


def _ncpp(tmp_path: Path, text: str, *extra: str, machine: str = AFFINE) -> tuple[Path, Path]:
    (tmp_path / "affine.toml").write_text(machine)
    program, out = tmp_path / "t.ngc", tmp_path / "t.out.ngc"
    program.write_text(text)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "--machine", str(tmp_path / "affine.toml"), *extra,
                           str(program), "-o", str(out)], capture_output=True, text=True, cwd=ROOT, timeout=300,
                          stdin=subprocess.DEVNULL)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return program, out


@pytest.mark.oracle
@pytest.mark.parametrize("name", sorted(LINUXCNC))
def test_rs274_sets_the_originals_offsets_from_the_written_program(tmp_path, name):
    """The offsets the written program sets in rs274 are the original's to 1e-7 (the control stood
    at the compensated point before, about 10 µm off), and so is every move after the first."""
    (tmp_path / "t.tbl").write_text("T1 P1 Z0 D6\n")
    (tmp_path / "subs").mkdir()
    (tmp_path / "subs" / "touchoff.ngc").write_text(TOUCHOFF)
    ini = tmp_path / "sub.ini"
    ini.write_text(f"[RS274NGC]\nSUBROUTINE_PATH = {tmp_path / 'subs'}\n")
    program, out = _ncpp(tmp_path, LINUXCNC[name])
    (sets, moves), (written_sets, written_moves) = (_rs274(p, tmp_path, ini) for p in (program, out))
    assert _same(written_sets, sets), (sets, written_sets)
    # the two compensated moves, the step back to where the second ends, then the original's moves
    assert len(written_moves) == len(moves) + 1
    assert np.allclose(written_moves[2:], moves[1:], rtol=0, atol=1e-7), (moves, written_moves)
    if "<touchoff>" not in LINUXCNC[name]:  # (pathcheck's rs274 reads no subroutine path)
        _pathcheck(program, out, tmp_path, 0.02)


def _pathcheck(program: Path, out: Path, tmp_path: Path, tolerance_mm: float) -> None:
    check = subprocess.run([sys.executable, str(rs274.PATHCHECK), str(program), str(out), "--tool-table",
                            str(tmp_path / "t.tbl"), "--tol-mm", str(tolerance_mm)], capture_output=True, text=True,
                           timeout=300, env={**os.environ, "HOME": str(tmp_path)})  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


# Programs with actions between the last move and the construct, each with the machine compensated
# for and pathcheck's tolerance (twice the largest correction and 0.01 mm): AFFINE corrects about
# 11 µm at X150 Y130; AFFINE_XZ about 50 µm at X150 Z-20, where tools of other lengths (1.2 and 0.4
# inch: rs274 reads its table in inches) put the tip 20 mm apart, so the step's Z is the move's
# tool's, before the change
LENGTHS = "G21 G90 G17\nT1 M6 G43\nG0 X10 Y10 Z5\nG1 X150 Y30 Z-20 F300\n{}o100 repeat [2]\nG92 X0 Y0 Z0\n"
LENGTHS += "G1 X5 Y5 Z1\no100 endrepeat\nG92.1\nG0 X0 Y0 Z5\nM2\n"
ACTED = {
    **{f"LinuxCNC, {name}": (TO + actions + LOOP, (), AFFINE, 0.032) for name, actions in ACTIONS.items()},
    "Fanuc M98": (TO + "M8\nM98 P2000 L2\nG0 X0 Y0\nM30\nO2000\nG92 X0 Y0\nG91 G1 X5 Y5\nG90\nM99\n",
                  ("--dialect", "fanuc"), AFFINE, 0.032),
    **{f"tool length, {name}": (LENGTHS.format(change), (), AFFINE_XZ, 0.11)
       for name, change in (("tool change", "T2 M6 G43 H2\n"), ("G43 H2", "G43 H2\n"), ("G49", "G49\n"))},
}  # fmt: skip


@pytest.mark.oracle
@pytest.mark.parametrize("name", sorted(ACTED))
def test_rs274_sets_the_originals_offsets_with_actions_before_the_construct(tmp_path, name):
    """After actions between the last move and the construct (a tool change, G43, G49, coolant), the
    offsets the written program sets in rs274 are the original's to 1e-7, and every move after the
    compensated one ends where the original's does: the step back right after it."""
    text, extra, machine, tolerance_mm = ACTED[name]
    (tmp_path / "t.tbl").write_text("T1 P1 Z0.4 D0.1\nT2 P2 Z1.2 D0.1\n")
    tools = ("--tool-table", str(tmp_path / "t.tbl"), "--var-units", "inch")
    program, out = _ncpp(tmp_path, text, *tools, *extra, machine=machine)
    (sets, moves), (written_sets, written_moves) = (_rs274(p, tmp_path) for p in (program, out))
    assert _same(written_sets, sets), (sets, written_sets)
    assert len(written_moves) == len(moves) + 1
    assert np.allclose(written_moves[2:], moves[1:], rtol=0, atol=1e-7), (moves, written_moves)
    _pathcheck(program, out, tmp_path, tolerance_mm)


@pytest.mark.oracle
def test_expanded_loops_set_the_originals_offsets(tmp_path):
    """With --expand the loop is interpreted run by run: each G92 is written with its values moved
    by the correction where the control stands, and rs274 sets the original's offsets."""
    (tmp_path / "t.tbl").write_text("T1 P1 Z0 D6\n")
    program, out = _ncpp(tmp_path, LINUXCNC["while"], "--expand")
    (sets, _), (written_sets, _) = (_rs274(p, tmp_path) for p in (program, out))
    assert _same(written_sets, sets), (sets, written_sets)


def test_a_construct_held_past_the_bound_gets_a_warning_instead_of_its_step(affine, monkeypatch):
    """The events from a construct's head are held to a bound (memory): a setting met past it has
    no step back, and says so."""
    import ncpp.motion.entries as entries

    monkeypatch.setattr(entries, "MAX_HELD", 5)
    original = LINUXCNC["set in the second pass"]
    written, warned = _compensated(affine, original)
    assert "its head was written before, 5 events ahead" in warned and "may carry" in warned, warned
    assert len(_lines(written)) == len(_lines(original)), written
