"""The LinuxCNC [FILTER] program, run the way LinuxCNC runs it; its output goes to rs274."""

from __future__ import annotations

import configparser
import io
import os
import re
import subprocess

import pytest

from ncpp.errors import Warnings
from ncpp.post import post
from tests.conftest import CORPUS, ROOT
from tests.rs274 import calls_from, canon, end_points
from tests.shop.axis import filter_program

FILTER = ROOT / "plugins/linuxcnc/ncpp-linuxcnc-filter"
MACHINE = ROOT / "samples/machines/hr5b.toml"


@pytest.fixture(scope="module")
def program(corpus, tmp_path_factory):
    """A long LinuxCNC program: the Creo roughing CL data posted plainly (8 000+ lines)."""
    path = tmp_path_factory.mktemp("linuxcnc") / "schruppen.ngc"
    out = io.BytesIO()
    cl = CORPUS / "apt_cldata/creo_ncl/schruppen_1.ncl.1"
    with open(cl, encoding="latin-1") as stream:
        post(stream, out, file=str(cl), dialect="linuxcnc", warnings=Warnings(stream=io.StringIO()))
    path.write_bytes(out.getvalue())
    return path


def filter_environment(tmp_path) -> dict[str, str]:
    """This environment without an ncpp machine or config of the user's, HOME in `tmp_path`."""
    home = tmp_path / "home"
    home.mkdir(exist_ok=True)
    base = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    return {**base, "HOME": str(home), "PYTHONPATH": str(ROOT)}


def run_filter(path, tmp_path, **env):
    return subprocess.run(
        [str(FILTER), str(path)],
        capture_output=True,
        cwd=tmp_path,
        env={**filter_environment(tmp_path), **env},
        timeout=300,
    )


def test_ini_lines_name_the_filter_for_ngc_and_nc():
    ini = configparser.ConfigParser()
    ini.optionxform = str
    ini.read(ROOT / "plugins/linuxcnc/filter.ini")
    assert ini["FILTER"]["PROGRAM_EXTENSION"] == ".ngc,.nc ncpp-compensated G-code"
    assert ini["FILTER"]["ngc"] == ini["FILTER"]["nc"] == FILTER.name


def test_filter_compensates_reports_progress_and_rs274_accepts_it(program, tmp_path):
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\nwork_offset = [400, 350, 300]\n')
    proc = run_filter(program, tmp_path)
    assert proc.returncode == 0, proc.stderr.decode()
    progress = [int(n) for n in re.findall(r"^FILTER_PROGRESS=(\d+)$", proc.stderr.decode(), re.M)]
    assert progress[0] == 0 and progress[-1] == 100 and len(progress) >= 4
    assert progress == sorted(progress)
    out = tmp_path / "compensated.ngc"
    out.write_bytes(proc.stdout)
    assert proc.stdout.startswith(b"(ncpp compensated for hr5b.toml")
    var = (
        tmp_path / "g54.var"
    )  # the G54 the placement guard checks (its raw values: rs274's units are inches)
    var.write_text("5220\t1.000000\n5221\t400.000000\n5222\t350.000000\n5223\t300.000000\n")
    compensated, plain = end_points(calls_from(var, out)), end_points(canon(program, timeout=300))
    assert len(compensated) >= len(plain) and compensated != plain


def test_without_machine_file_the_program_loads_unchanged(program, tmp_path):
    proc = run_filter(program, tmp_path)
    assert proc.returncode == 0 and proc.stdout == program.read_bytes()


def test_a_compensated_program_is_not_compensated_again(program, tmp_path):
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\nwork_offset = [400, 350, 300]\n')
    first = run_filter(program, tmp_path)
    assert first.returncode == 0, first.stderr.decode()
    again_in = tmp_path / "again.ngc"
    again_in.write_bytes(first.stdout)
    again = run_filter(again_in, tmp_path)
    assert again.returncode == 0 and again.stdout == first.stdout


def test_an_error_reaches_linuxcnc_as_exit_status_and_message(tmp_path):
    bad = tmp_path / "bad.ngc"
    bad.write_text("G21 G90\nG0 X5000 Y0 Z0\nM2\n")
    proc = run_filter(bad, tmp_path, NCPP_MACHINE=str(MACHINE))
    assert proc.returncode != 0 and proc.stdout == b""
    assert f"{bad}:2:" in proc.stderr.decode() and "outside the X travel" in proc.stderr.decode()


def test_the_parameter_file_places_the_program_as_linuxcnc_does(tmp_path):
    """`var_file` in the config: G54 from LinuxCNC's parameter file, the same output as
    `work_offset` saying the same zero."""
    pocket = ROOT / "samples/programs/pocket.ngc"
    (tmp_path / "linuxcnc.var").write_text(
        "5220\t1.000000\n5221\t400.000000\n5222\t350.000000\n5223\t300.000000\n"
    )
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\nvar_file = "linuxcnc.var"\n')
    from_var = run_filter(pocket, tmp_path)
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\nwork_offset = [400, 350, 300]\n')
    given = run_filter(pocket, tmp_path)
    assert from_var.returncode == 0 and given.returncode == 0, from_var.stderr.decode()
    assert from_var.stdout == given.stdout and from_var.stdout.startswith(b"%\n(ncpp compensated")
    (tmp_path / "ncpp.toml").write_text(
        f'machine = "{MACHINE}"\n'
    )  # G54 at the machine zero: outside the travel
    assert run_filter(pocket, tmp_path).returncode == 2


def test_the_tool_table_gives_the_lengths_g43_applies(tmp_path):
    """`tool_table` in the config (relative to it, like `var_file`): the program's G43 H1
    applies tool 1's length; without it, length 0 and a warning."""
    lines = (ROOT / "samples/programs/pocket.ngc").read_text().splitlines()
    program = tmp_path / "tool.ngc"
    program.write_text("\n".join([lines[0], "T1 M6", "G43 H1", *lines[1:]]) + "\n")
    (tmp_path / "tool.tbl").write_text("T1 P1 Z+120.0 D6.0\n")
    config = f'machine = "{MACHINE}"\nwork_offset = [400, 350, 300]\n'
    (tmp_path / "ncpp.toml").write_text(config + 'tool_table = "tool.tbl"\n')
    told = run_filter(program, tmp_path)
    (tmp_path / "ncpp.toml").write_text(config)
    untold = run_filter(program, tmp_path)
    assert told.returncode == 0 and untold.returncode == 0, told.stderr.decode()
    assert b"G43 applies a tool length" in untold.stderr and b"G43" not in told.stderr
    assert told.stdout != untold.stdout


INI = """[EMC]
MACHINE = mill
[HAL]
HALFILE = core_sim.hal
HALFILE = axis_manualtoolchange.hal
[TRAJ]
LINEAR_UNITS = mm
[RS274NGC]
PARAMETER_FILE = sim.var
[EMCIO]
TOOL_TABLE = tool.tbl
"""


def test_the_configuration_linuxcnc_runs_gives_its_parameter_file_and_tool_table(tmp_path):
    """LinuxCNC exports $INI_FILE_NAME: the filter reads the INI's PARAMETER_FILE and
    TOOL_TABLE (relative to it) when the ncpp config names none, and gets the same
    output as a config naming the zero and the table itself."""
    lines = (ROOT / "samples/programs/pocket.ngc").read_text().splitlines()
    program = tmp_path / "tool.ngc"
    program.write_text("\n".join([lines[0], "T1 M6", "G43 H1", *lines[1:]]) + "\n")
    lcnc = tmp_path / "configs" / "mill"
    lcnc.mkdir(parents=True)
    (lcnc / "mill.ini").write_text(INI)
    (lcnc / "sim.var").write_text("5220\t1.000000\n5221\t400.000000\n5222\t350.000000\n5223\t300.000000\n")
    (lcnc / "tool.tbl").write_text("T1 P1 Z+120.0 D6.0\n")
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\n')
    from_ini = run_filter(program, tmp_path, INI_FILE_NAME=str(lcnc / "mill.ini"))
    (tmp_path / "ncpp.toml").write_text(
        f'machine = "{MACHINE}"\nwork_offset = [400, 350, 300]\ntool_table = "configs/mill/tool.tbl"\n'
    )
    given = run_filter(program, tmp_path)
    told = [line for line in from_ini.stderr.splitlines() if not line.startswith(b"FILTER_PROGRESS")]
    assert from_ini.returncode == 0 and len(told) == 1 and b"tool.ngc: compensated 16 moves" in told[0], (
        from_ini.stderr
    )  # no warning
    assert from_ini.stdout == given.stdout and from_ini.stdout.startswith(b"%\n(ncpp compensated")
    (lcnc / "sim.var").unlink()  # a fresh configuration: LinuxCNC starts with all zeros, and so does ncpp
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\n')
    fresh = run_filter(program, tmp_path, INI_FILE_NAME=str(lcnc / "mill.ini"))
    assert (
        fresh.returncode == 2 and b"outside the" in fresh.stderr
    )  # G54 at the machine zero: the pocket leaves the travel


def test_the_filter_runs_subroutine_files_from_the_ini_subroutine_path(tmp_path):
    """An ngcgui-style program calls a subroutine file: the filter finds it through the INI's
    [RS274NGC]SUBROUTINE_PATH, leaves its moves as LinuxCNC will run them and compensates the
    program's own moves after the call; without the path the rest would pass uncompensated."""
    lcnc = tmp_path / "configs" / "mill"
    (lcnc / "subs").mkdir(parents=True)
    (lcnc / "mill.ini").write_text(
        INI.replace("PARAMETER_FILE = sim.var", "PARAMETER_FILE = sim.var\nSUBROUTINE_PATH = subs")
    )
    (lcnc / "sim.var").write_text("5220\t1.000000\n5221\t400.000000\n5222\t350.000000\n5223\t300.000000\n")
    (lcnc / "subs" / "slot.ngc").write_text("o<slot> sub\nG1 X[#1 + #3] F200\nG1 X#1\no<slot> endsub\n")
    program = tmp_path / "part.ngc"
    program.write_text(
        "G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F200\nG1 X20 Y10\no<slot> call [20] [10] [15]\nG1 X40 Y30\nG0 Z5\nM2\n"
    )
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\n')
    proc = run_filter(program, tmp_path, INI_FILE_NAME=str(lcnc / "mill.ini"))
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.decode().splitlines()
    call = lines.index("o<slot> call [20] [10] [15]")
    assert lines[call - 1].startswith("X20.0") and lines[call + 1].startswith(
        "G1 X"
    )  # compensated on both sides
    assert b"loop or subroutine" in proc.stderr and b"outside the motion interpreter" not in proc.stderr


@pytest.fixture
def axis(tmp_path, monkeypatch):
    """`axis(program, out)`: AXIS's own filter_program runs the filter as filter.ini names it
    (found on PATH, as LinuxCNC finds it), in the environment `run_filter` gives."""
    run = filter_program(tmp_path)
    environment = filter_environment(tmp_path)
    for name in set(os.environ) - set(environment):
        monkeypatch.delenv(name)
    for name, value in environment.items():
        monkeypatch.setenv(name, value)
    monkeypatch.setenv("PATH", f"{FILTER.parent}{os.pathsep}{os.environ['PATH']}")
    monkeypatch.chdir(tmp_path)
    ini = configparser.ConfigParser()
    ini.optionxform = str
    ini.read(ROOT / "plugins/linuxcnc/filter.ini")
    return lambda program, out: run(ini["FILTER"]["ngc"], program, out)


def _configure(folder):
    """An ncpp config placing the program, with the tool its G43 H1 applies (no warning)."""
    (folder / "tool.tbl").write_text("T1 P1 Z+50.0 D3.0\n")
    (folder / "ncpp.toml").write_text(
        f'machine = "{MACHINE}"\nwork_offset = [400, 350, 300]\ntool_table = "tool.tbl"\n'
    )


def _summary_only(message: str) -> bool:
    """Standard error besides the progress: the run's summary alone (no warning)."""
    lines = message.splitlines()
    return len(lines) == 1 and lines[0].startswith("ncpp: ") and ": compensated " in lines[0]


def test_axis_loads_the_program_the_filter_compensated(program, tmp_path, axis):
    _configure(tmp_path)
    out = tmp_path / "loaded.ngc"
    filtered = axis(program, out)
    assert filtered.exit_code == 0 and _summary_only(filtered.message), filtered.message
    assert (
        filtered.progress[0] == 0
        and filtered.progress[-1] == 100
        and filtered.progress == sorted(filtered.progress)
    )
    assert filtered.closed
    assert (
        out.read_bytes() == run_filter(program, tmp_path).stdout
    )  # AXIS's closed standard input changes nothing


def test_axis_shows_the_filters_error_and_loads_nothing(tmp_path, axis):
    bad = tmp_path / "bad.ngc"
    bad.write_text("G21 G90\nG0 X5000 Y0 Z0\nM2\n")
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\n')
    out = tmp_path / "loaded.ngc"
    filtered = axis(bad, out)
    assert filtered.exit_code == 2 and out.read_bytes() == b""
    assert filtered.message.startswith(
        f"{bad}:2:4: "
    )  # at the X word and "outside the X travel" in filtered.message


def test_axis_filters_a_long_program_with_its_progress_bar(program, tmp_path, axis):
    """AXIS reads standard error to its end after the filter exits: the bar moves on with
    the lines compensated, and only the summary is said besides."""
    body = program.read_bytes().removesuffix(b"M2\n")
    large = tmp_path / "large.ngc"
    large.write_bytes(body * (20_000 // body.count(b"\n") + 1) + b"M2\n")
    _configure(tmp_path)
    out = tmp_path / "loaded.ngc"
    filtered = axis(large, out)
    assert filtered.exit_code == 0 and _summary_only(filtered.message), filtered.message
    assert filtered.progress == sorted(filtered.progress) and filtered.progress[-1] == 100
    assert len({p // 10 for p in filtered.progress}) >= 8, filtered.progress  # every tenth of the way shows
    written = out.read_bytes()
    assert written.startswith(b"(ncpp compensated for hr5b.toml") and written.endswith(b"M2\n")
    assert written.count(b"\n") > large.read_bytes().count(b"\n")


def test_the_operator_sees_the_summary_and_each_kind_of_warning_when_the_program_runs(tmp_path):
    """`(MSG, ...)` lines at the program's start: rs274 shows them as MESSAGE calls, before any motion."""
    program = tmp_path / "drill.ngc"
    program.write_text("G21 G90 G54\nG0 X10 Y10 Z5 M3\nG1 X40 F300\no100 repeat [2]\nG98 G81 X50 Y50 Z-3 R2 F100\n"
                       "o100 endrepeat\nG80\nG0 Z5\no200 repeat [2]\nG1 X80 Y40 F200\nG1 X90 Y40\no200 endrepeat\nM2\n")  # fmt: skip
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\nwork_offset = [400, 350, 300]\n')
    proc = run_filter(program, tmp_path)
    assert proc.returncode == 0, proc.stderr.decode()
    out = tmp_path / "loaded.ngc"
    out.write_bytes(proc.stdout)
    var = tmp_path / "g54.var"
    var.write_text("5220\t1.000000\n5221\t400.000000\n5222\t350.000000\n5223\t300.000000\n")
    canon = calls_from(var, out, "T1 P1 D0.1 Z0\n")
    messages = re.findall(r'MESSAGE\("\s*(.*)"\)', canon)
    assert (
        messages[0].startswith("ncpp: drill.ngc: compensated 3 moves") and "largest correction" in messages[0]
    )
    said = " ".join(messages)
    assert (
        "3 moves of canned cycles [line 6]"
        in said  # (its repeat's rapid to the hole it stands over is no move)
        and "8 moves in loops or subroutines [lines 5, 10-12]" in said
    )
    assert [m.split(":")[0] for m in messages if m.startswith("ncpp warning")] == [
        "ncpp warning line 5 [and 1 more]",
        "ncpp warning line 6",
    ]
    assert canon.index("MESSAGE") < canon.index("STRAIGHT_")
