"""The placement guard's check of the G92 offset (`guard.g92_lines`), judged by LinuxCNC's rs274.

A G92 that sets the offset of axes the program has not positioned sets it from where the tool
stands (LinuxCNC G-code manual, "G92 Coordinate System Offset"), which ncpp takes to be the
program's zero; the check after it reads #5211-#5213, the G92 offset ("Numbered Parameters", in
the machine's units), and stops the program where it differs, before any move after the G92.  A
G92.3 restores the offset saved in #5211-#5219 ("G92.3 Restore G92 Offsets"), checked after it.
The stand-alone rs274 starts with the tool at the machine zero and reads its files in inches."""

from __future__ import annotations

import io
import re
import subprocess
from pathlib import Path

import pytest

from ncpp.errors import Warnings
from ncpp.guard import Placement
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import Line
from ncpp.pipeline import ErrorSource, process
from tests import rs274
from tests.compensation.conftest import events_of
from tests.conftest import SHARED
from tests.rs274 import linuxcnc_root

WIDE = SHARED / "machines" / "wide.toml"  # (its travel holds the programs at the machine zero)
TABLE = "T1 P1 D0.25 Z0\n"
CHECK = "the G92 offset"  # (what the check's comments say)
# a hobby program's start: the tool jogged to the part's zero, G92 makes it the program's
PROGRAM_MM = "G21 G90\nG92 X10 Y5 Z0\nG0 X20 Y15 Z5\nG1 Z-1 F300\nG1 X50 Y15\nG1 X50 Y35\nG0 Z5\nM2\n"
PROGRAM_INCH = "G20 G90\nG92 X0 Y0 Z0\nG0 X0.5 Y0.5 Z0.2\nG1 Z-0.04 F10\nG1 X1.5\nG1 Y1.2\nG0 Z0.2\nM2\n"


def _var_file(
    path: Path,
    g54_mm: tuple[float, float, float],
    g92_mm: tuple[float, float, float] | None = None,
    applied=True,
) -> Path:
    """A parameter file in inches (the stand-alone rs274's units): G54 in effect at `g54_mm`, and the
    G92 offset `g92_mm` in #5211-#5213, applied where `applied` (#5210)."""
    values = {5220: 1.0, **{5221 + k: v / 25.4 for k, v in enumerate(g54_mm)}}
    if g92_mm is not None:
        values.update({5210: float(applied), **{5211 + k: v / 25.4 for k, v in enumerate(g92_mm)}})
    path.write_text("".join(f"{number}\t{value:.6f}\n" for number, value in sorted(values.items())))
    return path


def _compensated(tmp_path: Path, program: str, var_file: Path, name: str = "out.ngc") -> tuple[Path, str]:
    """The program compensated on the wide machine for the control of `var_file`, guarded, written
    beside the original (p.ngc); and the warnings.  `process` verified it."""
    if not WIDE.exists():
        pytest.skip(f"{WIDE} not found")
    (tmp_path / "p.ngc").write_text(program)
    offsets = WorkOffsets.given({}, var_file, 25.4)
    said, out = io.StringIO(), io.BytesIO()
    process(io.BytesIO(program.encode()), out, file="p.ngc", source=ErrorSource.from_machine_file(str(WIDE)),
            offsets=offsets, warnings=Warnings(stream=said), guard=Placement.of(offsets, 25.4))  # fmt: skip
    (tmp_path / name).write_bytes(out.getvalue())
    return tmp_path / name, said.getvalue()


def _program_file(folder: Path, text: str) -> Path:
    (folder / "program.ngc").write_text(text)
    return folder / "program.ngc"


def _run(program: Path, var_file: Path) -> subprocess.CompletedProcess:
    linuxcnc_root(var_file.parent)  # (skips the test where rs274 cannot run)
    table = var_file.with_suffix(".tbl")
    table.write_text(TABLE)
    return rs274.run(program, var_file=var_file, tool_table=table, timeout=120)


def _runs_as_the_original(tmp_path: Path, written: Path, var_file: Path) -> None:
    ran = _run(written, var_file)
    assert ran.returncode == 0 and "PROGRAM_END" in ran.stdout, ran.stderr
    rs274.pathcheck(tmp_path / "p.ngc", written, "--var-file", str(var_file), "--tool-table",
                    str(var_file.with_suffix(".tbl")), "--tol-mm", "0.05")  # fmt: skip


def _stops_at_the_check(written: Path, var_file: Path, moves_before: int = 0) -> str:
    """rs274's run stops at the check's abort, the moves before the G92 made and none after it."""
    stopped = _run(written, var_file)
    assert stopped.returncode != 0 and f"compensated for {CHECK}" in stopped.stderr, stopped.stderr
    assert "SET_G92_OFFSET" in stopped.stdout and "PROGRAM_END" not in stopped.stdout
    assert len(re.findall(r"STRAIGHT_(TRAVERSE|FEED)", stopped.stdout)) == moves_before, stopped.stdout
    return stopped.stderr


@pytest.mark.parametrize("program", [PROGRAM_MM, PROGRAM_INCH], ids=["G21", "G20"])
def test_rs274_runs_a_g92_program_where_the_tool_stands_at_the_zero_told_and_stops_it_where_not(
    tmp_path, program
):
    """Told G54 at the machine zero, where rs274 starts: the G92 sets the offset ncpp compensated
    for, and the program runs the original's path.  Told G54 at X400 Y350 Z300 (the control's
    too: the check at the start passes), the tool still at the machine zero: the G92 sets
    #5211 = -400 mm, and the program stops before its first move."""
    at_zero = _var_file(tmp_path / "zero.var", (0.0, 0.0, 0.0))
    written, said = _compensated(tmp_path, program, at_zero)
    text = written.read_text()
    lines = text.splitlines()
    k = lines.index(program.splitlines()[1])  # the G92, as programmed: the control stands at no move yet
    assert lines[k + 1].startswith(f"(ncpp placement guard: {CHECK} ")
    assert lines[k + 5] == "(ncpp placement guard end)"
    if program is PROGRAM_MM:  # (G92 X10 at the program's zero: the offset is -10 mm, in inches)
        assert "[ABS[#5211 + 0.3937] GT 0.0039] OR [ABS[#5212 + 0.1969] GT 0.0039]" in lines[k + 2]
    assert "the placement guard's check after it stops the program" in said
    _runs_as_the_original(tmp_path, written, at_zero)

    elsewhere = _var_file(tmp_path / "elsewhere.var", (400.0, 350.0, 300.0))
    written, _ = _compensated(tmp_path, program, elsewhere, "elsewhere.ngc")
    said = _stops_at_the_check(written, elsewhere)
    set_there = "X-16.141732 Y-13.976378" if program is PROGRAM_MM else "X-15.748031 Y-13.779528"
    assert f"this G92 set {set_there} Z-11.811024" in said, said  # (rs274 writes the parameters in)


def test_rs274_checks_only_the_axes_the_program_had_not_positioned(tmp_path):
    """`G0 X10 Y10` then `G92 Z0`: X and Y stand where the program put them, Z where the operator
    left it (the machine zero in rs274), which the check of #5213 alone tells."""
    program = "G21 G90\nG0 X10 Y10\nG92 Z0\nG0 Z5\nG1 Z-1 F300\nG1 X40\nG0 Z5\nM2\n"
    z_at_zero = _var_file(tmp_path / "z0.var", (400.0, 350.0, 0.0))
    written, said = _compensated(tmp_path, program, z_at_zero)
    check = next(line for line in written.read_text().splitlines() if line.startswith("o<ncpp_guard_1> if"))
    assert "#5213" in check and "#5211" not in check and "#5212" not in check
    assert "has not positioned Z yet" in said
    _runs_as_the_original(tmp_path, written, z_at_zero)

    z_above = _var_file(tmp_path / "z300.var", (400.0, 350.0, 300.0))
    written, _ = _compensated(tmp_path, program, z_above, "z300.ngc")
    said = _stops_at_the_check(written, z_above, moves_before=1)
    assert "this G92 set Z-11.81" in said  # (-300 mm: the tool at the machine's Z0)


def test_rs274_checks_a_g92_made_under_a_g92_offset_of_the_parameter_file(tmp_path):
    """With a G92 offset in effect at the start (#5210 1, #5211 10 mm), the program's zero is
    G54's plus it: told G54 at X-10, that is the machine zero where rs274 starts, and the new
    offset (the old one gone: rs274ngc makes the block's point the tool's) is the one ncpp
    compensated for; told G54 at X0, ncpp takes the tool to stand at X10, and the check stops it."""
    program = "G21 G90\nG92 X0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG0 Z5\nM2\n"
    shifted = _var_file(tmp_path / "shifted.var", (-10.0, 0.0, 0.0), (10.0, 0.0, 0.0))
    written, _ = _compensated(tmp_path, program, shifted)
    assert "[ABS[#5211 - 0.3937] GT 0.0039]]" in written.read_text()
    _runs_as_the_original(tmp_path, written, shifted)

    off_zero = _var_file(tmp_path / "off.var", (0.0, 0.0, 0.0), (10.0, 0.0, 0.0))
    written, _ = _compensated(tmp_path, program, off_zero, "off.ngc")
    assert "this G92 set X0.000000:" in _stops_at_the_check(written, off_zero)


def test_rs274_checks_the_offset_a_g92_3_restores(tmp_path):
    """#5211-#5213 hold a G92 offset not in effect (#5210 0, as G92.2 leaves them): G92.3 applies
    it, and ncpp follows it there; a control that saved another stops at the check after it."""
    program = "G20 G90\nG0 X0.5 Y0.5 Z0.2\nG92.3\nG0 X0.5 Y0.5 Z0.2\nG1 Z-0.04 F10\nG1 X1.5\nG0 Z0.2\nM2\n"
    saved = _var_file(tmp_path / "saved.var", (0.0, 0.0, 0.0), (25.4, 50.8, 0.0), applied=False)
    written, _ = _compensated(tmp_path, program, saved)
    assert "(ncpp placement guard: the G92 offset X1 Y2 Z0 inch restored by G92.3" in written.read_text()
    _runs_as_the_original(tmp_path, written, saved)

    other = _var_file(tmp_path / "other.var", (0.0, 0.0, 0.0), (25.4, 0.0, 0.0), applied=False)
    said = _stops_at_the_check(written, other, moves_before=1)
    assert "the control restored X1.000000 Y0.000000 Z0.000000" in said


def test_the_interpreter_applies_the_saved_offset_at_g92_3_as_rs274_does(tmp_path):
    """The machine positions of the moves before and after a G92.3 of a parameter file whose #5210
    is 0: ncpp's, and rs274's (the move's point plus the G5X and G92 offsets it prints, inches)."""
    var = _var_file(tmp_path / "saved.var", (0.0, 0.0, 0.0), (25.4, 50.8, 0.0), applied=False)
    program = "G20 G90\nG0 X0.5 Y0 Z0\nG92.3\nG0 X0.5 Y0 Z0\nM2\n"
    offsets = WorkOffsets.from_var_file(var, 25.4)
    assert offsets.g92 == (0.0, 0.0, 0.0) and offsets.g92_saved == pytest.approx((25.4, 50.8, 0.0))
    moves = [e for e in events_of(program.encode(), offsets=offsets) if type(e) is Line]
    ours = [v / 25.4 for move in moves for v in move.context.to_machine(move.end)]
    calls = _run(_program_file(tmp_path, program), var).stdout
    offset = {"G5X": (0.0,) * 3, "G92": (0.0,) * 3}
    theirs: list[float] = []
    for name, args in re.findall(r"(SET_G5X_OFFSET|SET_G92_OFFSET|STRAIGHT_TRAVERSE)\((.*)\)", calls):
        values = [float(v) for v in args.split(",")]
        if name == "STRAIGHT_TRAVERSE":
            theirs += [p + z + g for p, z, g in zip(values[:3], offset["G5X"], offset["G92"], strict=True)]
        else:
            offset[name[4:7]] = tuple(values[1:4] if name == "SET_G5X_OFFSET" else values[:3])
    assert theirs == pytest.approx([0.5, 0, 0, 1.5, 2, 0], abs=1e-4)
    assert ours == pytest.approx(theirs, abs=1e-4)


def _warned(program: str, guard: bool = True, var_units: float = 1.0) -> tuple[str, str]:
    """The program compensated for G54 at X400 Y350 Z300 mm (guarded unless not `guard`), and the warnings."""
    if not WIDE.exists():
        pytest.skip(f"{WIDE} not found")
    offsets = WorkOffsets.given({"G54": (400.0, 350.0, 300.0)}, unit_mm=var_units)
    said, out = io.StringIO(), io.BytesIO()
    process(io.BytesIO(program.encode()), out, file="p.nc", source=ErrorSource.from_machine_file(str(WIDE)),
            offsets=offsets, warnings=Warnings(stream=said),
            guard=Placement.of(offsets, var_units) if guard else None)  # fmt: skip
    return out.getvalue().decode(), said.getvalue()


G92_FIRST = "G21 G90\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM2\n"


def test_an_mm_machine_checks_in_mm_and_each_check_has_a_label_of_its_own():
    program = "G21 G90\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG92.3\nG1 X40\nM2\n"
    written, _ = _warned(program, var_units=1.0)
    lines = written.splitlines()
    far = "[[ABS[#5211 - 0] GT 0.1] OR [ABS[#5212 - 0] GT 0.1] OR [ABS[#5213 - 0] GT 0.1]]"
    assert lines.count(f"o<ncpp_guard_1> if {far}") == 1 and lines.count(f"o<ncpp_guard_2> if {far}") == 1
    assert (
        "(ncpp placement guard: the G92 offset X0 Y0 Z0 mm set with the tool at the program's zero" in written
    )
    assert all(len(line) <= 255 for line in lines)  # (rs274ngc reads lines of up to 255 characters)


@pytest.mark.parametrize(
    "program",
    [
        "%\nO1234\nG21 G90\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM30\n%\n",  # Fanuc's: no variable cited
        "G21 G90\nG10 L20 P1 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM2\n",  # (G10 L20: no G92 offset)
    ],
    ids=["fanuc", "g10-l20"],
)
def test_no_check_where_the_control_gives_no_g92_offset_to_read_and_the_warning_stays(program):
    written, said = _warned(program)
    assert CHECK not in written and "#5211" not in written
    assert "has not positioned X and Y and Z yet" in said and "placement guard's check" not in said


@pytest.mark.parametrize(
    "program",
    [
        "G21 G90\nG0 X1 Y1 Z5\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM2\n",  # (placed: ncpp knows where)
        "G21 G90\nG92.1\nG0 X10 Y10 Z5\nG92.2\nG1 Z-1 F300\nG1 X40\nM2\n",  # (they set the offset 0)
        "G21 G90\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG92 X0 Y0 Z0",  # (a last line: nothing runs after it)
    ],
    ids=["positioned", "g92.1-g92.2", "last-line"],
)
def test_no_check_where_ncpp_knows_the_offset_or_nothing_runs_after_it(program):
    written, _ = _warned(program)
    assert CHECK not in written


def test_no_check_with_no_guard():
    written, said = _warned(G92_FIRST, guard=False)
    assert CHECK not in written and "has not positioned" in said and "placement guard's check" not in said
