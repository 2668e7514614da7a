"""What a run leaves behind and where its errors point: temporaries, special files, places."""

from __future__ import annotations

import os
import signal
import stat
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.conftest import READING, SHARED
from tests.hostile.conftest import ROOT

MACHINE = SHARED / "machines/wide.toml"
needs_machine = pytest.mark.skipif(not MACHINE.exists(), reason="no shared machine file")


def _long_program(path: Path, moves: int = 400_000) -> Path:
    with open(path, "w") as f:
        f.write("G21 G90 G17 F500\nG0 X0 Y0 Z5\n")
        for k in range(moves):
            f.write(f"G1 X{k % 100}.{k % 7} Y{k % 50}.3\n")
        f.write("M2\n")
    return path


def _writing_into(pid: int, folder: Path) -> bool:
    """Whether process `pid` holds a file of `folder` open with something in it (named or not:
    Linux's anonymous output file shows as `folder/#inode (deleted)`)."""
    for fd in Path(f"/proc/{pid}/fd").glob("*"):
        try:
            if os.path.dirname(os.readlink(fd)) == str(folder) and fd.stat().st_size:
                return True
        except OSError:
            pass
    return False


@needs_machine
@pytest.mark.parametrize("sig, status", [(signal.SIGTERM, 143), (signal.SIGINT, 130)])
def test_a_terminated_run_removes_its_temporaries(tmp_path, sig, status):
    program = _long_program(tmp_path / "long.ngc")
    out = tmp_path / "out.nc"
    tmp = tmp_path / "tmp"
    tmp.mkdir()
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TMPDIR": str(tmp)}
    run = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "ncpp",
            "compensate",
            "--machine",
            str(MACHINE),
            "--jobs",
            "1",
            str(program),
            "-o",
            str(out),
        ],
        env=env,
        stderr=subprocess.PIPE,
        # (a shell's background job ignores SIGINT, and so would ncpp started from it: as at a terminal)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.monotonic() + 60
    # (a file beside the output holding lines: the run is past its start, imports and all)
    while not _writing_into(run.pid, tmp_path) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert _writing_into(run.pid, tmp_path), "the run never started writing"
    run.send_signal(sig)
    # (a shell reports 128 + the signal either way: CPython ends a process by the signal itself when
    # the KeyboardInterrupt it caught was raised in an import under way, as scipy's may be)
    assert run.wait(timeout=60) in (status, -sig), run.stderr.read()
    assert b"Traceback" not in run.stderr.read()
    assert not list(tmp_path.glob(".out.nc.*")) and not out.exists() and not list(tmp.iterdir())


def test_output_onto_a_fifo_is_written_into_it(ncpp, tmp_path):
    program = tmp_path / "p.ngc"
    program.write_text("G1 X1 F100\nM2\n")
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    reader = subprocess.Popen(["cat", str(fifo)], stdout=subprocess.PIPE)
    done = ncpp(str(program), "-o", str(fifo))
    assert done.returncode == 0, done.stderr
    assert reader.communicate(timeout=30)[0] == b"G1 X1 F100\nM2\n"
    assert stat.S_ISFIFO(os.lstat(fifo).st_mode)


def test_output_onto_a_character_device_leaves_it_a_device(ncpp, tmp_path):
    """As root `-o /dev/null` replaced /dev/null by a regular file; a device node made here
    stands for it (a null device: the test makes its own, never touches /dev)."""
    program = tmp_path / "p.ngc"
    program.write_text("G1 X1 F100\nM2\n")
    node = tmp_path / "null"
    try:
        os.mknod(node, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
    except PermissionError:
        pytest.skip("making a device node takes root")
    done = ncpp(str(program), "-o", str(node))
    assert done.returncode == 0, done.stderr
    assert stat.S_ISCHR(os.lstat(node).st_mode)


def test_output_through_a_symlink_replaces_its_target_and_keeps_the_link(ncpp, tmp_path):
    program = tmp_path / "p.ngc"
    program.write_text("G1 X1 F100\nM2\n")
    target = tmp_path / "real.nc"
    target.write_text("old\n")
    os.chmod(target, 0o640)
    link = tmp_path / "link.nc"
    link.symlink_to(target)
    done = ncpp(str(program), "-o", str(link))
    assert done.returncode == 0, done.stderr
    assert link.is_symlink() and target.read_text() == "G1 X1 F100\nM2\n"
    assert stat.S_IMODE(target.stat().st_mode) == 0o640


def test_an_unwritable_output_names_its_file(ncpp, tmp_path):
    """A write error has no file name of its own: the message names the output (a full
    device made here: a regression must not replace the system's /dev/full)."""
    program = tmp_path / "p.ngc"
    program.write_text("G1 X1 F100\nM2\n")
    full = tmp_path / "full"
    try:
        os.mknod(full, 0o666 | stat.S_IFCHR, os.makedev(1, 7))
    except PermissionError:
        pytest.skip("making a device node takes root")
    done = ncpp(str(program), "-o", str(full))
    assert done.returncode == 2
    assert done.stderr.decode().strip() == f"ncpp: {full}: No space left on device"


@pytest.mark.parametrize(
    "text, where",
    [
        ("o<s> sub\nG1 X1\n", "1:1: o<s> sub has no o<s> endsub"),
        ("G1 X1 Y1 Z1 F100\n  o100 sub\nG1 X1\nM2\n", "2:3: o100 sub has no o100 endsub"),
    ],
)
def test_an_open_subroutine_is_located(ncpp, tmp_path, text, where):
    program = tmp_path / "p.ngc"
    program.write_text(text)
    done = ncpp("--machine", str(READING), str(program))
    assert done.stderr.decode().strip() == f"{program}:{where}"


def test_a_name_with_control_characters_is_escaped(ncpp, tmp_path):
    program = tmp_path / "p.ngc"
    program.write_bytes(b"o<a\x1b[31mb> call\nM2\n")
    done = ncpp("--machine", str(READING), str(program))
    assert b"\x1b" not in done.stderr and b"o<a\\x1b[31mb>" in done.stderr


@needs_machine
def test_a_tool_table_error_never_quotes_another_files_text(ncpp, tmp_path):
    program = tmp_path / "p.ngc"
    program.write_text("G43 H1\nG1 X1 F100\nM2\n")
    secret = tmp_path / "secret"
    secret.write_text("root:x:0:0:root:/root:/bin/bash\n")
    done = ncpp("compensate", "--machine", str(MACHINE), "--tool-table", str(secret), str(program))
    assert done.returncode == 2 and b"root:x" not in done.stderr
    assert done.stderr.decode().startswith(f"{secret}:1:1: ")


@needs_machine
@pytest.mark.parametrize("key", ["var_file", "tool_table", "machine"])
def test_a_settings_file_that_never_ends_is_refused(ncpp, tmp_path, key):
    program = tmp_path / "p.ngc"
    program.write_text("G1 X1 F100\nM2\n")
    if key == "machine":
        done = ncpp("compensate", "--machine", "/dev/zero", str(program), memory_mb=2048)
    else:
        (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\n{key} = "/dev/zero"\n')
        done = ncpp(
            str(program), cwd=str(tmp_path), memory_mb=2048, env={"XDG_CONFIG_HOME": str(tmp_path / "none")}
        )
    assert done.returncode == 2 and b"Traceback" not in done.stderr
    assert (
        done.stderr.decode().startswith("/dev/zero:1:1: not a ") and "more than 64 MB" in done.stderr.decode()
    )


@needs_machine
def test_a_config_file_that_is_not_utf8_is_a_located_error(ncpp, tmp_path):
    (tmp_path / "ncpp.toml").write_bytes(b'machine = "\xff"\n')
    program = tmp_path / "p.ngc"
    program.write_text("G1 X1 F100\nM2\n")
    done = ncpp(str(program), cwd=str(tmp_path), env={"XDG_CONFIG_HOME": str(tmp_path / "none")})
    assert done.returncode == 2 and b"Traceback" not in done.stderr
    assert done.stderr.decode().startswith(f"{tmp_path / 'ncpp.toml'}:1:1: not UTF-8")


def test_a_subroutine_name_stays_inside_the_subroutine_path(ncpp, tmp_path):
    """rs274ngc joins the name to each folder as text ("folder/name.ngc", `find_ngc_file`):
    `o</abs/x>` is folder/abs/x.ngc, never /abs/x.ngc."""
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "evil.ngc").write_text("o<evil> sub\nG1 X77 F100\no<evil> endsub\nM2\n")
    subs = tmp_path / "subs"
    subs.mkdir()
    program = tmp_path / "p.ngc"
    for name in (str(outside / "evil"), "../outside/evil"):
        program.write_text(f"G21 F100\no<{name}> call\nM2\n")
        done = ncpp("motion", "--subroutine-path", str(subs), str(program))
        assert "77" not in done.stdout.decode() and "does not define" in done.stderr.decode()
    inner = subs / outside.relative_to("/")
    inner.mkdir(parents=True)
    (inner / "evil.ngc").write_text(
        f"o<{outside / 'evil'}> sub\nG1 X33 F100\no<{outside / 'evil'}> endsub\nM2\n"
    )
    program.write_text(f"G21 F100\no<{outside / 'evil'}> call\nM2\n")
    done = ncpp("motion", "--subroutine-path", str(subs), str(program))
    assert "33" in done.stdout.decode(), done.stderr
