"""The guards of a Fanuc or Haas file whose subprograms stand before its main program: the control
stores each O program of the file as its own, the operator runs the main one (which ends with M30),
and a subprogram (which ends with M99) runs only where M98 calls it (Fanuc Series 0i-MC operator's
manual, B-64124EN, "Subprogram (M98, M99)").  The placement guard goes after the main program's O
line, as after a program's number at its top, never into a stored subprogram, where it would run
only at the call (a main program that does not select its offset runs unguarded up to there, and a
call under G55 would stop on "G54 NOT ACTIVE").  The checks before a selection and after a G43 stand
by the block they check: in a subprogram's text only where it runs once, where its call runs them.

No Fanuc control runs here: the lines are compared with Custom Macro B's syntax as the module
docstring of `ncpp/guard.py` cites it (#4014 the G code of group 14, 54 for G54; #5221-#5223 G54's
X Y Z and #5241-#5243 G55's, 20 per system; `#3000=n (text)` raises macro alarm n and stops; `IF
[cond] THEN` one assignment), and Haas's tool length offsets (#2001-#2200 geometry, #2201-#2400
wear, Mill Operator's Manual, "Macros").  Every program here is written through ncpp's verifier,
which reads the guarded text back (`process` raises where it parts from the input)."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import Warnings
from ncpp.guard import MAIN_UNDECIDED, Placement, with_guard
from ncpp.motion.flow import MainProgram
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from tests.shop.test_guard import G54_MM, G55_MM, MACHINE, _compensate, _guarded

SUB = "O2000 (SIDE)\nG91 G1 X20 F300\nG90\nM99\n"
MAIN = "O1000 (MAIN)\nG21 G90 G17\nG0 X10 Y10 Z5\nG1 Z-1 F300\nM98 P2000\nG1 X40 Y30\nG0 Z5\nM30\n"
G54_GUARD = [
    "(NCPP PLACEMENT GUARD: G54 AT X400 Y350 Z300 MM WITHIN 0.1 MM)",
    "IF [#4014 NE 54] THEN #3000=1 (NCPP G54 NOT ACTIVE)",
    "IF [ABS[#5221-400] GT 0.1] THEN #3000=2 (NCPP G54 X MOVED)",
    "IF [ABS[#5222-350] GT 0.1] THEN #3000=3 (NCPP G54 Y MOVED)",
    "IF [ABS[#5223-300] GT 0.1] THEN #3000=4 (NCPP G54 Z MOVED)",
    "(NCPP PLACEMENT GUARD END)",
]
G55_CHECK = [
    "(NCPP PLACEMENT GUARD: G55 AT X600 Y350 Z300 MM WITHIN 0.1 MM)",
    "IF [ABS[#5241-600] GT 0.1] THEN #3000=2 (NCPP G55 X MOVED)",
    "IF [ABS[#5242-350] GT 0.1] THEN #3000=3 (NCPP G55 Y MOVED)",
    "IF [ABS[#5243-300] GT 0.1] THEN #3000=4 (NCPP G55 Z MOVED)",
    "(NCPP PLACEMENT GUARD END)",
]


def _program(lines: list[str], first: str) -> list[str]:
    """The lines of the program whose O line is `first`, to its M99 or M30."""
    start = lines.index(first)
    end = next(k for k in range(start, len(lines)) if lines[k] in ("M99", "M30"))
    return lines[start : end + 1]


def test_the_guard_stands_after_the_main_programs_o_line_and_not_in_the_stored_subprogram(tmp_path):
    text, said = _compensate(
        tmp_path, "--dialect", "fanuc", "--work-offset", "400,350,300", program=f"%\n{SUB}{MAIN}%\n"
    )  # (its exit status 0: the verifier read the guarded program back and passed it)
    lines = text.splitlines()
    main = lines.index("O1000 (MAIN)")
    assert lines[main + 1 : main + 7] == G54_GUARD and lines[main + 7] == "G21 G90 G17"
    sub = _program(lines, "O2000 (SIDE)")
    assert sub[-1] == "M99" and lines.index("M99") < main and not any("NCPP" in line for line in sub)
    assert text.count("PLACEMENT GUARD:") == 1 and "ncpp runs O1000 as the main program" in said
    assert "no placement guard" not in said


def test_a_stored_subprogram_called_under_g55_carries_no_check_of_g54():
    """The main program moves in G54, then selects G55 and calls O2000 there: the G54 test runs
    once at the main program's start, G55's zero before its block, and O2000 tests nothing."""
    program = (f"%\n{SUB}O1000 (MAIN)\nG21 G90 G17\nG0 X10 Y10 Z5\nG0 G55 X10 Y10\nG1 Z-1 F300\nM98 P2000\n"
               "G0 Z5\nM30\n%\n")  # fmt: skip
    text, again = _guarded(program.encode(), {"G54": G54_MM, "G55": G55_MM}, "fanuc")
    lines = text.splitlines()
    main = lines.index("O1000 (MAIN)")
    assert not any("NCPP" in line for line in lines[:main])
    assert lines[main + 1 : main + 7] == G54_GUARD
    g55 = next(k for k, line in enumerate(lines) if line.startswith("G0 G55 X"))
    assert lines[g55 - 5 : g55] == G55_CHECK and text.count("#4014") == 1
    assert (
        again.count(b"PLACEMENT GUARD:") == 2 and again.count(b"#4014") == 1
    )  # (compensated again: as once)


@pytest.mark.parametrize(
    "sub, main, start_checked",
    [
        # the subprogram selects G55 first: the main program still relies on the system in effect
        ("O2000\nG55\nG91 G1 X20 F300\nG90\nG54\nM99\n", "G0 X10 Y10 Z5\n", True),
        # the main program selects G55 in its first move's block: no test of the system in effect
        ("O2000\nG91 G1 X20 F300\nG90\nM99\n", "G0 G55 X10 Y10 Z5\n", False),
    ],
)  # fmt: skip
def test_the_check_at_the_start_looks_at_the_main_programs_first_lines(sub, main, start_checked):
    program = f"%\n{sub}O1000\nG21 G90 G17\n{main}G1 Z-1 F300\nM98 P2000\nG0 Z5\nM30\n%\n"
    text, _ = _guarded(program.encode(), {"G54": G54_MM, "G55": G55_MM}, "fanuc")
    lines = text.splitlines()
    after = lines[lines.index("O1000") + 1 :]
    assert (after[:6] == G54_GUARD) is start_checked and ("#4014" in text) is start_checked
    assert after[start_checked * 6] == "G21 G90 G17"


HAAS_SUB = "O2000 (TOOL AND G55)\nG55\nT1 M06\nG0 G43 H01 Z50.\nG91 G1 X20 F300\nG90\nG54\nM99\n"
HAAS_MAIN = "O1000 (MAIN)\nG21 G90 G17\nG0 X10 Y10 Z5\nG1 Z-1 F300\nM98 P2000\n{}G0 Z50.\nM30\n"
TOOL_CHECK = [
    "(NCPP TOOL GUARD: H1 AT LENGTH Z50 MM WITHIN 0.1 MM)",
    "IF [ABS[#2001+#2201-50] GT 0.1] THEN #3000=5 (NCPP H1 LENGTH DIFFERS)",
    "(NCPP TOOL GUARD END)",
]


def _haas(tmp_path, program: str) -> tuple[str, str]:
    table = tmp_path / "told.tbl"
    table.write_text("T1 P1 Z50 D6\n")
    offsets = WorkOffsets.given({"G54": G54_MM, "G55": G55_MM}, tool_table=table)
    said, out = io.StringIO(), io.BytesIO()
    process(io.BytesIO(program.encode()), out, file="p.nc", source=ErrorSource.from_machine_file(str(MACHINE)),
            offsets=offsets, warnings=Warnings(stream=said), guard=Placement.of(offsets), guard_tools=True,
            dialect="haas")  # fmt: skip
    return out.getvalue().decode(), said.getvalue()


def test_a_stored_subprogram_run_once_carries_its_checks_where_the_call_runs_them(tmp_path):
    """Called once, O2000's text is its one run: the G55 check before its G55 and the tool check
    after its G43 run when M98 runs those blocks (the control runs a subprogram's text at the call)."""
    text, said = _haas(tmp_path, f"%\n{HAAS_SUB}{HAAS_MAIN.format('')}%\n")
    lines = text.splitlines()
    sub = _program(lines, "O2000 (TOOL AND G55)")
    assert sub[1:7] == [*G55_CHECK, "G55"]
    g43 = next(k for k, line in enumerate(sub) if line.startswith("G0 G43 H01"))
    assert sub[g43 + 1 : g43 + 4] == TOOL_CHECK, sub
    main = lines.index("O1000 (MAIN)")
    assert lines[main + 1 : main + 7] == G54_GUARD, said  # (the G54 test at the start: not in O2000)
    assert text.count("#4014") == 1 and text.count("TOOL GUARD:") == 1


def test_a_stored_subprogram_run_twice_carries_no_checks(tmp_path):
    """Its text runs at each call, perhaps after the program set a zero or with another tool."""
    text, said = _haas(tmp_path, "%\n" + HAAS_SUB + HAAS_MAIN.format("M98 P2000\n") + "%\n")
    lines = text.splitlines()
    assert HAAS_SUB in text and "loop or subroutine" in said  # (as programmed)
    assert not any("NCPP" in line for line in _program(lines, "O2000 (TOOL AND G55)"))
    main = lines.index("O1000 (MAIN)")
    assert lines[main + 1 : main + 7] == G54_GUARD


def test_the_ordinary_layout_keeps_the_guard_after_the_first_programs_o_line():
    """The main program first, its subprogram after M30: the guard as before, after O1000."""
    program = f"%\n{MAIN}{SUB}%\n"
    text, again = _guarded(program.encode(), {"G54": G54_MM}, "fanuc")
    lines = text.splitlines()
    main = lines.index("O1000 (MAIN)")
    assert lines[main + 1 : main + 7] == G54_GUARD and not any("NCPP" in line for line in lines[main + 7 :])
    written = ["(ncpp header)\n", *program.splitlines(keepends=True)[1:]]
    placement = Placement(1, G54_MM)
    assert list(with_guard(written, placement, "fanuc", "ncpp header", main=MainProgram())) == list(
        with_guard(written, placement, "fanuc", "ncpp header")
    )


def test_where_the_main_program_is_not_decided_no_guard_is_written():
    """Two later programs end with M30: which one the operator runs is not ncpp's to guess."""
    program = f"%\n{SUB}O1000\nG0 X10 Y10 Z5\nM30\nO1001\nG0 X20\nM30\n%\n"
    said = io.StringIO()
    offsets = WorkOffsets.given({"G54": G54_MM})
    out = io.BytesIO()
    process(io.BytesIO(program.encode()), out, file="p.nc", source=ErrorSource.from_machine_file(str(MACHINE)),
            offsets=offsets, warnings=Warnings(stream=said), guard=Placement.of(offsets), dialect="fanuc")  # fmt: skip
    assert "NCPP" not in out.getvalue().decode()
    assert f"no placement guard: {MAIN_UNDECIDED}; make sure the control has G54" in said.getvalue()


def test_the_guard_finds_the_main_programs_o_line_as_the_flow_reads_program_numbers():
    """A stored program's O line with words after it (`O2000 G91`) is a program number to the flow;
    where the line found after the stored programs is not the main one's, no guard is written."""
    placement = Placement(1, G54_MM)
    written = [
        "%\n",
        "(ncpp header)\n",
        "O2000 G91 G1 X20 F300\n",
        "G90\n",
        "M99\n",
        "O1000\n",
        "G0 X1\n",
        "M30\n",
    ]
    told: list[str] = []
    guarded = list(with_guard(written, placement, "fanuc", "ncpp header", unguarded=told.append,
                              main=MainProgram(1, "1000")))  # fmt: skip
    k = guarded.index("O1000\n")
    assert guarded[: k + 1] == written[:6] and guarded[k + 1] == G54_GUARD[0] + "\n" and not told
    assert guarded[k + 7 :] == written[6:]
    other = list(with_guard(written, placement, "fanuc", "ncpp header", unguarded=told.append,
                            main=MainProgram(1, "1001")))  # fmt: skip
    assert other == written and told == [
        "ncpp did not find the O line of the main program, O1001, in the written program"
    ]
