"""`--expand`: the loops and subroutines of an ISO program written out as straight code, every
run of a body where it runs, each move compensated as a plain move.

Judged by oracles ncpp did not write: `shared/tools/pathcheck` (LinuxCNC's rs274 runs the
original and the expanded program: the same actions in order, the same path), and rs274 running
the expanded output, its feed moves' end points mapped through a machine written here by hand
(scale errors and squareness, `square`): every point a feed move is programmed to lands within
0.5 µm of where the original program puts it.  The same measure on the output without --expand
finds microns: the test can fail."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import ncpp.motion.expand as expand_module
from ncpp.errors import NcppError, Warnings
from ncpp.motion.expressions import Parameters
from ncpp.pipeline import ErrorSource, process
from tests.compensation.accuracy import rs274_calls
from tests.conftest import CORPUS, READING, ROOT, SHARED, corpus_id
from tests.motion.test_fanuc_macro import TWINS
from tests.verify.test_corpus_pathcheck import (
    as_linuxcnc_reads,
    programs,
    rs274_environment,
    rs274_runs,
    tool_table,
)
from tests.writeback.conftest import compensate_file
from tests.writeback.test_compensated_holes import MACHINE, _rs274_text, square

PATHCHECK = SHARED / "tools" / "pathcheck"
WIDE = SHARED / "machines" / "wide.toml"
HEAD = "G21 G90 G17\nG0 X0 Y0 Z10\nM3 S1200\n"
# An o-word control line of LinuxCNC, or a Fanuc subprogram call, loop or jump
KEYWORDS = "sub|endsub|call|while|endwhile|do|repeat|endrepeat|if|elseif|else|endif|break|continue|return"
FLOW_LINE = re.compile(rf"^[ \t]*(N\d+[ \t]*)?(o[ \t]*(\d+|<[^>]*>)[ \t]*({KEYWORDS})\b"
                       r"|M98|M99|WHILE|END[ \t]*\d|GOTO|IF\b|G6[567])",
                       re.IGNORECASE | re.MULTILINE)  # fmt: skip
# A subroutine's definition, which stays (the control skips it)
DEFINITION = re.compile(r"^\s*o\s*(\d+|<[^>]*>)\s*sub\b.*?^\s*o\s*\1\s*endsub.*?$", re.I | re.M | re.S)
TOOL_GUARD = re.compile(r"^\(ncpp tool guard:.*?^\(ncpp tool guard end\)$", re.M | re.S)

PROGRAMS = {
    # a helical-free pocket corner subroutine with three arguments, called three times
    "subroutine called three times": HEAD
    + """o100 sub
  G0 X[#1] Y[#2] Z2
  G1 Z-1 F200
  G1 X[#1 + #3] F400
  G2 X[#1 + #3 + 10] Y[#2 - 10] I0 J-10
  G1 Y[#2 - #3]
  G0 Z10
o100 endsub
o100 call [100] [150] [40]
o100 call [-120] [80] [25]
o100 call [200] [-60] [60]
G0 X0 Y0
M5
M2
""",
    "while loop": HEAD
    + """#<x> = -150
o1 while [#<x> LT 160]
  G0 X[#<x>] Y-100 Z2
  G1 Z-2 F150
  G1 Y[120 + #<x> / 10] F500
  G0 Z10
  #<x> = [#<x> + 75]
o1 endwhile
M5
M2
""",
    "repeat loop": HEAD
    + """G0 X-180 Y-180 Z2
G1 Z-1 F200
o2 repeat [6]
  G91 G1 X60 F500
  G1 Y60
  G90
o2 endrepeat
G0 Z10
M5
M2
""",
    "loop around a call": HEAD
    + """o10 sub
  G0 X[#1] Y[#2] Z2
  G1 Z[#3] F150
  G1 X[#1 + 30] Y[#2 + 20] F400
  G0 Z10
o10 endsub
#<row> = 0
o11 while [#<row> LT 3]
  #<col> = 0
  o12 do
    o10 call [#<col> * 90 - 150] [#<row> * 110 - 130] [-1 - #<row>]
    #<col> = [#<col> + 1]
  o12 while [#<col> LT 4]
  #<row> = [#<row> + 1]
o11 endwhile
M5
M2
""",
    "if and else in a loop": HEAD
    + """#<i> = 0
o20 while [#<i> LT 4]
  G0 X[#<i> * 80 - 120] Y150 Z2
  G1 Z-1 F200
  o21 if [[#<i> MOD 2] EQ 0]
    G1 Y-150 F500
    M8
  o21 else
    G3 X[#<i> * 80 - 120] Y-150 I0 J-150 F500
    M9
  o21 endif
  G0 Z10
  #<i> = [#<i> + 1]
o20 endwhile
M9
M5
M2
""",
    "drilling cycle in a loop": HEAD
    + """G0 Z25
#<k> = 0
o30 while [#<k> LT 5]
  G99 G81 X[#<k> * 60 - 100] Y[120 - #<k> * 50] Z-12 R3 F120
  #<k> = [#<k> + 1]
o30 endwhile
G80
G0 Z25
M5
M2
""",
    # the main program reads what loops and subroutines left: a global, a return value, a counter
    "parameters read after the loops": HEAD
    + """o40 sub
  #<_total> = [#<_total> + #1]
  G1 X[#<_total>] Y[#1 * 2] F300
o40 endsub [#1 * 3]
#<_total> = 20
#<n> = 0
o41 repeat [3]
  #<n> = [#<n> + 1]
  o40 call [#<n> * 15]
o41 endrepeat
G1 X[#<_value>] Y[#<n> * 40] F300
G1 X[#<_total> + #<n>] Y-[#<_value_returned> * 50]
M5
M2
""",
}


def _running(text: str) -> str:
    """The written program without its subroutine definitions (they do not run) and the tool
    guard's checks (an o-word `if` of ncpp's own, not the program's flow)."""
    return TOOL_GUARD.sub("", DEFINITION.sub("", text))


def _compensated(tmp_path: Path, text: str, **options) -> tuple[Path, Path]:
    original = tmp_path / "p.ngc"
    original.write_text(text)
    return original, compensate_file(original, MACHINE, tmp_path, **options)


def _feed_ends(path: Path) -> np.ndarray:
    """The points rs274 feeds to running `path` (G17, work offset 0: machine mm)."""
    ends = [args[:2] + args[5:6] if name == "ARC_FEED" else args[:3] for name, args in rs274_calls(path)
            if name != "STRAIGHT_TRAVERSE"]  # fmt: skip
    return np.array(ends, dtype=float)


def _worst_point_um(original: Path, output: Path) -> float:
    """µm the worst of the original's feed end points is from where the tool feeds to running
    `output` on the machine `square` (the nearest such point)."""
    wanted = _feed_ends(original)
    reached = square(_feed_ends(output), np.ones(3))
    distances = np.linalg.norm(wanted[:, None, :] - reached[None, :, :], axis=2).min(axis=1)
    return float(distances.max() * 1000)


def _pathcheck(original: Path, output: Path, *options: str) -> subprocess.CompletedProcess:
    if not PATHCHECK.exists():
        pytest.skip(f"pathcheck not found under {SHARED}")
    return subprocess.run([sys.executable, str(PATHCHECK), str(original), str(output), *options],
                          capture_output=True, text=True, timeout=600,
                          env=rs274_environment(original.parent))  # fmt: skip


@pytest.mark.parametrize("name", PROGRAMS)
def test_expanded_bodies_land_where_programmed_and_rs274_runs_the_same_path(tmp_path, name):
    original, output = _compensated(tmp_path, PROGRAMS[name], expand=True)
    text = output.read_text()
    assert not FLOW_LINE.search(_running(text)), text
    check = _pathcheck(original, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr
    assert _worst_point_um(original, output) <= 0.5
    plain = compensate_file(original, MACHINE, tmp_path)  # without --expand: the bodies as programmed
    assert _worst_point_um(original, plain) > 2.0


# Programs judged by pathcheck alone (their points are not machine coordinates, or their cycles
# are written as moves): name -> (program, options)
PATH_ONLY = {
    "offset set in a loop": (
        HEAD
        + """#<k> = 0
o1 while [#<k> LT 3]
  G0 X[50 + #<k> * 60] Y20
  G92 X0 Y0
  G1 X40 F300
  G1 Y40
  G92.1
  #<k> = [#<k> + 1]
o1 endwhile
G0 X0 Y0
M5
M2
""",
        {},
    ),
    "dwelling cycle in a loop, written as moves": (
        HEAD
        + """#<k> = 0
o1 repeat [3]
  G82 X[#<k> * 70 - 60] Y90 Z-4 R2 P0.4 F120 M8
  #<k> = [#<k> + 1]
o1 endrepeat
G80
M9
M5
M2
""",
        {"expand_cycles": True},
    ),
}


@pytest.mark.parametrize("name", PATH_ONLY)
def test_expanded_offsets_and_cycles_run_in_rs274_as_the_original(tmp_path, name):
    program, options = PATH_ONLY[name]
    original, output = _compensated(tmp_path, program, expand=True, **options)
    assert not FLOW_LINE.search(output.read_text())
    check = _pathcheck(original, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


def _expanded(text: str, file: str = "t.ngc", warnings: Warnings | None = None) -> str:
    out = io.BytesIO()
    process(io.BytesIO(text.encode()), out, file=file, source=ErrorSource.from_machine_file(str(READING)),
            warnings=warnings or Warnings(stream=io.StringIO()), expand=True)  # fmt: skip
    return out.getvalue().decode()


def test_each_run_acts_in_order_and_the_parameters_are_set_before_the_main_program_reads_them():
    text = _expanded(HEAD + "#<_n> = 0\no1 repeat [2]\n  T[#<_n> + 1] M6\n  G4 P[0.5 + #<_n>]\n"
                     "  #<_n> = [#<_n> + 1]\no1 endrepeat\nG1 X#<_n> F100\nM2\n")  # fmt: skip
    body = text[text.index("M3 S1200") :]
    assert re.findall(r"T\S+ M6|G4 P\S+|#<_n>=\S+|G1 X\S+", body) == [
        "T1 M6", "G4 P0.5", "T2 M6", "G4 P1.5", "#<_n>=2", "G1 X2.0000"]  # fmt: skip


def test_without_expand_the_warning_tells_of_it():
    stream = io.StringIO()
    out = io.BytesIO()
    process(io.BytesIO(PROGRAMS["while loop"].encode()), out, file="t.ngc", warnings=Warnings(stream=stream),
            source=ErrorSource.from_machine_file(str(READING)))  # fmt: skip
    assert "loop or subroutine: its moves pass through uncompensated" in stream.getvalue()
    assert "--expand writes" in stream.getvalue()
    assert "o1 while" in out.getvalue().decode()


def test_the_main_programs_parameters_are_those_the_first_call_saved():
    params = Parameters()
    params.write(1, 5.0)
    params.write("x", 2.0)
    params.write("_g", 3.0)
    params.enter([7.0])  # an o-word call: #1.. and the local names are its own
    params.write("x", 9.0)
    params.write("_g", 4.0)
    params.enter(None)  # an M98 call in it shares them
    numbered, named, _ = params.main_level()
    assert numbered[1] == 5.0 and params.read(1) == 7.0
    assert {k: named[k] for k in ("x", "_g")} == {"x": 2.0, "_g": 4.0}


def test_more_blocks_than_the_bound_are_refused_where_the_bound_is_passed(monkeypatch):
    monkeypatch.setattr(expand_module, "MAX_EXPANDED", 20)
    with pytest.raises(
        NcppError, match=r"t\.ngc:5:1: --expand: the loops and subroutines make more than 20 blocks"
    ):
        _expanded(HEAD + "o1 repeat [11]\n  G1 X1 F100\n  G1 X2\no1 endrepeat\nM2\n")


def test_a_construct_out_of_scope_in_a_loop_is_refused_at_the_main_level_it_passes_the_rest_on():
    with pytest.raises(NcppError, match=r"t\.ngc:6:3: --expand: threading G33 is outside the motion "
                                        r"interpreter's scope, inside a loop"):  # fmt: skip
        _expanded(HEAD + "o1 repeat [2]\n  G1 X1 F100\n  G33 Z-1 K1\no1 endrepeat\nM2\n")
    warned = io.StringIO()
    text = _expanded(HEAD + "o2 sub\n  G1 X[#1] F100\no2 endsub\no1 repeat [2]\n  o2 call [5]\no1 endrepeat\n"
                     "G33 Z-1 K1\no2 call [7]\nM2\n", warnings=Warnings(stream=warned))  # fmt: skip
    assert "t.ngc:10:1: warning: threading G33 is outside" in warned.getvalue()
    assert _running(text).count("G1 X") == 2 and "o1 repeat" not in text  # expanded up to there
    assert "o2 sub" in text and text.endswith("G33 Z-1 K1\no2 call [7]\nM2\n")  # the definition stays


@pytest.mark.parametrize(
    "rest", ["G33 Z[-#<x>] K1\nG0 X#<x>\nM2\n", "o<missing> call [#<x>]\nG0 X#<x>\nM2\n"]
)
def test_a_line_that_passes_through_uninterpreted_finds_the_parameters_set(rest):
    text = _expanded(
        HEAD + "#<x> = 1\no1 repeat [2]\n  G1 X[#<x>] F100\n  #<x> = [#<x> + 1]\no1 endrepeat\n" + rest
    )
    assert text.endswith("  G1 X2.0000 F100\n#<x>=3\n" + rest)


def test_a_fanuc_stop_with_a_message_stops_each_run_and_is_no_parameter_to_set():
    text = _expanded("O0010\nG21 G90 G17\nG0 X0 Y0 Z5\n#100=0\nM98 P200 L3\nG1 X#100 F100\nM30\n"
                     "O200\n#100=#100+10\nG1 X#100 Y5 F300\n#3006=1 (CHECK)\nM99\n", file="t.nc")  # fmt: skip
    running = text[: text.index("M30")]
    assert re.findall(r"G1 X\S+|#\d+=\S+", running) == [
        "#100=0", "G1 X9.9999", "#3006=1", "G1 X19.9998", "#3006=1", "G1 X29.9997", "#3006=1", "#100=30",
        "G1 X29.9997"]  # fmt: skip


def test_debug_messages_show_each_runs_values_as_rs274_shows_the_originals(tmp_path):
    program = HEAD + "o1 sub\n(DEBUG, hole #1 of #<_n>)\nG1 X[#1 * 10] F100\no1 endsub\n#<_n> = 2\n"
    original, output = _compensated(tmp_path, program + "o1 call [1]\no1 call [2]\nM2\n", expand=True)
    messages = [re.findall(r"MESSAGE\((.*)\)", _rs274_text(path)) for path in (original, output)]
    assert messages[0] == messages[1] == ['" hole 1.000000 of 2.000000"', '" hole 2.000000 of 2.000000"']


@pytest.mark.parametrize("name", [name for name in TWINS if name != "IF THEN"])  # (rs274 reads no IF THEN)
def test_expanded_fanuc_macros_move_as_rs274_runs_their_o_word_twins(tmp_path, name):
    fanuc, linuxcnc = TWINS[name]
    program, twin = tmp_path / "fanuc.nc", tmp_path / "twin.ngc"
    program.write_text(fanuc.replace("M30", "M2"))  # (rs274 says M30 otherwise than M2: a pallet shuttle)
    twin.write_text(linuxcnc)
    output = compensate_file(program, MACHINE, tmp_path, expand=True)
    text = output.read_text()
    running = text[: text.index("\nM2\n")]  # (the subprograms after the program's end stay as they are)
    assert not FLOW_LINE.search(running), text
    check = _pathcheck(twin, output, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


@pytest.mark.parametrize("command", [("ncpp", "compensate"), ("ncpp",)])
def test_both_commands_take_the_option_and_refuse_with_the_place(tmp_path, command):
    (tmp_path / "machine.toml").write_text(MACHINE)
    (tmp_path / "p.ngc").write_text(PROGRAMS["repeat loop"])
    (tmp_path / "bad.ngc").write_text(HEAD + "o1 repeat [2]\n  G33 Z-1 K1\no1 endrepeat\nM2\n")
    environ = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    environ.update(PYTHONPATH=str(ROOT), HOME=str(tmp_path))

    def run(name: str) -> subprocess.CompletedProcess:
        arguments = ["--machine", "machine.toml", "--expand", name, "-o", "out.ngc"]
        return subprocess.run([sys.executable, "-m", *command, *arguments], capture_output=True, text=True,
                              cwd=tmp_path, env=environ, timeout=300)  # fmt: skip

    done = run("p.ngc")
    assert done.returncode == 0, done.stderr
    assert "o2 repeat" not in (tmp_path / "out.ngc").read_text() and "loop or subroutine" not in done.stderr
    refused = run("bad.ngc")
    assert refused.returncode != 0 and "bad.ngc:5:3: --expand: threading G33" in refused.stderr


def test_the_corpus_mount_program_expanded_runs_in_rs274_as_the_original(tmp_path):
    """LinuxCNC's own sample mmount.ngc: a hole-milling subroutine with a while loop, called 13
    times in three work offsets (G55-G57, given by a parameter file), six tools (a tool table)."""
    program = CORPUS / "iso_gcode" / "linuxcnc" / "mmount.ngc"
    if not (program.exists() and WIDE.exists()):
        pytest.skip("the corpus or wide.toml is not there")
    tools = tool_table(tmp_path)
    var = tmp_path / "mmount.var"  # inch, as the tool table: the stations' zeros 10 in apart
    var.write_text(
        "5220 1\n5241 2\n5242 1.5\n5243 -3\n5261 12\n5262 1.5\n5263 -3\n5281 22\n5282 1.5\n5283 -3\n"
    )
    output = tmp_path / "mmount-expanded.ngc"
    arguments = ["--machine", str(WIDE), "--var-file", str(var), "--tool-table", str(tools),
                 "--var-units", "inch", "--expand", str(program), "-o", str(output)]  # fmt: skip
    done = subprocess.run([sys.executable, "-m", "ncpp", "compensate", *arguments], capture_output=True,
                          text=True, timeout=600, env=dict(os.environ, PYTHONPATH=str(ROOT)))  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "in loops or subroutines" not in done.stderr and not FLOW_LINE.search(_running(output.read_text()))
    check = _pathcheck(program, output, "--var-file", str(var), "--tool-table", str(tools), "--tol-mm", "0.5")
    assert check.returncode == 0, check.stdout + check.stderr


# A corpus program with a loop, a subroutine or a Fanuc subprogram or macro loop
_FLOWING = re.compile(rb"^\s*(N\d+\s*)?o\s*(\d+|<[^>]*>)\s*(sub|while|repeat|do)\b|M98|WHILE", re.I | re.M)


def _flowing() -> list[Path]:
    return [path for path in programs() if _FLOWING.search(path.read_bytes())]


@pytest.mark.parametrize("program", _flowing(), ids=corpus_id)
def test_corpus_programs_with_loops_expanded_run_in_rs274_as_the_originals(program, tmp_path):
    """Every corpus program with loops or subroutines that rs274 runs, written out on the wide
    machine: pathcheck passes, or ncpp refuses it as it does without --expand, or --expand
    refuses a construct out of scope inside a loop or subroutine."""
    if not WIDE.exists():
        pytest.skip("wide.toml is not there")
    tools = tool_table(tmp_path)
    original = as_linuxcnc_reads(program, tmp_path)
    if not rs274_runs(original, tools, rs274_environment(tmp_path)):
        pytest.skip("rs274 refuses the original: nothing to compare")

    def compensate(*options: str) -> subprocess.CompletedProcess:
        arguments = ["--machine", str(WIDE), "--tool-table", str(tools), "--var-units", "inch", *options]
        return subprocess.run([sys.executable, "-m", "ncpp", "compensate", *arguments, str(program), "-o",
                               str(tmp_path / "out.ngc")], capture_output=True, text=True, timeout=600,
                              env=dict(os.environ, PYTHONPATH=str(ROOT)))  # fmt: skip

    done = compensate("--expand")
    if done.returncode != 0:
        error = done.stderr.strip().splitlines()[-1]
        assert "--expand: " in error and "inside a loop" in error or compensate().returncode != 0, error
        return
    check = _pathcheck(original, tmp_path / "out.ngc", "--tool-table", str(tools), "--tol-mm", "0.5")
    assert check.returncode == 0, check.stdout + check.stderr
