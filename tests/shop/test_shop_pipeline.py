"""Plain `ncpp` in a shop pipeline: where it finds the machine file, and how it fails."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from ncpp import __version__ as package_version
from ncpp.errors import NcppError
from ncpp.integrations.config import config_paths, find_settings, with_linuxcnc_ini
from tests.conftest import READING, ROOT

MACHINE = ROOT / "samples/machines/hr5b.toml"
OTHER = ROOT / "samples/machines/valmet.toml"
PROGRAM = "G21 G90\nG0 X10 Y10 Z10\nG1 X100 F500\nG2 X120 Y30 I0 J20\nM2\n"


@pytest.fixture
def shop(tmp_path):
    """A work folder and an empty home (no config anywhere yet)."""
    (tmp_path / "work").mkdir()
    (tmp_path / "home").mkdir()
    return tmp_path


def env_of(shop: Path, **extra: str) -> dict[str, str]:
    return {"HOME": str(shop / "home"), **extra}


def test_config_files_are_searched_in_the_documented_order(shop):
    env = env_of(shop)
    assert config_paths(shop / "work", env) == [
        shop / "work/ncpp.toml",
        shop / "home/.config/ncpp/config.toml",
    ]
    env["XDG_CONFIG_HOME"] = str(shop / "xdg")
    assert config_paths(shop / "work", env)[1] == shop / "xdg/ncpp/config.toml"


def test_lookup_order_option_then_environment_then_local_then_user_config(shop):
    user = shop / "home/.config/ncpp/config.toml"
    user.parent.mkdir(parents=True)
    user.write_text(f'machine = "{OTHER}"\ntolerance = 0.004\n')
    work, env = shop / "work", env_of(shop)
    assert find_settings(cwd=work, env=env).machine == str(OTHER)
    assert find_settings(cwd=work, env=env).tolerance == 0.004
    (work / "ncpp.toml").write_text('machine = "m/hr5b.toml"\nwork_offset = [400, 350, 300]\n')
    local = find_settings(cwd=work, env=env)
    assert local.machine == str(work / "m/hr5b.toml")  # relative to the config file
    assert (
        local.zeros == {"G54": (400.0, 350.0, 300.0)} and local.tolerance == 0.001
    )  # only the first file is read
    assert local.origin == str(work / "ncpp.toml")
    env["NCPP_MACHINE"] = "/env/m.toml"
    assert find_settings(cwd=work, env=env).machine == "/env/m.toml"
    chosen = find_settings("cli.toml", 0.002, None, cwd=work, env=env)
    assert (chosen.machine, chosen.tolerance, chosen.origin) == ("cli.toml", 0.002, "--machine")
    assert chosen.zeros == {"G54": (400.0, 350.0, 300.0)}  # not given on the command line: the config's


def test_no_machine_anywhere(shop):
    settings = find_settings(cwd=shop / "work", env=env_of(shop))
    assert settings.machine is None and settings.origin == "defaults"


@pytest.mark.parametrize(
    "text, message",
    [
        ("machine = 3\n", "path string"),
        ("tolerance = -1\n", "positive"),
        ("work_offset = [1, 2]\n", r"\[x, y, z\]"),
        ("work_offset = {G55 = [1e308, 0, 0]}\n", "within ±1,000,000 mm"),
        ("mashine = 'a'\n", "unknown key"),
        ("machine = \n", "not a valid TOML"),
    ],
)
def test_bad_config_is_an_error_naming_the_file(shop, text, message):
    (shop / "work/ncpp.toml").write_text(text)
    with pytest.raises(NcppError, match=message) as err:
        find_settings(cwd=shop / "work", env=env_of(shop))
    assert err.value.where.file.endswith("ncpp.toml")


def test_config_paths_and_the_linuxcnc_ini_files(shop):
    """`var_file` and `tool_table` are relative to the config; the INI's files fill what it
    leaves unnamed, in the INI's units, and only when they exist."""
    work = shop / "work"
    (work / "ncpp.toml").write_text('tool_table = "lcnc/tool.tbl"\nvar_units = "inch"\n')
    settings = find_settings(cwd=work, env=env_of(shop))
    assert settings.tool_table == str(work / "lcnc/tool.tbl") and settings.var_file is None
    ini = work / "lcnc/mill.ini"
    ini.parent.mkdir()
    ini.write_text(
        "[TRAJ]\nLINEAR_UNITS = imperial\n[RS274NGC]\nPARAMETER_FILE = sim.var\n[EMCIO]\nTOOL_TABLE = other.tbl\n"
    )
    assert with_linuxcnc_ini(settings, ini).var_file is None  # no sim.var yet: LinuxCNC starts from zeros
    (ini.parent / "sim.var").write_text("5220 1\n")
    merged = with_linuxcnc_ini(settings, ini)
    assert (
        merged.var_file == str(ini.parent / "sim.var")
        and merged.tool_table == settings.tool_table
        and merged.var_units == "inch"
    )
    plain = with_linuxcnc_ini(find_settings(cwd=shop, env=env_of(shop)), ini)
    assert plain.var_units == "inch" and plain.tool_table is None  # other.tbl does not exist
    assert with_linuxcnc_ini(settings, None) is settings


def ncpp(shop: Path, *args: str, stdin: str = PROGRAM, **env: str) -> subprocess.CompletedProcess:
    full_env = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    full_env.update(env_of(shop, **env), PYTHONPATH=str(ROOT))
    return subprocess.run(
        [sys.executable, "-m", "ncpp", *args],
        input=stdin.encode(),
        capture_output=True,
        cwd=shop / "work",
        env=full_env,
    )


def test_without_a_machine_file_the_filter_passes_through(shop):
    proc = ncpp(shop)
    assert proc.returncode == 0 and proc.stdout.decode() == PROGRAM


def test_version_is_printed_and_reads_no_program(shop):
    proc = ncpp(shop, "--version", stdin="G1 X(\n")  # a program it would refuse, were it read
    assert proc.returncode == 0, proc.stderr.decode()
    assert proc.stdout.decode().strip() == f"ncpp {package_version}"


def test_machine_from_the_environment_compensates(shop):
    proc = ncpp(shop, "--work-offset", "400,350,300", NCPP_MACHINE=str(MACHINE))
    assert proc.returncode == 0, proc.stderr.decode()
    out = proc.stdout.decode()
    assert out.startswith("(ncpp compensated for hr5b.toml") and "X100.0" in out and out != PROGRAM


def test_machine_from_the_local_config_compensates(shop):
    (shop / "work/ncpp.toml").write_text(
        f'machine = "{MACHINE}"\nwork_offset = [400, 350, 300]\ntolerance = 0.002\n'
    )
    proc = ncpp(shop)
    assert proc.returncode == 0, proc.stderr.decode()
    digest = proc.stdout.decode().split("sha256:")[1].split()[0]
    assert (
        proc.stdout.decode().splitlines()[0]
        == f"(ncpp compensated for hr5b.toml sha256:{digest} tolerance 0.002 mm by ncpp {package_version})"
    )


@pytest.mark.parametrize(
    "case, stdin, env, message",
    [
        (
            "missing machine file",
            PROGRAM,
            {"NCPP_MACHINE": "/no/such.toml"},
            "NCPP_MACHINE: machine file /no/such.toml does not exist",
        ),
        (
            "unreadable program",
            "G1 X1 F100\nG2 X3 Y0 R0.1\nM2\n",
            {"NCPP_MACHINE": str(READING)},
            "<stdin>:2:",
        ),
        (
            "compensated twice",
            "(ncpp compensated for hr5b.toml sha256:0 tolerance 0.001 mm)\n" + PROGRAM,
            {"NCPP_MACHINE": str(MACHINE)},
            "already compensated",
        ),
        (
            "outside the travel",
            "G21 G90\nG0 X5000 Y10 Z10\nM2\n",
            {"NCPP_MACHINE": str(MACHINE)},
            "<stdin>:2:",
        ),
    ],
)
def test_any_error_stops_the_pipeline(shop, case, stdin, env, message):
    proc = ncpp(shop, stdin=stdin, **env)
    assert proc.returncode != 0, case
    assert proc.stdout == b""  # nothing reaches the next program in the pipeline
    assert message in proc.stderr.decode() and "Traceback" not in proc.stderr.decode()


def test_shell_pipeline_stops_on_error(shop):
    """With `set -o pipefail` a shell pipeline fails when ncpp fails."""
    script = (
        f"set -o pipefail; printf 'G2 X3 Y0 R0.1\\n' | python3 -m ncpp --machine {READING} | cat > out.nc"
    )
    env = {k: v for k, v in os.environ.items() if k != "NCPP_MACHINE"}
    proc = subprocess.run(
        ["bash", "-c", script],
        cwd=shop / "work",
        env={**env, "PYTHONPATH": str(ROOT), "HOME": str(shop / "home")},
        capture_output=True,
    )
    assert proc.returncode != 0
    assert (shop / "work/out.nc").read_text() == ""


def test_progress_shows_only_on_a_terminal(capsys):
    import io

    from ncpp.cli.progress import progress_printer

    assert progress_printer("filter", io.StringIO()) is None

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    tty = Terminal()
    progress = progress_printer("filter", tty)
    progress(2000)
    progress.done()
    assert "2,000 lines" in tty.getvalue() and tty.getvalue().endswith("\n")
