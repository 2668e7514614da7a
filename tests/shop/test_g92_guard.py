"""The placement guard's check of the G92 offset and of a G10 L20's zero (`guard.offset_lines`),
judged by LinuxCNC's rs274.

A G92 that sets the offset of axes the program has not positioned sets it from where the tool
stands (LinuxCNC G-code manual, "G92 Coordinate System Offset"), which ncpp takes to be the
program's zero; the check after it reads #5211-#5213, the G92 offset ("Numbered Parameters", in
the machine's units), and stops the program where it differs, before any move after the G92.  A
G92.3 restores the offset saved in #5211-#5219 ("G92.3 Restore G92 Offsets"), checked after it.
A G10 L20 Pn sets system n's zero (P0: the one in effect) so that the tool stands at the block's
coordinates ("G10 L20 Set Coordinate System"): the check after it reads #5221-#5223 + 20 (n - 1).
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
    system: int = 1,
) -> Path:
    """A parameter file in inches (the stand-alone rs274's units): `system` (1: G54) in effect at
    `g54_mm`, and the G92 offset `g92_mm` in #5211-#5213, applied where `applied` (#5210)."""
    x = 5221 + 20 * (system - 1)
    values = {5220: float(system), **{x + k: v / 25.4 for k, v in enumerate(g54_mm)}}
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


def _stops_at_the_check(
    written: Path, var_file: Path, moves_before: int = 0, check: str = CHECK, sets: str = "SET_G92_OFFSET"
) -> str:
    """rs274's run stops at the check's abort (`check` in its message), the moves before the block
    that sets the offset (`sets`, the call rs274 makes for it) made and none after it."""
    stopped = _run(written, var_file)
    assert stopped.returncode != 0 and f"compensated for {check}" in stopped.stderr, stopped.stderr
    assert sets in stopped.stdout and "PROGRAM_END" not in stopped.stdout
    assert len(re.findall(r"STRAIGHT_(TRAVERSE|FEED)", stopped.stdout)) == moves_before, stopped.stdout
    return stopped.stderr


TOUCHED = "the program's zero at machine"  # (what a touch-off's check says: a G92 or G10 L20 of X Y Z first)
L20_MM = "G21 G90\nG10 L20 P1 X10 Y5 Z0\nG0 X20 Y15 Z5\nG1 Z-1 F300\nG1 X50 Y15\nG1 X50 Y35\nG0 Z5\nM2\n"
L20_INCH = "G20 G90\nG10 L20 P0 X0 Y0 Z0\nG0 X0.5 Y0.5 Z0.2\nG1 Z-0.04 F10\nG1 X1.5\nG1 Y1.2\nG0 Z0.2\nM2\n"
SET_HERE = "set with the tool at the program's zero"  # (what the check of a G92's or G10 L20's axes says)


@pytest.mark.parametrize(
    ("program", "system", "sets"),
    [
        (PROGRAM_MM, 1, "SET_G92_OFFSET"),
        (PROGRAM_INCH, 1, "SET_G92_OFFSET"),
        (L20_MM, 1, "SET_G5X_OFFSET"),
        (L20_INCH, 1, "SET_G5X_OFFSET"),
        (L20_INCH, 2, "SET_G5X_OFFSET"),
    ],
    ids=["G92-G21", "G92-G20", "L20-P1-G21", "L20-P0-G20", "L20-P0-in-G55"],
)
def test_rs274_runs_a_touched_off_program_where_the_tool_stands_at_the_zero_told_whatever_the_work_offset(
    tmp_path, program, system, sets
):
    """A program that touches off first (G92, or G10 L20 of the system in effect, of X Y Z before
    any move) puts its zero where the tool stands, whatever zero the control's system held: the
    check at the start reads the system (#5220) and its rotation, not its zero, and the check after
    the touch-off the program's zero in machine coordinates, the system's zero plus the G92 offset
    applied ("Numbered Parameters": #5220, #5221-, #5210, #5211-).  rs274 starts with the tool at
    the machine zero: told the system there, the program runs the original's path, under the
    control's zero told or one at X400 Y350 Z300; told it at X400 Y350 Z300, the tool at the machine
    zero is elsewhere, and the program stops before its first move."""
    at_zero = _var_file(tmp_path / "zero.var", (0.0, 0.0, 0.0), system=system)
    written, said = _compensated(tmp_path, program, at_zero)
    lines = written.read_text().splitlines()
    k = lines.index(
        program.splitlines()[1]
    )  # the touch-off, as programmed: the control stands at no move yet
    assert (
        lines[k + 1].startswith(f"(ncpp placement guard: {TOUCHED} ")
        and lines[k + 5] == "(ncpp placement guard end)"
    )
    assert "#[5201+20*#5220]+#5210*#5211" in lines[k + 2]
    start = "\n".join(lines[:k])
    assert f"[#5220 NE {system}]" in start and not re.search(
        r"#52[2-9]1\b", start
    )  # (the system, not its zero)
    assert "the placement guard's check after it stops the program" in said
    _runs_as_the_original(tmp_path, written, at_zero)
    moved = _var_file(
        tmp_path / "moved.var", (400.0, 350.0, 300.0), system=system
    )  # (the tool stays at the zero)
    _runs_as_the_original(tmp_path, written, moved)

    written, _ = _compensated(tmp_path, program, moved, "elsewhere.ngc")
    stopped = _stops_at_the_check(written, moved, check=TOUCHED, sets=sets)
    name = "G54" if system == 1 else "G55"  # (rs274 writes the parameters in)
    assert re.search(rf"put it at {name} X-?\d+\.\d{{6}} Y.* \+ [01]\.0{{6}} \* G92 X-?\d", stopped), stopped


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


@pytest.mark.parametrize(
    ("program", "system", "parameter"),
    [
        ("G21 G90\nG10 L20 P2 X0 Y0 Z0\nG55\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG0 Z5\nM2\n", 1, 5241),
        ("G21 G90\nG0 X10 Y10\nG10 L20 P1 Z0\nG0 Z5\nG1 Z-1 F300\nG1 X40\nG0 Z5\nM2\n", 1, 5223),
    ],
    ids=["P2-from-G54", "Z-alone"],
)
def test_rs274_checks_the_zero_of_the_system_p_names_on_the_axes_not_positioned(
    tmp_path, program, system, parameter
):
    """G10 L20 P2 sets G55's zero whichever system is in effect (not the program's zero, which
    stays G54's: no touch-off); after `G0 X10 Y10` only Z stands where the operator left it.  The check reads that system's parameters of those axes: the program runs where the tool
    stood at the zero told, and stops before the move after the L20 where not."""
    at_zero = _var_file(tmp_path / "zero.var", (0.0, 0.0, 0.0), system=system)
    written, said = _compensated(tmp_path, program, at_zero)
    check = next(line for line in written.read_text().splitlines() if line.startswith("o<ncpp_guard_1> if"))
    assert re.findall(r"#(\d+)", check) == (
        [str(parameter)] if parameter == 5223 else ["5241", "5242", "5243"]
    )
    _runs_as_the_original(tmp_path, written, at_zero)

    elsewhere = _var_file(tmp_path / "elsewhere.var", (400.0, 350.0, 300.0), system=system)
    written, _ = _compensated(tmp_path, program, elsewhere, "elsewhere.ngc")
    name = "G54" if parameter == 5223 else "G55"
    said = _stops_at_the_check(written, elsewhere, program.count("G0 X10 Y10\n"), f"{name}'s zero", "G5X")
    set_there = (
        "Z0.000" if parameter == 5223 else "X0.000000 Y0.000000 Z0.000000"
    )  # (Z: moved by the correction)
    assert f"this G10 L20 set {set_there}" in said, said


@pytest.mark.parametrize(
    "setting, check, stop, said",
    [
        ("G92 X0", "[ABS[#5211 - 0.3937] GT 0.0039]]", {}, "this G92 set X0.000000:"),
        (
            "G10 L20 P1 X0 Y0 Z0",
            "[ABS[#[5201+20*#5220]+#5210*#5211-0] GT 0.0039]",
            {"check": TOUCHED, "sets": "SET_G5X_OFFSET"},
            "this G10 L20 put it at G54 X-0.393701 Y0.000000 Z0.000000 + 1.000000 * G92 X0.393701 Y0.000000",
        ),
    ],
)
def test_rs274_checks_an_offset_set_under_a_g92_offset_of_the_parameter_file(
    tmp_path, setting, check, stop, said
):
    """With a G92 offset in effect at the start (#5210 1, #5211 10 mm), the program's zero is G54's
    plus it: told G54 at X-10, that is the machine zero where rs274 starts.  A G92 then sets the new
    offset (the old one gone: rs274ngc makes the block's point the tool's), a G10 L20 of X Y Z sets
    G54's zero less the G92 offset (X -10 mm), each as ncpp compensated for; told G54 at X0, ncpp
    takes the tool to stand at X10, the block sets its offset all the same, and the check stops the
    program."""
    program = f"G21 G90\n{setting}\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG0 Z5\nM2\n"
    shifted = _var_file(tmp_path / "shifted.var", (-10.0, 0.0, 0.0), (10.0, 0.0, 0.0))
    written, _ = _compensated(tmp_path, program, shifted)
    assert check in written.read_text()
    _runs_as_the_original(tmp_path, written, shifted)

    off_zero = _var_file(tmp_path / "off.var", (0.0, 0.0, 0.0), (10.0, 0.0, 0.0))
    written, _ = _compensated(tmp_path, program, off_zero, "off.ngc")
    stopped = _stops_at_the_check(written, off_zero, **stop)
    assert said in stopped, stopped


def test_rs274_runs_a_g10_l20_touch_off_under_another_g92_offset_with_the_tool_at_the_zero_told(tmp_path):
    """Told G54 at X-10 under a G92 offset of X10 (#5210 1): the program's zero at the machine zero.
    A control without the G92 offset whose G54 is at X0 has its zero there too: the G10 L20 sets G54's
    zero to the tool's position less the G92 offset applied, and the check after it reads the sum,
    which is where the compensation placed the program, so it runs."""
    program = "G21 G90\nG10 L20 P1 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG0 Z5\nM2\n"
    shifted = _var_file(tmp_path / "shifted.var", (-10.0, 0.0, 0.0), (10.0, 0.0, 0.0))
    written, _ = _compensated(tmp_path, program, shifted)
    plain = _var_file(tmp_path / "plain.var", (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), applied=False)
    _runs_as_the_original(tmp_path, written, plain)


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


def test_the_check_after_a_block_reads_only_its_events_and_the_axes_the_writer_hands_over():
    """`PlacementChecks.after` keeps nothing between calls: a G92's check covers the axes handed over
    (those the program had not positioned) whichever block came before, a G92.3's X Y Z."""
    from ncpp.guard import PlacementChecks

    program = "G21 G90\nG92 X0 Y0 Z0\nG92.3\nM2\n"
    offsets = WorkOffsets.given({"G54": (400.0, 350.0, 300.0)})
    events = events_of(program.encode(), offsets=offsets)
    g92, g92_3 = ([e for e in events if e.block.line == line] for line in (2, 3))
    checks = PlacementChecks(offsets, "iso", 1.0)
    assert checks.after(g92, ()) == [] and not checks.checks_offset(g92, ())
    assert checks.checks_offset(g92, ["Y"])
    assert "if [[ABS[#5212 - 0] GT 0.1]]" in "".join(checks.after(g92, ["Y"]))
    restored = "".join(checks.after(g92_3, ()))
    assert "restored by G92.3" in restored and all(f"#521{n}" in restored for n in (1, 2, 3))
    assert "o<ncpp_guard_3> if" in "".join(checks.after(g92, ["X", "Y", "Z"]))  # (a label per check written)


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
    zero = " OR ".join(
        f"[ABS[#[{5201 + k}+20*#5220]+#5210*#{5211 + k}-{v}] GT 0.1]" for k, v in enumerate((400, 350, 300))
    )
    far = "[[ABS[#5211 - 0] GT 0.1] OR [ABS[#5212 - 0] GT 0.1] OR [ABS[#5213 - 0] GT 0.1]]"
    assert lines.count(f"o<ncpp_guard_1> if [{zero}]") == 1 and lines.count(f"o<ncpp_guard_2> if {far}") == 1
    assert (
        f"(ncpp placement guard: {TOUCHED} X400 Y350 Z300 mm set by the tool there within 0.1 mm)" in written
    )
    assert "(ncpp placement guard: the G92 offset X0 Y0 Z0 mm restored by G92.3" in written
    assert "o<ncpp_guard> if [[#5220 NE 1] OR [ABS[#5230 - 0] GT 0.001]]" in lines
    assert all(len(line) <= 255 for line in lines)  # (rs274ngc reads lines of up to 255 characters)


def test_no_check_where_the_control_gives_no_g92_offset_to_read_and_the_warning_stays():
    program = "%\nO1234\nG21 G90\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM30\n%\n"  # Fanuc's
    written, said = _warned(program)
    assert CHECK not in written and "#5211" not in written
    assert "has not positioned X and Y and Z yet" in said and "placement guard's check" not in said


def test_a_g10_l20_after_a_g92_gets_a_check_of_its_own_in_mm():
    """`G92 Z0` sets Z's offset from where the tool stands, the G10 L20 after it G54's X and Y (its
    Z placed by the G92): two checks, each of its own axes and label."""
    program = "G21 G90\nG92 Z0\nG10 L20 P1 X0 Y0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM2\n"
    written, said = _warned(program, var_units=1.0)
    lines = written.splitlines()
    assert lines.count("o<ncpp_guard_1> if [[ABS[#5213 - 0] GT 0.1]]") == 1
    far = "[[ABS[#5221 - 400] GT 0.1] OR [ABS[#5222 - 350] GT 0.1]]"
    assert lines.count(f"o<ncpp_guard_2> if {far}") == 1  # (G54's zero where the tool stood: the told one)
    assert f"(ncpp placement guard: G54's zero X400 Y350 mm {SET_HERE}" in written
    assert said.count("the placement guard's check after it") == 2
    assert all(len(line) <= 255 for line in lines)


def test_a_fanuc_g10_l20_sets_an_additional_offset_from_its_words_and_gets_no_check():
    """Fanuc's G10 L20 Pn gives additional work offset n's zero (Series 0i-MC operator's manual,
    "Additional workpiece coordinate systems"), not one from where the tool stands."""
    program = "%\nO1234\nG21 G90\nG10 L20 P1 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM30\n%\n"
    written, said = _warned(program)
    assert SET_HERE not in written and "has not positioned X and Y and Z yet" not in said


@pytest.mark.parametrize(
    "program",
    [
        "G21 G90\nG0 X1 Y1 Z5\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM2\n",  # (placed: ncpp knows where)
        "G21 G90\nG92.1\nG0 X10 Y10 Z5\nG92.2\nG1 Z-1 F300\nG1 X40\nM2\n",  # (they set the offset 0)
        "G21 G90\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG92 X0 Y0 Z0",  # (a last line: nothing runs after it)
        "G21 G90\nG0 X1 Y1 Z5\nG10 L20 P1 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM2\n",
        "G21 G90\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG10 L20 P1 X0 Y0 Z0",
    ],
    ids=["positioned", "g92.1-g92.2", "last-line", "l20-positioned", "l20-last-line"],
)
def test_no_check_where_ncpp_knows_the_offset_or_nothing_runs_after_it(program):
    written, _ = _warned(program)
    assert CHECK not in written and SET_HERE not in written


@pytest.mark.parametrize(
    "program", [G92_FIRST, "G21 G90\nG10 L20 P1 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nM2\n"]
)
def test_no_check_with_no_guard(program):
    written, said = _warned(program, guard=False)
    assert SET_HERE not in written and "has not positioned" in said and "placement guard's check" not in said


@pytest.mark.parametrize(
    "program",
    [
        "G21 G90 G54\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG0 Z5\nM2\n",
        "(head)\nG21 G90\nG55\nG17 T1 M6\nG10 L20 P0 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nG0 Z5\nM2\n",
    ],
    ids=["G54-G92", "G55-L20-P0"],
)
def test_rs274_runs_a_program_that_selects_its_system_then_touches_off_whatever_that_system_s_zero(
    tmp_path, program
):
    """The system a program selects before it touches off gets its rotation checked before the
    selection, not its zero: rs274, the tool at the machine zero told as the program's zero, runs
    it under that system's zero told or another, and stops it, after the touch-off, told the zero
    elsewhere."""
    system = 2 if "G55" in program else 1
    at_zero = _var_file(tmp_path / "zero.var", (0.0, 0.0, 0.0), system=system)
    written, _ = _compensated(tmp_path, program, at_zero)
    text = written.read_text()
    x = 5221 + 20 * (system - 1)
    assert f"[ABS[#{x} " not in text and f"[ABS[#{x + 9} - 0] GT 0.001]" in text and TOUCHED in text
    moved = _var_file(tmp_path / "moved.var", (400.0, 350.0, 300.0), system=system)
    _runs_as_the_original(tmp_path, written, moved)

    written, _ = _compensated(tmp_path, program, moved, "elsewhere.ngc")
    _stops_at_the_check(
        written, moved, check=TOUCHED, sets="SET_G92_OFFSET" if system == 1 else "SET_G5X_OFFSET"
    )


@pytest.mark.parametrize(
    "program",
    [
        "G21 G90 G55\nG10 L20 P1 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40\nM2\n",  # (another system's zero)
        "G21 G90 G54\nG10 L2 P1 R0\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nM2\n",  # (the program sets it)
        "G21 G90 G54\nG28 Z0\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nM2\n",  # (Z0 in G54 on the way home)
        "G21 G90 G54\nG92 X0 Y0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nM2\n",  # (Z: G54's)
        "G21 G90\nG0 Z5\nG92 X0 Y0 Z0\nG0 X10 Y10 Z5\nG1 Z-1 F300\nM2\n",  # (a move first)
    ],
    ids=["l20-p1-in-g55", "g10-l2", "g28-z", "xy-alone", "moved-first"],
)
def test_a_program_that_does_not_touch_off_first_keeps_the_check_of_the_zero(program):
    """A system's zero is left out only where the touch-off sets X Y Z of the program's zero before
    anything relies on it: the check of the system selected, or at the start, reads its zero."""
    offsets = WorkOffsets.given({"G54": (400.0, 350.0, 300.0), "G55": (100.0, 100.0, 100.0)})
    written = io.BytesIO()
    process(io.BytesIO(program.encode()), written, file="p.ngc", source=ErrorSource.from_machine_file(str(WIDE)),
            offsets=offsets, warnings=Warnings(stream=io.StringIO()), guard=Placement.of(offsets))  # fmt: skip
    text = written.getvalue().decode()
    zero = "#5241 - 100" if "G55" in program else "#5221 - 400"
    assert f"[ABS[{zero}] GT 0.1]" in text and "its zero where the program touches off" not in text
    assert (TOUCHED in text) == ("G10 L2 " in program)  # (X Y Z unplaced there: the zero is checked after)


def test_a_touch_off_check_s_lines_stay_within_rs274ngc_s_255_characters():
    """The longest numbers and names the check may hold: rs274ngc reads lines of up to 255 characters."""
    from ncpp.guard import touch_off_lines

    for unit_mm in (1.0, 25.4):
        lines = touch_off_lines(9, (-12345.6789, -12345.6789, -12345.6789), False, unit_mm, 999)
        assert "G59.3 X#5381 Y#5382 Z#5383" in lines[2] and max(map(len, lines)) <= 255, lines
