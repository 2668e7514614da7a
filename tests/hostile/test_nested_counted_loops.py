"""A counted loop around a counted loop, whose passes (each a whole run of the inner loop) would
run more lines again than the bound, is refused at its own line as soon as the inner loop's first
pass has shown its length: not after a whole run of the inner loop (hundreds of thousands of
lines, each written out under --expand).  Loops within the bound still run.

The bound is lowered here; the moves made before the refusal say how early it came."""

from __future__ import annotations

import io
from collections.abc import Iterator

import pytest

import ncpp.motion.flow as flow
from ncpp.errors import NcppError
from ncpp.motion import interpret
from ncpp.motion.segments import Line
from ncpp.program.dialects import parse_program
from ncpp.program.parser import parse_stream

BOUND = 20_000


@pytest.fixture(autouse=True)
def _lower_bound(monkeypatch):
    monkeypatch.setattr(flow, "MAX_RERUN", BOUND)


def _iso(text: str) -> Iterator:
    return interpret(parse_stream(io.BytesIO(text.encode()), "t.ngc"), file="t.ngc")


def _sinumerik(text: str) -> Iterator:
    from ncpp.motion.sinumerik import interpret as run

    _, blocks = parse_program(io.BytesIO(text.encode()), "t.mpf", "sinumerik")
    return run(blocks, file="t.mpf")


def _klartext(text: str) -> Iterator:
    from ncpp.pipeline import dialect_tools

    run, _ = dialect_tools("heidenhain")
    _, blocks = parse_program(io.BytesIO(text.encode()), "t.h", "heidenhain")
    return run(blocks, file="t.h")


def _moves_before_refusal(events: Iterator) -> tuple[int, NcppError]:
    moves = 0
    with pytest.raises(NcppError) as err:
        for event in events:
            moves += type(event) is Line
    return moves, err.value


ISO = "G21 G90 G17 F200\nG0 X0 Y0 Z5\no1 repeat [100]\no2 repeat [{inner}]\nG1 X10\nG1 X0\n" + (
    "o2 endrepeat\no1 endrepeat\nM2\n"
)
SINUMERIK = "G17 G90 G71 F200\nG0 X0 Y0 Z5\nFOR R1=1 TO 100\nFOR R2=1 TO {inner}\nG1 X10\nG1 X0\n" + (
    "ENDFOR\nENDFOR\nM30\n"
)
KLARTEXT = """0 BEGIN PGM LOOP MM
1 TOOL CALL 1 Z S1000
2 L X+0 Y+0 Z+5 R0 FMAX
3 LBL 1
4 LBL 2
5 L X+10 R0 F200
6 L X+0 R0 F200
7 CALL LBL 2 REP {inner}
{between}8 CALL LBL 1 REP 100
9 L Z+50 R0 FMAX
10 END PGM LOOP MM
"""
CASES = {
    "o-word repeat": (_iso, ISO, "t.ngc", 3, "o1 repeat"),
    "Sinumerik FOR": (_sinumerik, SINUMERIK, "t.mpf", 3, "FOR ... ENDFOR"),
    "Klartext CALL LBL REP": (_klartext, KLARTEXT.replace("{between}", ""), "t.h", 9, "CALL LBL ... REP"),
}


@pytest.mark.parametrize("name", CASES)
def test_the_outer_loop_is_refused_at_its_line_at_the_inner_loops_first_pass(name):
    run, text, file, line, what = CASES[name]
    moves, err = _moves_before_refusal(run(text.replace("{inner}", "2000")))
    assert (err.where.file, err.where.line) == (file, line), err
    assert f"{what} would run" in err.message and f"more than {BOUND:,} lines run again" in err.message
    assert moves < 10  # (not after the inner loop's 4000 moves)


@pytest.mark.parametrize(
    "name, moves",
    [("o-word repeat", 1 + 2 * 20 * 100), ("Sinumerik FOR", 1 + 2 * 20 * 100),
     ("Klartext CALL LBL REP", 1 + 2 * 21 * 101 + 1)],  # (REP k: k passes more than the first)
)  # fmt: skip
def test_nested_loops_within_the_bound_run_all_their_passes(name, moves):
    run, text, *_ = CASES[name]
    assert len([e for e in run(text.replace("{inner}", "20")) if type(e) is Line]) == moves


def test_a_klartext_section_whose_outer_repeat_a_jump_passes_over_is_not_refused():
    """The REP call after a jump may never run: the inner section's passes alone count."""
    text = (
        KLARTEXT.replace("{inner}", "2000")
        .replace("{between}", "7 FN 9: IF +0 EQU +0 GOTO LBL 3\n")
        .replace("9 L Z+50 R0 FMAX", "9 LBL 3\n9 L Z+50 R0 FMAX")
    )
    moves = [e for e in _klartext(text) if type(e) is Line]
    assert len(moves) == 1 + 2 * 2001 + 1
