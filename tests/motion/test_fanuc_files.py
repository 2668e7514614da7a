"""A Fanuc or Haas file that holds several programs, each between `%` marks or one after another:
each O-number program is one the control keeps in memory, which `M98 Pn` and `G65 Pn` call (Fanuc
operator's manual, "Program configuration" and "Subprogram"; Haas Mill Operator's Manual,
"Subprograms": M98 calls a program in memory by its O number).  The text after the first program's
closing `%` runs only when called, and passes through as it is.

Judged by moves computed by hand, and by LinuxCNC's rs274 on the twin that holds the subprogram in
the first program's text (rs274 reads a Fanuc-style `O1002 ... M99` there, not after the `%`)."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.canon import canon_call, read_canon
from ncpp.program.parser import parse_text
from tests.conftest import READING, ROOT, RS274
from tests.motion.test_fanuc_flavours import PATHCHECK, events
from tests.motion.test_oracle import rs274, same_calls

MAIN = "%\nO1001\nG21 G90 G54\nG0 X0 Y0 Z5\nM98 P1002 L2\nG0 X1\n"
SUB = "O1002\nG91 G1 Z-1 F100\nG90 X10\nM99\n%\n"
# The ways a file holds the two programs: each between its own `%` marks, one after the other
# behind one `%`, and a first program that its closing `%` ends (no M30)
LAYOUTS = {
    "each between % marks": MAIN + "M30\n%\n%\n" + SUB,
    "one after the other": MAIN + "M30\n%\n(the subprogram)\n" + SUB,
    "ended by its %": MAIN + "%\n%\n" + SUB,
}
# The same moves as LinuxCNC reads them: the subprogram after M30, inside the first program's `%`
TWIN = MAIN + "M30\n" + SUB
# O1002 runs twice from (0, 0, 5): down 1 mm, across to X10, down 1 mm, X10 again; then X1
BY_HAND = [
    ("STRAIGHT_TRAVERSE", (0, 0, 5)),
    ("STRAIGHT_FEED", (0, 0, 4)), ("STRAIGHT_FEED", (10, 0, 4)),
    ("STRAIGHT_FEED", (10, 0, 3)), ("STRAIGHT_FEED", (10, 0, 3)),
    ("STRAIGHT_TRAVERSE", (1, 0, 3)),
]  # fmt: skip


def moves(program: str, dialect: str, said: io.StringIO | None = None) -> list[tuple[str, tuple]]:
    calls = [canon_call(e) for e in events(program, dialect, Warnings(stream=said or io.StringIO()))]
    return [(c.name, tuple(round(v, 9) for v in c.args[:3])) for c in calls if c is not None]


@pytest.mark.parametrize("layout", LAYOUTS)
@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_m98_runs_a_program_that_stands_after_the_closing_percent(layout, dialect):
    said = io.StringIO()
    assert moves(LAYOUTS[layout], dialect, said) == BY_HAND
    assert said.getvalue() == ""


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_g65_calls_a_macro_after_the_closing_percent_with_its_arguments(dialect):
    program = "%\nO1\nG21 G90\nG0 X0 Y0 Z5\nG65 P2 A3 B-2\nM30\n%\n%\nO2\nG1 X#1 Y#2 F100\nM99\n%\n"
    assert moves(program, dialect) == [("STRAIGHT_TRAVERSE", (0, 0, 5)), ("STRAIGHT_FEED", (3, -2, 5))]


@pytest.mark.parametrize("layout", LAYOUTS)
def test_the_moves_are_rs274s_of_the_twin_with_the_subprogram_in_the_first_program(tmp_path, layout):
    if not RS274.exists():
        pytest.skip("rs274 not available")
    twin = tmp_path / "twin.ngc"
    twin.write_text(TWIN)
    reference = read_canon(rs274(str(twin))[0])
    mine = [c for c in (canon_call(e) for e in events(LAYOUTS[layout], "fanuc")) if c is not None]
    assert len(mine) == len(reference) == len(BY_HAND) and same_calls(reference, mine), (reference, mine)


def compensate(tmp_path, text: str, *options: str) -> tuple[str, subprocess.CompletedProcess]:
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(text)
    command = ["compensate", "--machine", str(READING), "--dialect", "fanuc", *options, str(program),
               "-o", str(out)]  # fmt: skip
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr
    return out.read_text(), proc


@pytest.mark.parametrize("layout", LAYOUTS)
def test_the_text_after_the_closing_percent_passes_through_as_it_is(tmp_path, layout):
    """Compensated (the call's moves left as programmed) and verified; the subprogram's text
    unchanged, though the main program's mode (G0) is another than its own where it stands (no
    motion code put before its M99); and with no machine file the whole file unchanged."""
    text = LAYOUTS[layout]
    written, proc = compensate(tmp_path, text)
    rest = text.split("%\n", 2)[2]
    assert written.endswith(rest) and "M98 P1002 L2\n" in written
    assert "left as programmed: 4 moves in loops or subroutines (line 5)" in proc.stderr
    bare = {"PATH": "/usr/bin:/bin", "HOME": str(tmp_path)}  # (no machine file from the environment)
    plain = subprocess.run([sys.executable, "-m", "ncpp", "filter", str(tmp_path / "p.nc")],
                           capture_output=True, cwd=ROOT, env=bare)  # fmt: skip
    assert plain.returncode == 0 and plain.stdout == text.encode(), plain.stderr


@pytest.mark.parametrize("layout", [name for name, text in LAYOUTS.items() if "M30" in text])  # (as the twin)
def test_expanded_the_calls_follow_rs274s_path_of_the_twin(tmp_path, layout):
    """--expand writes the calls as straight code, each move compensated; rs274 runs the result
    (it would not find O1002 after the `%`) along the twin's path (pathcheck: same actions,
    within 0.05 mm, rapids where the twin rapids), and the text after the end is kept."""
    if not (RS274.exists() and PATHCHECK.exists()):
        pytest.skip("rs274 or pathcheck not available")
    written, _ = compensate(tmp_path, LAYOUTS[layout], "--expand")
    assert "M98" not in written and written.endswith(SUB)
    expanded, twin = tmp_path / "expanded.ngc", tmp_path / "twin.ngc"
    expanded.write_text(written)
    twin.write_text(TWIN)
    check = subprocess.run([sys.executable, str(PATHCHECK), str(twin), str(expanded), "--tol-mm", "0.05"],
                           capture_output=True, text=True, timeout=600)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr


def test_a_goto_of_the_first_program_does_not_jump_into_a_program_after_it():
    program = "%\nO1\nG21 G90\nG0 X0 Y0 Z5\nGOTO 7\nN5 G0 X2\nM30\n%\n%\nO2\nN7 G0 X3\nM99\n%\n"
    with pytest.raises(NcppError, match="GOTO 7: the program has no block N7"):
        events(program, "fanuc")


def test_a_line_after_the_end_that_cannot_be_read_is_an_error_only_where_a_call_runs_it():
    long_line = "G1 X" + "1" * 300 + "\n"
    uncalled = "%\nO1\nG21 G90\nG0 X0 Y0 Z5\nM30\n%\n%\nO2\n" + long_line + "G1 X1 [\nM99\n%\n"
    said = io.StringIO()
    assert moves(uncalled, "fanuc", said) == [("STRAIGHT_TRAVERSE", (0, 0, 5))] and said.getvalue() == ""
    called = uncalled.replace("M30", "M98 P2\nM30")
    with pytest.raises(NcppError, match="block too long") as err:
        events(called, "fanuc")
    assert err.value.where is not None and err.value.where.line == 10


def test_a_program_the_percent_ends_before_its_m99_is_not_a_subprogram():
    said = io.StringIO()
    program = "%\nO1\nG21 G90\nG0 X0 Y0 Z5\nM98 P2\nM30\n%\nO2\nG1 X1 F100\n%\nG1 X2\nM99\n"
    assert moves(program, "fanuc", said) == [("STRAIGHT_TRAVERSE", (0, 0, 5))]
    assert "M98 P2: a subprogram the program does not define" in said.getvalue()


def test_linuxcnc_reads_nothing_after_the_closing_percent():
    """rs274ngc stops reading a file at its closing `%`: the lines after it stay unparsed there."""
    text = "%\nG0 X1\n%\nO2\nG1 X1\nM99\n"
    for dialect, parsed in (("iso", False), ("fanuc", True)):
        after = parse_text(text, grammar=dialect)[3:]
        assert all(b.verbatim for b in after) and all(bool(b.items) is parsed for b in after)


@pytest.mark.parametrize("name", ["1002.nc", "O1002.nc", "1002.NC"])
def test_a_subprogram_file_named_for_its_number_without_the_o_is_found(tmp_path, name):
    """`G65P3003...` with O3003 in `3003.nc` (dennisselyaev/gcode, 3.nc and 3003.nc, a Fanuc 0i-MD's
    programs as a PC folder keeps them): the file on the subroutine path, which must say `O1002` itself."""
    (tmp_path / name).write_text("%\n" + SUB)
    written, proc = compensate(tmp_path, MAIN + "M30\n%\n", "--subroutine-path", str(tmp_path), "--expand")
    assert "not define" not in proc.stderr and written.count("G91 G1 Z-1") == 2, (proc.stderr, written)
    (tmp_path / name).write_text("%\n" + SUB.replace("O1002", "O1003"))
    command = ["compensate", "--machine", str(READING), "--dialect", "fanuc", "--subroutine-path", str(tmp_path),
               str(tmp_path / "p.nc"), "-o", str(tmp_path / "out.nc")]  # fmt: skip
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode != 0 and f"{name}:1:1: O1002 ... M99 is not in the file" in proc.stderr, (
        proc.stderr
    )


# A file whose first program ends with M99: a subprogram stored before the main program, which the
# operator runs (Fanuc Series 0i-MC operator's manual, B-64124EN, "Subprogram (M98, M99)": a subprogram
# ends with M99, and runs where M98 calls it); `ncpp motion` follows the main program, the twin
# written by hand in LinuxCNC's o-word form is what rs274 runs
SUB_FIRST = {
    "one subprogram": (
        "%\nO2000 (SUB)\nG91 G1 X10 F300\nG90\nM99\n"
        "O1000 (MAIN)\nG21 G90 G54\nG0 X0 Y0 Z5\nG1 Z-1 F200\nM98 P2000\nG0 Z5\nM30\n%\n",
        "o2000 sub\nG91 G1 X10 F300\nG90\no2000 endsub\n"
        "G21 G90 G54\nG0 X0 Y0 Z5\nG1 Z-1 F200\no2000 call\nG0 Z5\nM30\n",
    ),
    "two, one called twice, an arc": (
        "%\nO2000\nG91 G1 X10 F300\nG3 X5 Y5 I0 J5\nG90\nM99\n(the second)\nO3000\nG1 Y20\nM99\n"
        "O1000\nG21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F200\nM98 P2000\nM98 P3000\nG1 X30\nM98 P2000\nG0 Z5\nM30\n%\n",
        "o2000 sub\nG91 G1 X10 F300\nG3 X5 Y5 I0 J5\nG90\no2000 endsub\no3000 sub\nG1 Y20\no3000 endsub\n"
        "G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F200\no2000 call\no3000 call\nG1 X30\no2000 call\nG0 Z5\nM30\n",
    ),
}


def motion_command(path, dialect: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "ncpp", "motion", "--dialect", dialect, str(path)],
                          capture_output=True, text=True, cwd=ROOT)  # fmt: skip


@pytest.mark.parametrize("name", SUB_FIRST)
@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_subprograms_before_the_main_program_run_where_it_calls_them_as_rs274_runs_the_twin(
    tmp_path, name, dialect
):
    if not RS274.exists():
        pytest.skip("rs274 not available")
    program, twin = SUB_FIRST[name]
    (tmp_path / "p.nc").write_text(program)
    (tmp_path / "twin.ngc").write_text(twin)
    reference = read_canon(rs274(str(tmp_path / "twin.ngc"))[0])
    shown = motion_command(tmp_path / "p.nc", dialect)
    assert shown.returncode == 0, shown.stderr
    mine = read_canon(shown.stdout)
    assert len(mine) == len(reference) >= 4 and same_calls(reference, mine), (reference, mine)
    main = program.splitlines().index(next(line for line in program.splitlines() if line.startswith("O1000")))
    subprograms = "O2000 is a subprogram" if "O3000" not in program else "O2000 and O3000 are subprograms"
    said = f"p.nc:{main + 1}:1: warning: the file's first program ends with M99: ncpp runs O1000 as the main program; {subprograms}"
    assert said in shown.stderr and shown.stderr.count("warning") == 1, shown.stderr


FIRST = "%\nO2000 (SUB)\nG21 G91 G1 X10 F300\nG90\nM99\n"
# Files whose first program ends with M99 where which one is the main program is not told: what the
# warning says of each
UNTOLD = {
    "two end with M30": (FIRST + "O1000\nG0 X0 Y0 Z5\nM98 P2000\nM30\nO3000\nG0 X5 Y5 Z5\nM30\n%\n",
                         "2 later programs end with M30 or M2 (O1000, O3000)"),
    "none ends with M30": (FIRST + "O1000\nG0 X5 Y5\nM98 P2000\nM99\n%\n",
                           "no later program of the file ends with M30 or M2"),
    "the main one after the closing %": (FIRST + "%\n%\nO1000\nG0 X5 Y5\nM98 P2000\nM30\n%\n",
                                         "the one that ends with M30 or M2, O1000, stands after the file's closing %"),
    "one before it with neither end": (FIRST + "O3000\nG1 X1\nO1000\nG0 X5 Y5\nM98 P2000\nM2\n%\n",
                                       "O3000, before O1000, ends with neither M99 nor M30 or M2"),
}  # fmt: skip


@pytest.mark.parametrize("name", UNTOLD)
def test_where_the_main_program_is_not_told_nothing_runs_and_the_warning_says_why(name):
    program, why = UNTOLD[name]
    said = io.StringIO()
    assert moves(program, "fanuc", said) == []
    assert said.getvalue() == (
        f"p.nc:2:1: warning: a file whose first program O2000 ends with M99 (a subprogram) while {why} (which "
        "program the operator runs as the main one is not ncpp's to guess) is outside the motion interpreter's "
        "scope; from this line on the program passes through uninterpreted (its modal state is unknown)\n"
    )


@pytest.mark.parametrize("name", ["two end with M30", "none ends with M30"])
def test_where_the_main_program_is_not_told_the_file_passes_through_and_strict_refuses(tmp_path, name):
    program = UNTOLD[name][0]
    written, proc = compensate(tmp_path, program)
    unheaded = [line for line in written.splitlines(keepends=True) if not line.startswith("(ncpp ")]
    assert "".join(unheaded) == program
    assert "passes through uninterpreted" in proc.stderr and "compensated 0 moves" in proc.stderr
    command = ["compensate", "--strict", "--machine", str(READING), "--dialect", "fanuc", str(tmp_path / "p.nc")]  # fmt: skip
    refused = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True,
                             cwd=ROOT)  # fmt: skip
    assert refused.returncode != 0 and "(refused in strict mode)" in refused.stderr, refused.stderr


@pytest.mark.parametrize("dialect", ["fanuc", "haas", "iso"])
def test_a_file_of_one_program_that_ends_with_m99_is_an_endless_main_program(dialect):
    """Its moves run up to the M99, which ends interpretation there."""
    said = io.StringIO()
    assert moves(FIRST + "%\n", dialect, said) == [("STRAIGHT_FEED", (10, 0, 0))]
    assert "p.nc:5:1: warning: M99 in the main program (an endless main program)" in said.getvalue()


def test_linuxcnc_runs_a_file_of_subprograms_first_from_its_top():
    """rs274ngc reads a file from its top, an M99 there ending an endless main program: the ISO
    reading is unchanged."""
    said = io.StringIO()
    assert moves(SUB_FIRST["one subprogram"][0], "iso", said) == [("STRAIGHT_FEED", (10, 0, 0))]
    assert "p.nc:5:1: warning: M99 in the main program" in said.getvalue()


def test_the_main_programs_jumps_and_local_calls_find_its_own_sequence_numbers():
    """A GOTO searched back from the top of the main program, and a Haas M97, find the main program's
    block Nn, not one of a subprogram stored before it."""
    stored = "%\nO2000\nN10 G1 X99 F100\nN20 G1 Y99\nM99\n"
    goto = stored + "O1000\nG21 G90\n#1 = 0\nN10 G0 X#1 Y0 Z5\n#1 = #1 + 1\nIF [#1 LT 2] GOTO 10\nM30\n%\n"
    assert moves(goto, "fanuc") == [("STRAIGHT_TRAVERSE", (0, 0, 5)), ("STRAIGHT_TRAVERSE", (1, 0, 5))]
    local = stored + "O1000\nG21 G90\nG0 X0 Y0 Z5\nM97 P20\nG0 X3\nM30\nN20 G1 Y7 F100\nM99\n%\n"
    said = io.StringIO()
    assert moves(local, "haas", said) == [
        ("STRAIGHT_TRAVERSE", (0, 0, 5)), ("STRAIGHT_FEED", (0, 7, 5)), ("STRAIGHT_TRAVERSE", (3, 7, 5))
    ]  # fmt: skip
    assert "ncpp runs O1000 as the main program" in said.getvalue() and "outside" not in said.getvalue()


def test_a_stored_subprograms_m99_with_other_words_ends_it_there_too():
    """`G90 M99`: O2000 is a subprogram stored before the main program still, not run as the main
    one; its call, which ncpp does not follow (the M99 of a subprogram's run shares its line), passes
    the rest through."""
    program = "%\nO2000\nG91 G1 X10 F300\nG90 M99\nO1000\nG21 G90\nG0 X0 Y0 Z5\nM98 P2000\nG0 Z6\nM30\n%\n"
    said = io.StringIO()
    assert moves(program, "fanuc", said) == [("STRAIGHT_TRAVERSE", (0, 0, 5))]
    assert "p.nc:5:1: warning: the file's first program ends with M99: ncpp runs O1000" in said.getvalue()
    assert "p.nc:8:1: warning: M98 P2000: a subprogram the program does not define" in said.getvalue()
