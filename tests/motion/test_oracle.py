"""The interpreter against LinuxCNC's own (`../shared/tools/rs274`), call by call.

For every ISO-family corpus program (and the good arcs of malformed/), the
end points, arc centres, rotations and rotary positions of every
STRAIGHT_TRAVERSE, STRAIGHT_FEED and ARC_FEED must agree within 1e-4
(program units).  A program either

* is in scope and agrees completely (rs274's output for a file without a
  final `%`/M2 still counts), or
* leaves the interpreter's scope: it is listed in OUT_OF_SCOPE with the
  construct the interpreter's warning names, and the moves before that
  point must still agree, or
* is refused by rs274: ncpp refuses it too, on the same line, after the same
  moves; or it is listed in RS274_ONLY_REFUSES with the reason the
  difference is right.

Under cutter compensation (from the first move under G41/G42 to the first
after G40) ncpp's moves are the programmed contour and rs274's the tool
centre, more or fewer of them: those runs are left out (`without_comp`), and
the moves after each must agree, which they do only where ncpp followed the
position through it.

A program in none of these cases fails.
"""

from __future__ import annotations

import functools
import io
import os
import subprocess
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

from ncpp.errors import NcppError, Warnings
from ncpp.motion import interpret
from ncpp.motion.canon import CanonCall, canon_call, read_canon
from ncpp.motion.segments import COMP
from ncpp.program.parser import parse_stream
from tests import rs274 as oracle
from tests.conftest import CORPUS, corpus_files, corpus_id
from tests.rs274 import error as rs274_error
from tests.rs274 import many_tools as tool_table

TOLERANCE = 1e-4
PROGRAMS = corpus_files("iso_gcode") + sorted((CORPUS / "malformed/linuxcnc_interp_good").glob("*.ngc"))

# file name -> the construct the interpreter's out-of-scope warning names
OUT_OF_SCOPE = {
    # the machine position, where the operator jogged it to at M0
    "iso_gcode/fanuc_macroB_sheet/7997A.NC": "the control's system variable #5021",
    # a tool offset (G41 D2's radius)
    "iso_gcode/fanuc_macroB_sheet/CIRCLE.NC": "a write to the control's system variable #2002",
    "iso_gcode/fanuc_macroB_sheet/RECTANGLE.NC": "a write to the control's system variable #2001",
    "iso_gcode/fanuc_macroB_sheet/WASHER.NC": "M98 P9010: a subprogram the program does not define",
    "iso_gcode/linuxcnc/g76.ngc": "canned cycle G76",
    "iso_gcode/linuxcnc/nurbs_G5_butterfly-xy.ngc": "spline G5.2",
    "iso_gcode/linuxcnc/plasmac_metric_pipe.ngc": "probing G38.2",
    "iso_gcode/linuxcnc/systems.ngc": "spline G5.1",
    "iso_gcode/linuxcnc/threading.ngc": "threading G33",
    "iso_gcode/linuxcnc_fanuc_subs/12-M99-endless-main-program__test.ngc": "M99 in the main program",
    # (its G10 L1 and L10 before that agree)
    "iso_gcode/linuxcnc_interp_oracle/interp__g10__g10-l1-l10/test.ngc": "G10 L10 under a coordinate system rotation",
    # (its moves under G10 L2 R before that agree)
    "iso_gcode/linuxcnc_interp_oracle/interp__rotation__abs-pts/test.ngc": "G92 or G10 L10/L11/L20 in a loop or subroutine",
}

# file name -> why rs274 refuses a program that ncpp reads
RS274_ONLY_REFUSES = {
    "iso_gcode/cncjs_toolpath_fixtures/helical-thread-milling.nc": "rs274 finds the cutter compensation entry move not longer "
    "than the tool radius; ncpp does not offset the path by a radius (its moves there are left as programmed)",
    "iso_gcode/linuxcnc/large/130207LZW.ngc": "the oracle's rs274 build has no U V W axes; ncpp moves W like the other axes",
    "iso_gcode/linuxcnc/large/impeller-7bl-xyzac.ngc": "M428 is a machine's own M code (> 199), which rs274 refuses; ncpp passes M codes through",
}


# Examples of a property test against rs274: each runs it (about 50 ms); NCPP_HYPOTHESIS_EXAMPLES=600
# for a deeper search.
ORACLE_EXAMPLES = max(int(os.environ.get("NCPP_HYPOTHESIS_EXAMPLES", "300")) // 8, 20)
# The settings of such a test (each example runs rs274: no deadline, slow examples allowed)
oracle_settings = settings(
    max_examples=ORACLE_EXAMPLES,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
)


def run_rs274(path) -> tuple[str, str]:
    """rs274's (canonical calls, messages) for the program at `path`, with `tool_table`."""
    try:
        done = oracle.run(Path(path), tool_table=tool_table(), timeout=300)
    except (OSError, subprocess.TimeoutExpired) as err:
        pytest.skip(f"rs274 oracle unavailable: {err}")
    if not oracle.ran(done):
        pytest.skip(f"rs274 oracle did not run: {done.stderr.strip()[:200]}")
    return done.stdout, done.stderr


@functools.cache
def rs274(path: str) -> tuple[str, str]:
    """`run_rs274`, cached for this test session (the corpus's programs do not change; a
    property test rewrites one file, and runs `run_rs274` itself)."""
    return run_rs274(path)


def ours(
    path, off_path: list[bool] | None = None, offsets=None
) -> tuple[list[CanonCall], NcppError | None, str]:
    """ncpp's calls, error and warnings (from `offsets`, a `WorkOffsets`, if given); `off_path`
    gets, call by call, whether it is a move under cutter compensation."""
    stream = io.StringIO()
    calls: list[CanonCall] = []
    error = None
    with open(path, "rb") as f:
        try:
            for event in interpret(
                parse_stream(f, str(path)), file=str(path), warnings=Warnings(stream=stream), offsets=offsets
            ):
                call = canon_call(event)
                if call is not None:
                    calls.append(call)
                    if off_path is not None:
                        off_path.append(event.fixed == COMP or event.centre_shift is not None)  # type: ignore[union-attr]
        except NcppError as err:
            error = err
    return calls, error, stream.getvalue()


def refused_alike(refused: tuple[str, str] | None, error: NcppError | None) -> bool:
    """Whether rs274 (its `rs274_error`) and ncpp both refused the program, asserting that
    they agree: both accept, or both refuse with the same message."""
    assert (refused is None) == (error is None), (refused, error)
    if refused is not None:
        assert refused[0] == error.message, (refused, error)  # type: ignore[union-attr]
    return refused is not None


def without_comp(
    reference: list[CanonCall], mine: list[CanonCall], off_path: list[bool]
) -> tuple[list[CanonCall], list[CanonCall]]:
    """rs274's calls and ncpp's with the runs of moves under cutter compensation left out: each
    run of ncpp's is matched to the calls of rs274's before the first place where the run of
    ncpp's calls after it agrees (all of rs274's rest when none follows, or none agrees)."""
    runs: list[tuple[bool, list[CanonCall]]] = []
    for call, off in zip(mine, off_path):
        if runs and runs[-1][0] == off:
            runs[-1][1].append(call)
        else:
            runs.append((off, [call]))
    theirs: list[CanonCall] = []
    kept: list[CanonCall] = []
    j = 0
    for n, (off, calls) in enumerate(runs):
        if not off:
            theirs += reference[j : j + len(calls)]
            kept += calls
            j += len(calls)
            continue
        after = runs[n + 1][1] if n + 1 < len(runs) else []
        shifts = (
            s
            for s in range(len(reference) - j)
            if after and same_calls(reference[j + s : j + s + len(after)], after)
        )
        j += next(shifts, len(reference) - j)
    return theirs, kept


def write_program(folder, text: str, name: str = "program.ngc"):
    """A program file for rs274 (ending with M2 unless it does)."""
    path = folder / name
    path.write_text(text + ("" if text.rstrip().endswith("M2") else "M2\n"))
    return path


def same_calls(reference: list[CanonCall], mine: list[CanonCall]) -> bool:
    """The calls they have in common agree (names, and arguments within TOLERANCE)."""
    return all(
        want.name == got.name and all(abs(a - b) <= TOLERANCE for a, b in zip(want.args, got.args))
        for want, got in zip(reference, mine)
    )


def assert_agrees_with_rs274(path) -> list[CanonCall]:
    """rs274 accepts the program; ncpp reads it without error or warning, the same moves."""
    calls, messages = rs274(str(path))
    assert rs274_error(messages) is None, messages
    reference = read_canon(calls)
    mine, error, warning = ours(path)
    assert error is None and not warning, (error, warning)
    assert len(mine) == len(reference) and same_calls(reference, mine), (reference, mine)
    return mine


def assert_refused_like_rs274(path, line: int) -> None:
    """rs274 and ncpp both refuse the program, on line `line`."""
    _, messages = rs274(str(path))
    refused = rs274_error(messages)
    text = path.read_text().splitlines()
    assert refused is not None and refused[1].strip() == text[line - 1].strip(), messages
    _, error, _ = ours(path)
    assert error is not None and error.where.line == line, error


def assert_same_moves(path, reference: list[CanonCall], mine: list[CanonCall]) -> None:
    for index, (want, got) in enumerate(zip(reference, mine)):
        same = want.name == got.name and all(abs(a - b) <= TOLERANCE for a, b in zip(want.args, got.args))
        assert same, f"{corpus_id(path)}: move {index + 1}: rs274 {want} but ncpp {got}"


@pytest.mark.parametrize("path", PROGRAMS, ids=corpus_id)
def test_motion_agrees_with_linuxcnc(path):
    calls, messages = rs274(str(path))
    refused = rs274_error(messages)
    off_path: list[bool] = []
    mine, error, warning = ours(path, off_path)
    reference, mine = without_comp(read_canon(calls), mine, off_path)
    name = corpus_id(path)
    assert_same_moves(path, reference, mine)
    if warning:
        assert name in OUT_OF_SCOPE, (
            f"{corpus_id(path)} left the interpreter's scope but is not listed: {warning}"
        )
        assert OUT_OF_SCOPE[name] in warning, warning
        return
    assert name not in OUT_OF_SCOPE, f"{corpus_id(path)} is listed as out of scope but is interpreted"
    if refused is None:
        assert error is None, f"rs274 accepts {corpus_id(path)} but ncpp refuses it: {error}"
        assert name not in RS274_ONLY_REFUSES
        assert len(mine) == len(reference), (
            f"{corpus_id(path)}: rs274 made {len(reference)} moves, ncpp {len(mine)}"
        )
        return
    message, source = refused
    if error is not None:
        block_text = _line_text(path, error.where.line)
        assert block_text.strip() == source.strip(), f"rs274 refused {source!r} ({message}), ncpp {error}"
        assert len(mine) == len(reference)
        return
    assert name in RS274_ONLY_REFUSES, (
        f"rs274 refuses {corpus_id(path)} ({message} at {source!r}), ncpp does not"
    )
    assert len(mine) >= len(reference)


def _line_text(path, line: int) -> str:
    return path.read_bytes().decode("latin-1").splitlines()[line - 1]


def test_every_listed_file_exists(corpus):
    names = {corpus_id(p) for p in PROGRAMS}
    assert set(OUT_OF_SCOPE) <= names and set(RS274_ONLY_REFUSES) <= names


def test_blanks_inside_numbers_move_as_rs274_reads_them(tmp_path):
    """`X1 5` is X15, `X 2 0 . 5` is X20.5, `G 0 1` is G1, `[1 0]` is 10, `#3 1` is #31 and
    `o1 00` is o100: rs274ngc drops a line's blanks."""
    program = (
        "G21 G90 G17 F100\nG1 X1 5 Y2\nG1 X 2 0 . 5 Y- 1 2\nG 0 1 X3\nG2 X1 3 Y-1 2 I5 J0\nG 0 X1 . 5\n"
        "#1 = 1 0\nG1 X[#1 + 2 0] Y[1 . 5]\n#3 1 = 7\no1 00 sub\nG1 X#31\no100 endsub\no 100 call\n"
    )
    assert [call.args[:2] for call in assert_agrees_with_rs274(write_program(tmp_path, program))] == [
        (15.0, 2.0), (20.5, -12.0), (3.0, -12.0), (13.0, -12.0), (1.5, -12.0), (30.0, 1.5), (7.0, 1.5)
    ]  # fmt: skip
