"""The placement guard, judged by LinuxCNC's rs274: a compensated program runs to its end
where the control's G54 is the one it was compensated for, and stops where it is not."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests import rs274
from tests.conftest import ROOT
from tests.rs274 import linuxcnc_root

MACHINE = ROOT / "samples/machines/hr5b.toml"
PROGRAM = "G21 G90\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40 Y10\nG1 X40 Y30\nG0 Z5\nM2\n"
G54_MM = (400.0, 350.0, 300.0)


def _var_file(
    path: Path,
    g54_mm: tuple[float, float, float],
    system: int = 1,
    g55_mm: tuple[float, ...] = (),
    g54_turned: float = 0.0,
) -> Path:
    """A parameter file in inches (the stand-alone rs274's units), with G55's zero where given
    and G54 turned `g54_turned` degrees about Z (#5230, G10 L2 R)."""
    values = {5220: float(system), 5230: g54_turned}
    for first, zero in ((5221, g54_mm), (5241, g55_mm)):
        values.update({first + k: v / 25.4 for k, v in enumerate(zero)})
    # (rs274 wants the parameters in order)
    lines = [f"{number}\t{value:.6f}" for number, value in sorted(values.items())]
    path.write_text("\n".join(lines) + "\n")
    return path


def _rs274(var_file: Path, program: Path) -> subprocess.CompletedProcess:
    linuxcnc_root(var_file.parent)  # (skips the test where rs274 cannot run)
    table = var_file.with_suffix(".tbl")
    table.write_text("T1 P1 D0.25 Z0\n")
    return rs274.run(program, var_file=var_file, tool_table=table, timeout=120)


def _compensate(tmp_path: Path, *args: str, program: str = PROGRAM) -> tuple[str, str]:
    (tmp_path / "p.ngc").write_text(program)
    env = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    env.update(PYTHONPATH=str(ROOT), HOME=str(tmp_path))
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "ncpp",
            "compensate",
            "--machine",
            str(MACHINE),
            *args,
            "p.ngc",
            "-o",
            "out.ngc",
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stderr  # (the verifier read the guarded program back and passed it)
    return (tmp_path / "out.ngc").read_text(), proc.stderr


def test_rs274_runs_the_guarded_program_where_g54_matches_and_stops_it_where_not(tmp_path):
    told = _var_file(tmp_path / "told.var", G54_MM)
    text, _ = _compensate(tmp_path, "--var-file", str(told), "--var-units", "inch")
    assert "o<ncpp_guard> if" in text and "(abort," in text
    program = tmp_path / "out.ngc"
    ran = _rs274(told, program)
    assert ran.returncode == 0, ran.stderr
    assert "PROGRAM_END" in ran.stdout and ran.stdout.count("STRAIGHT_FEED") >= 3
    for moved in ((400.5, 350.0, 300.0), (400.0, 350.0, 299.8)):
        stopped = _rs274(_var_file(tmp_path / "moved.var", moved), program)
        assert stopped.returncode != 0 and "compensated for G54" in stopped.stderr, stopped.stderr
        assert "STRAIGHT_FEED" not in stopped.stdout and "PROGRAM_END" not in stopped.stdout
    other_system = _rs274(_var_file(tmp_path / "g55.var", G54_MM, system=2), program)
    assert other_system.returncode != 0 and "PROGRAM_END" not in other_system.stdout, other_system.stderr
    within = _rs274(_var_file(tmp_path / "near.var", (400.05, 349.95, 300.0)), program)
    assert within.returncode == 0 and "PROGRAM_END" in within.stdout, within.stderr  # within 0.1 mm


def test_rs274_stops_the_guarded_program_where_g54_is_turned_other_than_told(tmp_path):
    """LinuxCNC G-code manual, "Numbered Parameters": #5230 is G54's rotation about Z (R)."""
    told = _var_file(tmp_path / "told.var", G54_MM, g54_turned=30.0)
    text, _ = _compensate(tmp_path, "--var-file", str(told), "--var-units", "inch")
    assert "turned R30" in text
    program = tmp_path / "out.ngc"
    ran = _rs274(told, program)
    assert ran.returncode == 0 and "PROGRAM_END" in ran.stdout, ran.stderr
    for turned in (0.0, 30.01, -30.0):
        stopped = _rs274(_var_file(tmp_path / "turned.var", G54_MM, g54_turned=turned), program)
        assert stopped.returncode != 0 and "turned R30" in stopped.stderr, stopped.stderr
        assert "STRAIGHT_FEED" not in stopped.stdout
    unturned = _var_file(tmp_path / "unturned.var", G54_MM)
    _compensate(tmp_path, "--var-file", str(unturned), "--var-units", "inch")
    assert _rs274(_var_file(tmp_path / "turned.var", G54_MM, g54_turned=0.5), program).returncode != 0


def test_the_guard_is_written_only_where_the_offset_was_told_and_not_with_no_guard(tmp_path):
    told, _ = _compensate(tmp_path, "--work-offset", "400,350,300")
    assert "#5221 - 400]" in told and "(ncpp placement guard end)" in told
    assert (
        "ncpp placement guard" not in _compensate(tmp_path, "--work-offset", "400,350,300", "--no-guard")[0]
    )
    wide = Path("/work/shared/machines/wide.toml")
    if not wide.exists():
        pytest.skip("no machine file whose travel holds the program at the machine zero")
    env = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "compensate", "--machine", str(wide), "p.ngc"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env={**env, "PYTHONPATH": str(ROOT), "HOME": str(tmp_path)},
    )
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("(ncpp compensated") and "guard" not in proc.stdout


def test_a_fanuc_program_gets_macro_b_alarms(tmp_path):
    import io

    from ncpp.guard import Placement
    from ncpp.motion.offsets import WorkOffsets
    from ncpp.pipeline import ErrorSource, process

    program = (
        b"%\nO1234\nG21 G90\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40 Y10\nM30\n%\n"  # (in the system in effect)
    )
    offsets = WorkOffsets.at(G54_MM)
    out = io.BytesIO()
    process(
        io.BytesIO(program),
        out,
        file="f.nc",
        source=ErrorSource.from_machine_file(str(MACHINE)),
        offsets=offsets,
        guard=Placement.of(offsets),
    )
    lines = out.getvalue().decode().splitlines()
    assert lines[0] == "%" and lines[1].startswith("(ncpp compensated")
    k = lines.index("O1234")  # after the header's lines (the placement it was made for)
    assert all(line.startswith("(ncpp ") for line in lines[1:k])
    lines = lines[k - 2 :]  # (as if the header were one line)
    assert lines[2] == "O1234" and lines[3].startswith("(NCPP PLACEMENT GUARD: G54 AT X400 Y350 Z300 MM")
    assert lines[4] == "IF [#4014 NE 54] THEN #3000=1 (NCPP G54 NOT ACTIVE)"
    assert lines[5:8] == [
        "IF [ABS[#5221-400] GT 0.1] THEN #3000=2 (NCPP G54 X MOVED)",
        "IF [ABS[#5222-350] GT 0.1] THEN #3000=3 (NCPP G54 Y MOVED)",
        "IF [ABS[#5223-300] GT 0.1] THEN #3000=4 (NCPP G54 Z MOVED)",
    ]
    assert lines[8] == "(NCPP PLACEMENT GUARD END)" and lines[9] == "G21 G90"


def test_a_sinumerik_program_gets_its_settable_frame_checked_and_ncpp_still_reads_it(tmp_path):
    """The guard (`$P_UIFR`, `SETAL`, `M0`) passes the verifier, and `ncpp simulate` reads the
    compensated program past it (its contour error against the original stays at a micron)."""
    (tmp_path / "p.mpf").write_text("G54 G17 G90\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40 Y10\nG0 Z5\nM30\n")
    env = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    env.update(PYTHONPATH=str(ROOT), HOME=str(tmp_path))

    def run(*args: str) -> subprocess.CompletedProcess:
        command = [
            sys.executable,
            "-m",
            "ncpp",
            *args,
            "--machine",
            str(MACHINE),
            "--work-offset",
            "400,350,300",
        ]
        return subprocess.run(command, capture_output=True, text=True, cwd=tmp_path, env=env, timeout=300)

    written = run("compensate", "p.mpf", "-o", "out.mpf")
    assert written.returncode == 0, written.stderr
    lines = (tmp_path / "out.mpf").read_text().splitlines()
    k = next(
        n for n, line in enumerate(lines) if line.startswith("; ncpp placement guard:")
    )  # after the program's line that selects G54
    assert lines[k - 1] == "G54 G17 G90"
    lines = lines[k - 1 :]
    assert lines[2] == (  # (the program selects the frame: its translation is what counts)
        "IF (ABS($P_UIFR[1,X,TR]+$P_UIFR[1,X,FI]-400)>0.1) OR "
        "(ABS($P_UIFR[1,Y,TR]+$P_UIFR[1,Y,FI]-350)>0.1) OR (ABS($P_UIFR[1,Z,TR]+$P_UIFR[1,Z,FI]-300)>0.1)"
    )
    assert lines[4:7] == ["SETAL(65000)", "M0", "ENDIF"] and lines[8].startswith("G0 X")
    simulated = run("simulate", "out.mpf", "--reference", "p.mpf")
    assert simulated.returncode == 0 and "outside the motion interpreter" not in simulated.stderr, (
        simulated.stderr
    )
    assert float(simulated.stdout.split("max ")[1].split(" ")[0]) < 1.0  # µm


def test_the_post_writes_the_guard_of_its_dialect(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    env.update(PYTHONPATH=str(ROOT), HOME=str(tmp_path))
    for dialect in ("linuxcnc", "fanuc"):
        proc = subprocess.run(
            [
                sys.executable,
                "-m",
                "ncpp",
                "post",
                str(ROOT / "samples/programs/pocket.cls"),
                "--dialect",
                dialect,
                "--machine",
                str(MACHINE),
                "--work-offset",
                "400,350,300",
                "-o",
                f"{dialect}.nc",
            ],
            capture_output=True,
            text=True,
            cwd=tmp_path,
            env=env,
            timeout=300,
        )
        assert proc.returncode == 0, proc.stderr  # (verified past the guard)
    fanuc = (tmp_path / "fanuc.nc").read_text().splitlines()
    assert fanuc[:2] == ["%", "O0001"] and fanuc[4] == "IF [#4014 NE 54] THEN #3000=1 (NCPP G54 NOT ACTIVE)"
    told = _var_file(
        tmp_path / "told.var", (400 * 25.4, 350 * 25.4, 300 * 25.4)
    )  # raw 400 350 300: the guard's mm
    ran = _rs274(told, tmp_path / "linuxcnc.nc")
    assert ran.returncode == 0 and "PROGRAM_END" in ran.stdout, ran.stderr
    stopped = _rs274(
        _var_file(tmp_path / "moved.var", (401 * 25.4, 350 * 25.4, 300 * 25.4)), tmp_path / "linuxcnc.nc"
    )
    assert stopped.returncode != 0 and "PROGRAM_END" not in stopped.stdout, stopped.stderr


def test_an_o_word_line_is_no_fanuc_program_number():
    from ncpp.guard import Placement, guard_lines

    placement = Placement(1, G54_MM)
    assert guard_lines(placement, "iso", ["(header)\n", "o100 sub\n"])[1].startswith("o<ncpp_guard> if")
    assert guard_lines(placement, "iso", ["%\n", "O0100 (PART)\n"])[1].startswith("IF [#4014 NE 54]")


def test_a_sinumerik_guard_comes_after_the_programs_definitions():
    """The 840D wants its DEF lines before any statement (Job Planning, "Definition of user
    variables (DEF)"): the guard's IF goes after them, and after the comments among them."""
    from ncpp.guard import Placement, with_guard

    program = [
        "; ncpp header\n",
        "N10 DEF REAL DEPTH=-2\n",
        "\n",
        "def int i ; a counter\n",
        "G0 X1\n",
        "M30\n",
    ]
    written = list(with_guard(program, Placement(1, (400.0, 350.0, 300.0)), "sinumerik", "ncpp header"))
    first = next(n for n, line in enumerate(written) if line.startswith("IF "))
    assert written[:4] == program[:4] and written[first - 1].startswith("; ncpp placement guard:")
    assert written[-2:] == program[-2:] and "; ncpp placement guard end\n" in written


@pytest.mark.parametrize(
    "first, frame, active_checked",
    [("G55 G17 G90\n", 2, False), ("N10 G17 G90 ; the plane\nN20 G57\n", 4, False), ("G0 X10\n", 1, True),
     ("T1 D1 M6\nG55\n", 1, True)],
)  # fmt: skip
def test_a_sinumerik_guard_checks_the_frame_the_program_selects_first(first, frame, active_checked):
    """The zero told is that of the frame the program selects first: where lines of G codes alone
    select one before anything else runs, the guard follows them and checks that frame's
    translation; else it checks the frame in effect ($P_UIFRNUM) as well, before anything runs."""
    from ncpp.guard import Placement, with_guard

    program = ["; ncpp header\n", "DEF INT I\n", *first.splitlines(keepends=True), "G1 X20 F100\n", "M30\n"]
    written = list(with_guard(program, Placement(1, (400.0, 350.0, 300.0)), "sinumerik", "ncpp header"))
    check = next(line for line in written if line.startswith("IF "))
    assert f"$P_UIFR[{frame},X,TR]" in check and ("$P_UIFRNUM" in check) == active_checked
    before = written[: written.index(check)]
    assert [line for line in before if not line.startswith(";")] == (
        ["DEF INT I\n"] if active_checked else ["DEF INT I\n", *first.splitlines(keepends=True)]
    )


G55_MM = (600.0, 350.0, 300.0)
SELECTS_G55 = "G21 G90\nG55\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40 Y10\nG0 Z5\nM2\n"
# moves in G54, then in G55
SELECTS_G55_LATER = "G21 G90\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG0 Z5\nG0 G55 X20 Y10\nG1 Z-1 F300\nG0 Z5\nM2\n"


def test_rs274_runs_a_program_that_selects_its_system_whatever_system_the_control_was_left_in(tmp_path):
    """The program selects G55 before it moves: the guard checks G55's zero before that line,
    not the system in effect at the start (the control left in G54 is no fault)."""
    text, _ = _compensate(tmp_path, "--work-offset", "G55=600,350,300", program=SELECTS_G55)
    assert "#5220" not in text and "o<ncpp_guard_1> if [[ABS[#5241 - 600] GT 0.1]" in text
    program = tmp_path / "out.ngc"
    lines = program.read_text().splitlines()
    assert lines[lines.index("(ncpp placement guard end)") + 1] == "G55"
    inch = 25.4  # (the guard's values are mm, rs274's parameter file here inches: the raw numbers meet)
    g54, g55 = tuple(v * inch for v in G54_MM), tuple(v * inch for v in G55_MM)
    for system in (1, 2, 3):  # the control's system at the start
        ran = _rs274(_var_file(tmp_path / "told.var", g54, system, g55), program)
        assert ran.returncode == 0 and "PROGRAM_END" in ran.stdout, ran.stderr
    assert ran.stdout.count("STRAIGHT_FEED") >= 2
    moved = _rs274(_var_file(tmp_path / "moved.var", g54, 2, (600 * inch, 350.3 * inch, 300 * inch)), program)
    assert moved.returncode != 0 and "compensated for G55 at X600 Y350 Z300 mm" in moved.stderr, moved.stderr
    assert "STRAIGHT_TRAVERSE" not in moved.stdout and "PROGRAM_END" not in moved.stdout


def test_rs274_stops_a_program_before_a_system_it_selects_later_whose_zero_moved(tmp_path):
    """G54 is checked at the start (the program moves in it first), G55 before the block that
    selects it: a G55 zero moved stops the program there, after its G54 moves."""
    told = _var_file(tmp_path / "told.var", G54_MM, g55_mm=G55_MM)
    text, _ = _compensate(tmp_path, "--var-file", str(told), "--var-units", "inch", program=SELECTS_G55_LATER)
    assert text.count("(ncpp placement guard end)") == 2 and "o<ncpp_guard> if [[#5220 NE 1]" in text
    program = tmp_path / "out.ngc"
    lines = program.read_text().splitlines()
    assert lines[
        lines.index("(ncpp placement guard end)", lines.index("o<ncpp_guard_1> endif")) + 1
    ].startswith("G0 G55 X")
    ran = _rs274(told, program)
    assert ran.returncode == 0 and "PROGRAM_END" in ran.stdout and "SET_G5X_OFFSET(2," in ran.stdout
    moved = _rs274(_var_file(tmp_path / "moved.var", G54_MM, g55_mm=(600.0, 350.0, 299.5)), program)
    assert moved.returncode != 0 and "the control's G55 zero differs" in moved.stderr, moved.stderr
    assert "STRAIGHT_FEED" in moved.stdout and "SET_G5X_OFFSET(2," not in moved.stdout  # (stopped before G55)
    assert "PROGRAM_END" not in moved.stdout
    g54_moved = _rs274(_var_file(tmp_path / "g54.var", (400.0, 350.5, 300.0), g55_mm=G55_MM), program)
    assert g54_moved.returncode != 0 and "STRAIGHT_FEED" not in g54_moved.stdout


def _guarded(
    program: bytes, zeros: dict, dialect: str | None = None, file: str = "f.nc"
) -> tuple[str, bytes]:
    """The program compensated with the guard for `zeros` (verified: ncpp's reading of it
    passes), and compensated again from it with --force's reading (which drops the guard)."""
    import io

    from ncpp.guard import Placement
    from ncpp.motion.offsets import WorkOffsets
    from ncpp.pipeline import ErrorSource, process

    offsets = WorkOffsets.given(zeros)
    source = ErrorSource.from_machine_file(str(MACHINE))
    out = io.BytesIO()
    process(io.BytesIO(program), out, file=file, source=source, offsets=offsets, guard=Placement.of(offsets),
            dialect=dialect)  # fmt: skip
    again = io.BytesIO()
    process(io.BytesIO(out.getvalue()), again, file=file, source=source, offsets=offsets, force=True,
            guard=Placement.of(offsets), dialect=dialect)  # fmt: skip
    return out.getvalue().decode(), again.getvalue()


def test_a_fanuc_program_gets_the_zero_of_the_system_it_selects_checked_before_the_block():
    """Custom Macro B: #5241-#5243 hold G55's X Y Z; the program's own G55 needs no #4014 test."""
    program = b"%\nO1234\nG21 G90 G17\nG0 G55 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40 Y10\nM30\n%\n"
    text, again = _guarded(program, {"G55": G55_MM})
    lines = text.splitlines()
    k = lines.index("(NCPP PLACEMENT GUARD: G55 AT X600 Y350 Z300 MM WITHIN 0.1 MM)")
    assert lines[k - 2 : k] == ["O1234", "G21 G90 G17"] and "#4014" not in text
    assert lines[k + 1 : k + 5] == [
        "IF [ABS[#5241-600] GT 0.1] THEN #3000=2 (NCPP G55 X MOVED)",
        "IF [ABS[#5242-350] GT 0.1] THEN #3000=3 (NCPP G55 Y MOVED)",
        "IF [ABS[#5243-300] GT 0.1] THEN #3000=4 (NCPP G55 Z MOVED)",
        "(NCPP PLACEMENT GUARD END)",
    ] and lines[k + 5].startswith("G0 G55 X")
    assert (
        text.count("PLACEMENT GUARD:") == 1
        and again.count(b"PLACEMENT GUARD:") == 1
        and again.count(b"#5241") == 1
    )


@pytest.mark.parametrize(
    "dialect, select, variable",
    [("fanuc", "G54.1 P2", "#7021"), ("haas", "G154 P3", "#14041")],
)
def test_an_additional_work_offset_the_program_selects_is_checked_at_its_variables(dialect, select, variable):
    """Fanuc's P2 zero at #7021-#7023, Haas's P3 at #14041-#14043 (`motion/offsets.py`)."""
    name = select.replace(" ", "")
    program = f"%\nO1234\nG21 G90\n{select}\nG0 X10 Y10 Z5\nG1 Z-1 F300\nG1 X40 Y10\nM30\n%\n".encode()
    text, _ = _guarded(program, {"G54": G54_MM, name: G55_MM}, dialect)
    lines = text.splitlines()
    k = lines.index(select)
    assert lines[k - 5] == f"(NCPP PLACEMENT GUARD: {select} AT X600 Y350 Z300 MM WITHIN 0.1 MM)"
    assert lines[k - 4] == f"IF [ABS[{variable}-600] GT 0.1] THEN #3000=2 (NCPP {select} X MOVED)"
    assert "#4014" not in text  # (it selects before it moves: G54 is not relied on)


@pytest.mark.parametrize(
    "program, checked",
    [
        ("G21 G90\nG55\nG0 X10 Y10 Z5\nG10 L2 P2 X1 Y2 Z3\nG54\nG55\nG0 X20\nM2\n", ["G55", "G54"]),
        ("G21 G90\nG10 L2 P2 X1 Y2 Z3\nG55\nG0 X10 Y10 Z5\nM2\n", []),  # G55 is the program's
        # (a subroutine run once is written with its run where it is defined: G55 is checked there)
        ("o<s> sub\nG55\no<s> endsub\nG21 G90\nG0 X10 Y10 Z5\no<s> call\nG0 X20\nM2\n", ["G54", "G55"]),
        ("G21 G90\nT1 M6 G43\nG56\nG0 X10 Y10 Z5\nM2\n", []),  # G56 not told: warned where it is selected
    ],
)  # fmt: skip
def test_a_linuxcnc_program_checks_only_zeros_that_are_still_the_ones_told(program, checked):
    text, _ = _guarded(program.encode(), {"G54": G54_MM, "G55": G55_MM}, file="p.ngc")
    said = [line.split()[3] for line in text.splitlines() if line.startswith("(ncpp placement guard:")]
    assert said == checked


@pytest.mark.parametrize(
    "head, selects",
    [
        ("G21 G90\nG55\nG0 X1\n", True),
        ("G21 G90\nG0 X1\nG55\n", False),  # (it moves in the system in effect first)
        ("G90 G94 G17\nG21\nG28 G91 Z0.\nG90\nT1 M6\nS5000 M3\nG54\nG0 X1\n", True),  # (a CAM post's head)
        ("G90\nG53 G0 Z0\nG0 G55 X1 Y1\n", True),  # (a selection in the first move's block comes first)
        ("%\nO1234\nG21\n(PART)\nG0 G54 X10\n", True),
        ("G90\nG92 X0\nG55\n", False),
        ("G21\no100 call\nG55\n", False),
        ("G21\n/G55\nG0 X1\n", False),  # (block delete may skip it)
        ("G21\nG0 G55 X[10/2]\n", True),  # (a division in its move is no block delete)
        ("G21\nM98 P100\nG55\n", False),
        ("G21\n#1=5\nG55\n", False),
        ("G21\nG10 L2 P1 X0 Y0 Z0\nG10 P2 L2 X0\nG55\n", True),  # (it sets zeros, whatever is in effect)
        ("G21\nG10 L2 P0 X0\nG55\n", False),  # (P0: the system in effect)
        ("G21\nG10 L20 P2 X0\nG55\n", False),  # (from where the control stands)
    ],
)  # fmt: skip
def test_the_check_at_the_start_is_left_out_only_where_the_program_selects_first(head, selects):
    from ncpp.guard import _iso_selects_first

    lines = head.splitlines(keepends=True)
    assert _iso_selects_first(lines[:1], 0, iter(lines[1:])) is selects


def test_a_klartext_program_passes_unguarded_and_the_warning_says_which_manual_is_missing():
    """The FN 18 reads of the active preset are cited only from the iTNC 530's technical manual,
    not from a TNC 640, TNC 620 or TNC7 manual (the module docstring of `ncpp/guard.py`): the
    program's lines pass as written, and the warning names the reads and the manuals."""
    from ncpp.guard import Placement, guard_lines, with_guard

    program = ["0 BEGIN PGM P MM\n", "1 ; ncpp header\n", "2 L X+10 Y+10 R0 FMAX\n", "3 END PGM P MM\n"]
    told: list[str] = []
    placement = Placement(1, G54_MM)
    assert list(with_guard(program, placement, "heidenhain", "ncpp header", unguarded=told.append)) == program
    assert guard_lines(placement, "heidenhain") == []
    assert len(told) == 1 and "FN 18 reads of the active preset (ID530 NR1, ID502/ID503)" in told[0]
    assert told[0].endswith(
        "only from the iTNC 530's technical manual, not from a TNC 640, TNC 620 or TNC7 manual"
    )


def test_the_klartext_warning_names_the_preset_to_set_not_a_g54(tmp_path):
    """A Klartext program's zero is the preset it runs under (`--work-offset`): the warning says
    which preset the control must have, not an ISO system a TNC does not select."""
    klartext = "0 BEGIN PGM P MM\n1 L X+10 Y+10 Z+5 R0 FMAX\n2 L X+40 F300\n3 END PGM P MM\n"
    out, err = _compensate(
        tmp_path, "--dialect", "heidenhain", "--work-offset", "400,350,300", program=klartext
    )
    assert "FN 18" not in out
    said = [line for line in err.splitlines() if "no placement guard" in line]
    assert len(said) == 1, err
    assert said[0].endswith(
        "make sure the control has the active preset at X400 Y350 Z300 mm before the program runs"
    )


def test_a_negative_zero_or_length_is_added_not_subtracted_twice():
    """`#5221--100` is no expression the Fanuc Custom Macro B or Siemens manuals define (a
    control that refuses it would stop every program with a negative zero at its guard)."""
    from ncpp.guard import Placement, _fanuc, _linuxcnc, _sinumerik, haas_tool_guard_lines, tool_guard_lines

    placement = Placement(1, (-100.0, 50.0, -20.5))
    written = [*_fanuc(placement), *_sinumerik(placement), *_linuxcnc(placement),
               *haas_tool_guard_lines(1, -5.25, 1.0), *tool_guard_lines(1, -5.25, 1.0, 1)]  # fmt: skip
    text = "\n".join(written)
    assert "--" not in text and "- -" not in text
    assert "IF [ABS[#5221+100] GT 0.1]" in text and "IF [ABS[#5222-50] GT 0.1]" in text
    assert "$P_UIFR[1,X,FI]+100)" in text and "$P_UIFR[1,Z,FI]+20.5)" in text
    assert "[ABS[#5221 + 100] GT" in text and "[ABS[#5403 + 5.25] GT" in text
    assert "IF [ABS[#2001+#2201+5.25] GT" in text
