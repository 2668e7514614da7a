"""The tool guard: after each G43 that applies a length of the tool table ncpp was told, a
LinuxCNC program checks the control's tool in the spindle (#5400) and its length (#5403).
LinuxCNC's rs274 judges it: the program runs to its end with the told table and stops at the
check with a table whose length differs."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
from pathlib import Path

from ncpp.errors import Warnings
from ncpp.guard import without_guard
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from tests import rs274
from tests.conftest import ROOT
from tests.rs274 import linuxcnc_root

MACHINE = ROOT / "samples/machines/hr5b.toml"
G54_MM = (400.0, 350.0, 300.0)
TOOL_BEGIN = "ncpp tool guard:"  # (the check's first comment)
TABLE = "T1 P1 Z50 D6\nT2 P2 Z75.5 D4\n"
PROGRAM = (
    "G21 G90 G54\n"
    "T1 M6\n"
    "G43 H1\n"  # (no move: the check comes before the first)
    "G0 X10 Y10 Z5\n"
    "G1 Z-1 F300\n"
    "G1 X40 Y10\n"
    "G0 Z5\n"
    "T2 M6 G43 Z20\n"  # (its own move runs with the length, before the check)
    "G0 X10 Y30\n"
    "G1 Z-2 F300\n"
    "G1 X40\n"
    "G0 Z20\n"
    "M2\n"
)


def _compensated(
    tmp_path: Path, program: str = PROGRAM, table: str | None = TABLE, guard: bool = True
) -> tuple[str, list[str]]:
    """The written program and the warnings, compensated with G54 and the tool table told."""
    tool_table = None
    if table is not None:
        tool_table = tmp_path / "told.tbl"
        tool_table.write_text(table)
    offsets = WorkOffsets.given({"G54": G54_MM}, tool_table=tool_table)
    said = io.StringIO()
    out = io.BytesIO()
    process(io.BytesIO(program.encode()), out, file="p.ngc", source=ErrorSource.from_machine_file(str(MACHINE)),
            offsets=offsets, warnings=Warnings(stream=said), guard_tools=guard)  # fmt: skip
    return out.getvalue().decode(), said.getvalue().splitlines()


def _rs274(tmp_path: Path, program: Path, table: str) -> subprocess.CompletedProcess:
    """rs274 started with G54 at the zero told and this tool table (both read raw: the check
    compares the table's numbers, in the machine's units, with the told ones)."""
    linuxcnc_root(tmp_path)  # (skips the test where rs274 cannot run)
    var_file = tmp_path / "g54.var"
    var_file.write_text("5220\t1\n" + "".join(f"{5221 + k}\t{v}\n" for k, v in enumerate(G54_MM)))
    tool_table = tmp_path / "control.tbl"
    tool_table.write_text(table)
    return rs274.run(program, var_file=var_file, tool_table=tool_table, timeout=60)


def test_rs274_runs_the_program_with_the_told_table_and_stops_at_a_length_that_differs(tmp_path):
    program, _ = _ncpp(tmp_path, PROGRAM, TABLE)
    written = program.read_text()
    ran = _rs274(tmp_path, program, TABLE)
    assert ran.returncode == 0 and "PROGRAM_END" in ran.stdout, ran.stderr
    assert ran.stdout.count("STRAIGHT_FEED") >= 6
    within = _rs274(tmp_path, program, "T1 P1 Z50.05 D6\nT2 P2 Z75.45 D4\n")  # within 0.1 mm
    assert within.returncode == 0 and "PROGRAM_END" in within.stdout, within.stderr

    second = _rs274(tmp_path, program, "T1 P1 Z50 D6\nT2 P2 Z75.7 D4\n")
    assert second.returncode != 0 and "PROGRAM_END" not in second.stdout
    assert "compensated for tool 2 at length Z75.5 mm" in second.stderr, second.stderr
    assert "the control has tool 2.000000 at Z75.700000" in second.stderr  # (rs274 says #5400 and #5403)
    before, after = second.stdout.split("CHANGE_TOOL(2)")
    assert before.count("STRAIGHT_FEED") >= 3  # tool 1's cuts ran; after tool 2's G43 block's own move,
    assert after.count("STRAIGHT_TRAVERSE") == 1 and "STRAIGHT_FEED" not in after  # none

    # `ncpp motion` reads the guarded program's moves as rs274 runs them (rs274 reads the
    # tables in inches, and prints program coordinates: the tool length's shift shows)
    from tests.rs274 import end_points

    told = WorkOffsets.given({}, tmp_path / "g54.var", 25.4, tmp_path / "told.tbl")
    read, run = _moves(written, told), end_points(ran.stdout)
    assert len(read) == len(run) and max(abs(a - b) for m, r in zip(read, run) for a, b in zip(m, r)) < 1e-4

    first = _rs274(tmp_path, program, "T1 P1 Z49.8 D6\nT2 P2 Z75.5 D4\n")
    assert first.returncode != 0 and "compensated for tool 1 at length Z50 mm" in first.stderr, first.stderr
    assert "STRAIGHT_TRAVERSE" not in first.stdout and "STRAIGHT_FEED" not in first.stdout


def test_the_check_follows_the_g43_block_and_names_the_tool_and_length_told(tmp_path):
    written, warned = _compensated(tmp_path)
    lines = written.splitlines()
    k = lines.index("G43 H1")
    assert lines[k + 1] == f"({TOOL_BEGIN} tool 1 at length Z50 mm within 0.1 mm)"
    assert lines[k + 2] == "o<ncpp_tool_guard_1> if [[#5400 NE 1] OR [ABS[#5403 - 50] GT 0.1]]"
    assert lines[k + 3].startswith("(abort, ncpp: compensated for tool 1 at length Z50 mm;")
    assert lines[k + 4:k + 6] == ["o<ncpp_tool_guard_1> endif", "(ncpp tool guard end)"]  # fmt: skip
    assert lines[k + 6].startswith("G0 X10.0")
    k = next(n for n, line in enumerate(lines) if line.startswith("T2 M6 G43 Z20"))
    assert lines[k + 2] == "o<ncpp_tool_guard_2> if [[#5400 NE 2] OR [ABS[#5403 - 75.5] GT 0.1]]"
    assert written.count(TOOL_BEGIN) == 2 and not warned


def _moves(text: str, offsets: WorkOffsets) -> list[tuple[float, ...]]:
    """The end points of the moves `ncpp motion` reads from a program."""
    from ncpp.cli.motion import interpreted
    from ncpp.motion.segments import Line

    _, events = interpreted(io.BytesIO(text.encode()), "p.ngc", None, Warnings(), offsets)
    return [event.end for event in events if type(event) is Line]


def test_ncpp_motion_reads_the_written_program_as_if_the_checks_were_not_there(tmp_path):
    """The verifier passed it (`process` verifies it against the input), and the motion command
    reads the same moves from it as from its text with the checks cut out."""
    written, _ = _compensated(tmp_path)
    offsets = WorkOffsets.given({"G54": G54_MM}, tool_table=tmp_path / "told.tbl")
    cut = re.sub(r"\(ncpp tool guard:.*?\(ncpp tool guard end\)\n", "", written, flags=re.S)
    assert cut.count("\n") == written.count("\n") - 10
    read = _moves(written, offsets)
    assert read == _moves(cut, offsets) and len(read) > len(_moves(PROGRAM, offsets))


def test_no_check_with_no_guard_without_a_table_or_for_another_tools_length(tmp_path):
    assert "tool guard" not in _compensated(tmp_path, guard=False)[0]
    assert "tool guard" not in _compensated(tmp_path, table=None)[0]
    # G43 H2 with tool 1 in the spindle: #5403 holds tool 1's length, not the one applied
    other = PROGRAM.replace("G43 H1", "G43 H2")
    written = _compensated(tmp_path, other)[0]
    assert written.count(TOOL_BEGIN) == 1 and "tool 2 at length" in written


def test_an_inch_machines_check_compares_the_tables_inches():
    """LinuxCNC's #5403 holds the table's number, in the machine's units (rs274 shows it)."""
    from ncpp.guard import tool_guard_lines

    lines = tool_guard_lines(3, 50.8, 25.4, 7)
    assert lines[0] == f"({TOOL_BEGIN} tool 3 at length Z2 inch within 0.1 mm)"
    assert lines[1] == "o<ncpp_tool_guard_7> if [[#5400 NE 3] OR [ABS[#5403 - 2] GT 0.0039]]"


def test_a_fanuc_program_gets_no_check_and_a_warning_that_says_what_is_not_cited(tmp_path):
    """No Fanuc manual at hand gives the system variables of the H offsets for each tool
    compensation memory, nor a variable of the tool in the spindle (`ncpp/guard.py`): the
    program gets no check, and the warning names both and the table to set on the control."""
    fanuc = "%\nO1234\n" + PROGRAM.replace("M2\n", "M30\n%\n")
    written, warned = _compensated(tmp_path, fanuc)
    assert "tool guard" not in written.lower() and "#3000=5" not in written
    said = [line for line in warned if "no tool guard" in line]
    assert len(said) == 1, warned
    assert "tool compensation memory (A, B or C" in said[0] and "cites from no Fanuc manual" in said[0]
    assert "no standard variable of the tool in the spindle (#4120 is the last T commanded)" in said[0]
    assert said[0].endswith("make sure the control's tool lengths are those of " + str(tmp_path / "told.tbl"))


def test_a_klartext_program_gets_no_tool_check_and_the_warning_says_which_manual_is_missing():
    """Klartext's active tool length (FN 18 ID200 NR2) is cited only from the iTNC 530's and
    TNC 426/430's technical manuals (`ncpp/guard.py`)."""
    from ncpp.guard import ToolGuard

    told: list[str] = []
    guard = ToolGuard("heidenhain", 1.0, told.append)
    assert guard.why is not None and told == [guard.why]
    assert "FN 18 read of the active tool length (ID200 NR2)" in told[0]
    assert "not from a TNC 640, TNC 620 or TNC7 manual" in told[0]


def test_a_guard_without_its_last_comment_is_no_guard():
    """A first comment alone (its check cut away by hand) leaves the program's blocks in place."""
    from ncpp.program.dialects import parse_program

    text = f"G0 X1\n({TOOL_BEGIN} tool 1 at length Z50 mm within 0.1 mm)\n" + "".join(
        f"G1 X{n} F100\n" for n in range(2, 20)
    )
    blocks = list(without_guard(parse_program(io.BytesIO(text.encode()), "p.ngc", "iso")[1]))
    assert len(blocks) == 20
    guarded = text.replace("G1 X5 ", "(ncpp tool guard end)\nG1 X5 ")
    kept = [b.raw for b in without_guard(parse_program(io.BytesIO(guarded.encode()), "p.ngc", "iso")[1])]
    assert kept[:2] == ["G0 X1", "G1 X5 F100"] and len(kept) == 16


def test_a_g43_in_a_loop_gets_no_check(tmp_path):
    """A loop's text runs again, perhaps with another tool: no check is written inside it."""
    loop = "o100 repeat [2]\nT1 M6 G43\nG0 X5\no100 endrepeat\n"
    program = PROGRAM.replace("T1 M6\nG43 H1\n", loop + "T1 M6\nG43 H1\n")
    written = _compensated(tmp_path, program)[0]
    assert written.count(TOOL_BEGIN) == 2 and written.index("o100 endrepeat") < written.index(TOOL_BEGIN)


HAAS = (
    "%\nO01234\nG21 G90 G17\nT1 M06\nG0 G43 H01 Z50.\nG0 G54 X10 Y10\nG1 Z-1 F300\nG1 X40 Y10\nG0 Z50.\n"
    "T2 M06\nG0 G43 H02 Z50.\nG0 X10 Y30\nG1 Z-2 F300\nG0 Z50.\nG187 P1\nM30\n%\n"
)


def _haas(tmp_path: Path, program: str) -> tuple[str, list[str], bytes]:
    """The Haas program compensated with the table told, and compensated again from it (--force)."""
    table = tmp_path / "told.tbl"
    table.write_text(TABLE)
    offsets = WorkOffsets.given({"G54": G54_MM}, tool_table=table)
    source = ErrorSource.from_machine_file(str(MACHINE))
    said, out, again = io.StringIO(), io.BytesIO(), io.BytesIO()
    process(io.BytesIO(program.encode()), out, file="p.nc", source=source, offsets=offsets,
            warnings=Warnings(stream=said), guard_tools=True, dialect="haas")  # fmt: skip
    process(io.BytesIO(out.getvalue()), again, file="p.nc", source=source, offsets=offsets, force=True,
            warnings=Warnings(stream=io.StringIO()), guard_tools=True, dialect="haas")  # fmt: skip
    return out.getvalue().decode(), said.getvalue().splitlines(), again.getvalue()


def test_a_haas_program_checks_the_length_offset_each_g43_applies(tmp_path):
    """Haas Mill Operator's Manual, "Macros": #2001-#2200 hold the tool length offsets (geometry),
    #2201-#2400 their wear; G43 Hn applies offset n's sum.  ncpp's verifier reads the written
    program past the checks (`process` raises where it parts), and compensating it again writes
    each check once."""
    written, warned, again = _haas(tmp_path, HAAS)
    lines = written.splitlines()
    k = next(n for n, line in enumerate(lines) if line.startswith("G0 G43 H01"))
    assert lines[k + 1 : k + 4] == [
        "(NCPP TOOL GUARD: H1 AT LENGTH Z50 MM WITHIN 0.1 MM)",
        "IF [ABS[#2001+#2201-50] GT 0.1] THEN #3000=5 (NCPP H1 LENGTH DIFFERS)",
        "(NCPP TOOL GUARD END)",
    ]
    assert "IF [ABS[#2002+#2202-75.5] GT 0.1] THEN #3000=5 (NCPP H2 LENGTH DIFFERS)" in lines
    assert not any("no tool guard" in line for line in warned), warned
    assert again.count(b"TOOL GUARD:") == 2 and again.count(b"#2201") == 1


def test_a_haas_g43_of_another_offset_than_the_spindles_tool_gets_no_check(tmp_path):
    """ncpp knows the length the table gives the tool in the spindle; an H of another offset
    (or none) applies a register it is not told of as that tool's."""
    written = _haas(tmp_path, HAAS.replace("T2 M06\n", ""))[0]  # (G43 H02 with tool 1 in the spindle)
    assert "#2001+#2201" in written and "#2002" not in written


def test_a_haas_program_that_sets_its_length_offsets_is_checked_at_them(tmp_path):
    """Haas's "G10 Set Offsets": `G10 L10 P1 R..` sets offset 1's length, `G10 L11 P1 R..` its wear;
    the control then holds them in #2001 and #2201, which the check after G43 H01 reads."""
    set_at_top = HAAS.replace("G21 G90 G17\n", "G21 G90 G17\nG10 L10 P1 R120.\nG10 L11 P1 R0.02\n")
    written, warned, _ = _haas(tmp_path, set_at_top)
    assert "IF [ABS[#2001+#2201-120.02] GT 0.1] THEN #3000=5 (NCPP H1 LENGTH DIFFERS)" in written
    assert "IF [ABS[#2002+#2202-75.5] GT 0.1] THEN #3000=5 (NCPP H2 LENGTH DIFFERS)" in written
    assert not any("outside" in line for line in warned), warned


# A program whose cuts depend on the tool's parameters (LinuxCNC G-code manual, "Numbered
# Parameters": #5401 the X offset, #5410 the diameter, #5411 #5412 the front and back angles): a
# pass offset by the radius, a branch on an angle, a subroutine that runs once and sizes its pass
READS = (
    "G21 G90 G54\n"
    "o<slot> sub\n"
    "  G1 X[40 + #5410 + #5412] F300\n"
    "o<slot> endsub\n"
    "T1 M6\n"
    "G43 H1\n"
    "G0 X10 Y10 Z5\n"
    "G0 Z1\n"
    "G1 Z-1 X[10 + #5410 / 2] F300\n"
    "o1 if [#5411 GT 5]\n"
    "G1 Y20\n"
    "o1 endif\n"
    "G1 X40 Y[10 + #5401]\n"
    "o<slot> call\n"
    "G0 Z5\n"
    "M2\n"
)
READ_TABLE = "T1 P1 X0.5 Z50 D6 I10 J2\nT2 P2 Z75.5 D4\n"


def _ncpp(tmp_path: Path, text: str, table: str, *options: str) -> tuple[Path, subprocess.CompletedProcess]:
    """The program compensated by `ncpp compensate` with G54 and the tool table told."""
    (tmp_path / "p.ngc").write_text(text)
    (tmp_path / "told.tbl").write_text(table)
    env = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    command = [
        "compensate",
        "--machine",
        str(MACHINE),
        "--work-offset",
        "400,350,300",
        "--tool-table",
        "told.tbl",
    ]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command, *options, "p.ngc", "-o", "out.ngc"],
                          capture_output=True, text=True, cwd=tmp_path,
                          env={**env, "PYTHONPATH": str(ROOT), "HOME": str(tmp_path)})  # fmt: skip
    assert proc.returncode == 0, proc.stderr  # (verified)
    return tmp_path / "out.ngc", proc


def test_rs274_stops_before_the_first_cut_that_reads_a_diameter_that_differs(tmp_path):
    """The told table's diameter, front angle and X offset are written into the cuts: rs274 runs
    the program to its end with that table (and one within the tolerances), and stops before the
    first cut with a diameter 0.2 mm larger, before the branch with another front angle, before
    the subroutine's pass (which runs at its call) with another X offset... each naming the
    parameter, the told value and the control's."""
    program, proc = _ncpp(tmp_path, READS, READ_TABLE)
    written = program.read_text()
    assert "X[10 + #5410" not in written and "G1 Z-0.9880 X13.0244 F300" in written  # (a number, compensated)
    ran = _rs274(tmp_path, program, READ_TABLE)
    assert ran.returncode == 0 and "PROGRAM_END" in ran.stdout, ran.stderr
    assert ran.stdout.count("STRAIGHT_FEED") >= 4
    within = _rs274(tmp_path, program, "T1 P1 X0.45 Z50 D6.05 I10.0005 J2\nT2 P2 Z75.5 D4\n")
    assert within.returncode == 0 and "PROGRAM_END" in within.stdout, within.stderr

    wider = _rs274(tmp_path, program, "T1 P1 X0.5 Z50 D6.2 I10 J2\nT2 P2 Z75.5 D4\n")
    assert wider.returncode != 0 and "PROGRAM_END" not in wider.stdout
    assert "compensated for tool 1 with diameter, parameter 5410, at 6 mm;" in wider.stderr, wider.stderr
    assert "the control has tool 1.000000 with 6.200000:" in wider.stderr
    assert "STRAIGHT_FEED" not in wider.stdout and "STRAIGHT_TRAVERSE" in wider.stdout  # (the rapids ran)

    turned = _rs274(tmp_path, program, "T1 P1 X0.5 Z50 D6 I4 J2\nT2 P2 Z75.5 D4\n")
    assert turned.returncode != 0 and "front angle, parameter 5411, at 10 deg;" in turned.stderr, (
        turned.stderr
    )
    assert turned.stdout.count("STRAIGHT_FEED") == 1  # (the first cut, not the branch's)

    shifted = _rs274(tmp_path, program, "T1 P1 X0.7 Z50 D6 I10 J2\nT2 P2 Z75.5 D4\n")
    assert shifted.returncode != 0 and "X offset, parameter 5401, at 0.5 mm;" in shifted.stderr, (
        shifted.stderr
    )
    assert shifted.stdout.count("STRAIGHT_FEED") == 2


def test_each_read_is_checked_once_before_its_block_and_a_subroutines_inside_its_body(tmp_path):
    """The check stands before the block that reads (a control line's condition too), inside the
    body of a subroutine that runs once (written where its definition stands, it runs at the
    call, before the pass), and a value checked in straight code is not checked again."""
    lines = _ncpp(tmp_path, READS, READ_TABLE)[0].read_text().splitlines()
    checks = [
        line
        for line in lines
        if line.startswith("o<ncpp_tool_guard_") and " if " in line and "#5403" not in line
    ]
    assert [line.split(" if ")[1] for line in checks] == [
        "[[#5400 NE 1] OR [ABS[#5412 - 2] GT 0.001]]",  # (in the body, whose #5410 is checked below first)
        "[[#5400 NE 1] OR [ABS[#5410 - 6] GT 0.1]]",
        "[[#5400 NE 1] OR [ABS[#5411 - 10] GT 0.001]]",
        "[[#5400 NE 1] OR [ABS[#5401 - 0.5] GT 0.1]]",
    ]
    following = [lines[lines.index(check) + 4] for check in checks]
    assert following[0].startswith("  G1 X48.") and following[1].startswith("G1 Z-0.98")
    assert following[2:] == ["o1 if [#5411 GT 5]", "G1 X13.0247 Y20.0167 Z-0.9880"]
    assert lines[lines.index(checks[0]) - 2] == "o<slot> sub"
    assert (
        lines[lines.index(checks[1]) - 1]
        == f"({TOOL_BEGIN} tool 1 with diameter, parameter 5410, at 6 mm within 0.1 mm)"
    )


def test_a_program_that_reads_no_tool_parameter_is_written_as_before_and_no_guard_leaves_the_checks_out(
    tmp_path,
):
    written, warned = _compensated(tmp_path)
    assert written.count(TOOL_BEGIN) == 2 and "#5410" not in written and not warned
    unguarded, _ = _compensated(tmp_path, READS, READ_TABLE, guard=False)
    assert "tool guard" not in unguarded


def test_a_read_in_a_loop_gets_no_check_and_a_warning(tmp_path):
    """A loop's text runs again, perhaps with another tool, and its moves are left as programmed:
    the control reads its own value there; ncpp warns that the read is not checked, once."""
    loop = "o2 repeat [2]\nG1 Y[10 + #5402]\no2 endrepeat\n"
    written, warned = _compensated(
        tmp_path, PROGRAM.replace("G1 X40 Y10\n", loop), "T1 P1 Y0.2 Z50 D6\nT2 P2 Z75.5 D4\n"
    )
    assert "#5402 NE" not in written and "ABS[#5402" not in written
    said = [line for line in warned if "no tool guard check of #5402 = 0.2" in line]
    assert len(said) == 1 and "p.ngc:7:" in said[0], warned


def test_an_inch_table_and_angles_and_the_orientation():
    from ncpp.guard import tool_read_lines

    lines = tool_read_lines(3, 5410, 0.25, 25.4, 4)
    assert lines[0] == f"({TOOL_BEGIN} tool 3 with diameter, parameter 5410, at 0.25 inch within 0.0039 inch)"
    assert lines[1] == "o<ncpp_tool_guard_4> if [[#5400 NE 3] OR [ABS[#5410 - 0.25] GT 0.0039]]"
    assert "ABS[#5412 + 7.5] GT 0.001]" in tool_read_lines(3, 5412, -7.5, 1.0, 5)[1]
    assert "ABS[#5413 - 2] GT 0.5]" in tool_read_lines(3, 5413, 2.0, 1.0, 6)[1]


def test_a_condition_read_in_a_loop_that_changes_the_tool_gets_no_check_inside_it(tmp_path):
    """Each run of the loop's text reads the diameter of another tool: a check written in it for
    the first would stop the second run; the reads are warned of, each tool's once, and the read
    after the loop is checked before its block."""
    loop = (
        "#<t> = 1\no2 repeat [2]\nT#<t> M6\nG43\nG0 X0 Y0 Z5\no1 if [#5410 GT 5]\nG1 X5 F100\no1 endif\n"
        "#<t> = 2\no2 endrepeat\nG1 X[#5410]\nM2\n"
    )
    written, warned = _compensated(tmp_path, "G21 G90 G54\n" + loop, TABLE)
    body = written[written.index("o2 repeat") : written.index("o2 endrepeat")]
    assert TOOL_BEGIN not in body and written.count(TOOL_BEGIN) == 1
    after = written.split("o2 endrepeat\n")[1].splitlines()
    assert after[1] == "o<ncpp_tool_guard_1> if [[#5400 NE 2] OR [ABS[#5410 - 4] GT 0.1]]"
    said = [line for line in warned if "no tool guard check of #5410" in line]
    assert len(said) == 2 and "= 6 (tool 1" in said[0] and "= 4 (tool 2" in said[1], warned


def test_a_while_condition_checked_before_the_loop_is_not_checked_again(tmp_path):
    """The condition's first read stands in straight code: its check before the `while` line runs
    once, and the reads of the same tool's value after it (the condition again, a cut after the
    loop) need none."""
    loop = "#1 = 0\no1 while [#1 LT #5410]\nG1 X[#1 + 20]\n#1 = [#1 + 2]\no1 endwhile\nG1 X[30 + #5410] Y30\n"
    written, warned = _compensated(tmp_path, PROGRAM.replace("G1 X40 Y10\n", loop))
    lines = written.splitlines()
    k = lines.index("o1 while [#1 LT #5410]")
    assert lines[k - 4] == "o<ncpp_tool_guard_2> if [[#5400 NE 1] OR [ABS[#5410 - 6] GT 0.1]]"
    assert written.count("ABS[#5410") == 1 and not any("no tool guard check" in line for line in warned)


def test_compensated_again_the_read_checks_go_with_a_warning(tmp_path):
    """The written program has numbers where the original read the parameters: compensated again
    (--force), each check is dropped with a warning at its line, and only the read left (the
    branch's condition) is checked again."""
    first = _ncpp(tmp_path, READS, READ_TABLE)[0]
    again, proc = _ncpp(tmp_path, first.read_text(), READ_TABLE, "--force")
    written = again.read_text()
    assert written.count(TOOL_BEGIN) == 2 and "ABS[#5403 - 50]" in written  # (the length's, after G43)
    assert "ABS[#5411 - 10]" in written and "ABS[#5410" not in written
    said = [line for line in proc.stderr.splitlines() if "compensated again, the check" in line]
    assert len(said) == 4 and "tool 1 with back angle, parameter 5412, at 2 deg" in said[0], proc.stderr
    assert "p.ngc:11:" in said[0] and said[0].endswith("compensate the original program instead")
