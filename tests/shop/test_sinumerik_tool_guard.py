"""Sinumerik's tool guard: after each M6 or D that selects an edge of the told tool offsets
(`_N_TO_INI`), the program checks the active tool offset's length 1, $P_AD[3] + $P_AD[12] +
$P_AD[21] (geometry, wear and adapter of the edge in effect: `ncpp/guard.py`'s docstring), and
stops with cycle alarm 65001 where it is not the length ncpp compensated for."""

from __future__ import annotations

import io
import re
from dataclasses import replace
from pathlib import Path

from ncpp.errors import Warnings
from ncpp.guard import TOOL_BEGIN, TOOL_END, sinumerik_tool_guard_lines, without_guard
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import Line
from ncpp.motion.tools import ToolTable
from ncpp.pipeline import ErrorSource, dialect_tools, process
from ncpp.program.dialects import parse_program
from tests.compensation.test_dialect_tool_lengths import SINUMERIK, TO_INI
from tests.conftest import ROOT

MACHINE = ROOT / "samples/machines/hr5b.toml"
G54_MM = (400.0, 350.0, 300.0)


def test_the_check_text_for_a_length_in_mm_in_inch_and_below_zero():
    assert sinumerik_tool_guard_lines(2, 150.0, 1.0) == [
        f"; {TOOL_BEGIN} D2 at length 1 = 150 mm within 0.1 mm",
        "IF ABS($P_AD[3]+$P_AD[12]+$P_AD[21]-150)>0.1",
        'MSG("ncpp: compensated for D2 at length 1 = 150 mm: the control\'s active tool offset differs")',
        "SETAL(65001)",
        "M0",
        "ENDIF",
        f"; {TOOL_END}",
    ]
    assert sinumerik_tool_guard_lines(1, 50.8, 25.4)[1] == "IF ABS($P_AD[3]+$P_AD[12]+$P_AD[21]-2)>0.0039"
    assert sinumerik_tool_guard_lines(1, -5.25, 1.0)[1] == "IF ABS($P_AD[3]+$P_AD[12]+$P_AD[21]+5.25)>0.1"


def _offsets(tmp_path: Path) -> WorkOffsets:
    (tmp_path / "_N_TO_INI").write_text(TO_INI)
    return replace(WorkOffsets.at(G54_MM), tools=ToolTable.from_file(tmp_path / "_N_TO_INI"))


def _compensated(program: bytes, offsets: WorkOffsets, guard: bool = True, force: bool = False) -> str:
    """The program compensated (and verified: `process` raises where the written one parts)."""
    out = io.BytesIO()
    process(io.BytesIO(program), out, file="p.mpf", source=ErrorSource.from_machine_file(str(MACHINE)),
            offsets=offsets, warnings=Warnings(stream=io.StringIO()), guard_tools=guard, dialect="sinumerik",
            force=force)  # fmt: skip
    return out.getvalue().decode()


def _checks(written: str) -> list[tuple[str, str]]:
    """(the block before each check, the check's IF line)."""
    lines = written.splitlines()
    return [
        (lines[n - 1], lines[n + 1]) for n, line in enumerate(lines) if line.startswith(f"; {TOOL_BEGIN}")
    ]


def test_a_check_follows_each_m6_and_d_that_selects_a_told_edge(tmp_path):
    """SINUMERIK's blocks: N20 loads D10_ENDMILL with D1 (150.02 - 0.02), N40 tool 2 with D1
    (40 + adapter 0.5), N100 tool 1 with D2 (100); N60's G18 selects no edge, N80's D0 none."""
    written = _compensated(SINUMERIK, _offsets(tmp_path))
    assert _checks(written) == [
        ('N20 T="D10_ENDMILL" M6', "IF ABS($P_AD[3]+$P_AD[12]+$P_AD[21]-150)>0.1"),
        ("N40 D1 M6 T2", "IF ABS($P_AD[3]+$P_AD[12]+$P_AD[21]-40.5)>0.1"),
        ("N100 T1 M6 D2", "IF ABS($P_AD[3]+$P_AD[12]+$P_AD[21]-100)>0.1"),
    ]
    assert "tool guard" not in _compensated(SINUMERIK, _offsets(tmp_path), guard=False)


def _moves(text: str, offsets: WorkOffsets) -> list[tuple[float, ...]]:
    interpret, _ = dialect_tools("sinumerik")
    blocks = without_guard(parse_program(io.BytesIO(text.encode()), "p.mpf", "sinumerik")[1])
    events = interpret(blocks, file="p.mpf", warnings=Warnings(stream=io.StringIO()), offsets=offsets)
    return [event.end for event in events if type(event) is Line]


def test_the_checks_change_no_move_and_readers_and_force_drop_them(tmp_path):
    """The guarded program reads (guards dropped) as the one written without them, its text with
    the checks cut out is that one, and compensated again (--force) it carries each check once."""
    offsets = _offsets(tmp_path)
    written, plain = _compensated(SINUMERIK, offsets), _compensated(SINUMERIK, offsets, guard=False)
    cut = re.sub(rf"; {TOOL_BEGIN}.*?; {TOOL_END}\n", "", written, flags=re.S)
    assert cut == plain and written.count("\n") == plain.count("\n") + 3 * 7
    assert _moves(written, offsets) == _moves(plain, offsets) != []
    again = _compensated(written.encode(), offsets, force=True)
    assert again.count(TOOL_BEGIN) == 3 and again.count("SETAL(65001)") == 3


def test_an_edge_selected_in_a_loop_gets_no_check(tmp_path):
    """A loop's body runs again, perhaps with another edge: no check inside it."""
    loop = b"N10 G90 G17 G71\nR1=0\nWHILE R1<2\nT1 M6 D2\nG1 X5 F100\nR1=R1+1\nENDWHILE\nT2 M6\nG1 X10\nM30\n"
    assert [line for _, line in _checks(_compensated(loop, _offsets(tmp_path)))] == [
        "IF ABS($P_AD[3]+$P_AD[12]+$P_AD[21]-40.5)>0.1"
    ]


def test_with_expand_the_checks_are_those_of_the_blocks_that_run_in_place(tmp_path):
    """--expand writes a loop's runs out; the checks follow the blocks that run where they stand."""
    out = io.BytesIO()
    loop = b"N10 G90 G17 G71\nR1=0\nWHILE R1<2\nT1 M6 D2\nG1 X5 F100\nR1=R1+1\nENDWHILE\nT2 M6\nG1 X10\nM30\n"
    for program, checked in ((SINUMERIK, ["150", "40.5", "100"]), (loop, ["40.5"])):
        process(io.BytesIO(program), out, file="p.mpf", source=ErrorSource.from_machine_file(str(MACHINE)),
                offsets=_offsets(tmp_path), warnings=Warnings(stream=io.StringIO()), guard_tools=True,
                dialect="sinumerik", expand=True)  # fmt: skip
        written, out = out.getvalue().decode(), io.BytesIO()
        assert [line.rsplit("-", 1)[1].split(")")[0] for _, line in _checks(written)] == checked, written
