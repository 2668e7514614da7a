"""A run killed (SIGKILL, no clean-up) leaves nothing behind: no file beside its output, none in
$TMPDIR, and no process of its own still writing programs."""

from __future__ import annotations

import os
import random
import signal
import stat
import subprocess
import time
from pathlib import Path

import pytest

from tests.conftest import SHARED
from tests.hostile.conftest import PYTHON, ROOT

MACHINE = SHARED / "machines/wide.toml"
pytestmark = [
    pytest.mark.skipif(not MACHINE.exists(), reason="no shared machine file"),
    pytest.mark.skipif(not os.path.isdir("/proc/self/fd"), reason="finds open files through Linux's /proc"),
]


def _program(path: Path, moves: int) -> Path:
    """A program of `moves` feed moves, long enough to be killed while it is written."""
    rng = random.Random(moves)
    lines = ["G21 G17 G90 F200", "G0 X0 Y0 Z5"]
    lines += [f"G1 X{rng.uniform(0, 100):.3f} Y{rng.uniform(0, 100):.3f}" for _ in range(moves)]
    path.write_text("\n".join([*lines, "M2", ""]))
    return path


def _family(pid: int) -> list[int]:
    """`pid` and the processes it started, and theirs."""
    found = [pid]
    for task in Path(f"/proc/{pid}/task").glob("*"):
        try:
            children = (task / "children").read_text().split()
        except OSError:
            continue
        for child in children:
            found += _family(int(child))
    return found


def _writing_into(pids: list[int], folder: Path) -> bool:
    """Whether one of `pids` holds a file in `folder` open (named or not)."""
    for pid in pids:
        for fd in Path(f"/proc/{pid}/fd").glob("*"):
            try:
                if os.readlink(fd).startswith(f"{folder}/"):
                    return True
            except OSError:
                pass
    return False


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state not in ("Z", "X")


def _kill_while_writing(args: list[str], out: Path, temporary: Path) -> list[int]:
    """Start `ncpp ARGS`, SIGKILL it once it writes into `out`; the processes it had started."""
    env = {**os.environ, "PYTHONPATH": str(ROOT), "TMPDIR": str(temporary)}
    run = subprocess.Popen([PYTHON, "-m", "ncpp", *args], env=env, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 60
        family = _family(run.pid)
        while not _writing_into(family, out):
            assert run.poll() is None and time.monotonic() < deadline, "never wrote its output"
            time.sleep(0.05)
            family = _family(run.pid)
        time.sleep(0.5)
        family = _family(run.pid)
    finally:
        run.send_signal(signal.SIGKILL)
        run.wait()
    return family[1:]


def _stopped(pids: list[int], seconds: float = 10) -> bool:
    deadline = time.monotonic() + seconds
    while any(_alive(pid) for pid in pids) and time.monotonic() < deadline:
        time.sleep(0.1)
    survivors = [pid for pid in pids if _alive(pid)]
    for pid in survivors:  # (the test's clean-up: nothing left running after it)
        os.kill(pid, signal.SIGKILL)
    return not survivors


def test_a_killed_run_leaves_no_file_beside_its_output(tmp_path):
    out, temporary = tmp_path / "out", tmp_path / "tmp"
    out.mkdir()
    temporary.mkdir()
    program = _program(tmp_path / "big.ngc", 40_000)
    children = _kill_while_writing(
        ["compensate", "--machine", str(MACHINE), str(program), "-o", str(out / "big.nc")], out, temporary
    )
    assert _stopped(children)
    assert sorted(os.listdir(out)) == []
    assert sorted(os.listdir(temporary)) == []


def test_the_workers_of_a_killed_run_stop_with_it(tmp_path):
    out, temporary = tmp_path / "out", tmp_path / "tmp"
    out.mkdir()
    temporary.mkdir()
    programs = [str(_program(tmp_path / f"{name}.ngc", 20_000)) for name in ("a", "b")]
    children = _kill_while_writing(
        ["compensate", "--machine", str(MACHINE), *programs, "--jobs", "2", "-o", str(out)], out, temporary
    )
    assert children, "no worker processes"
    assert _stopped(children), "a worker outlived the run"
    assert sorted(os.listdir(out)) == []
    assert sorted(os.listdir(temporary)) == []


def test_a_new_output_file_takes_its_mode_from_the_umask(tmp_path):
    program = _program(tmp_path / "small.ngc", 3)
    for umask, mode in ((0o022, 0o644), (0o077, 0o600), (0o002, 0o664)):
        target = tmp_path / f"out{umask:o}.nc"
        done = subprocess.run(
            [PYTHON, "-m", "ncpp", "compensate", "--machine", str(MACHINE), str(program), "-o", str(target)],
            env={**os.environ, "PYTHONPATH": str(ROOT)},
            capture_output=True,
            preexec_fn=lambda umask=umask: os.umask(umask),
            timeout=120,
        )
        assert done.returncode == 0, done.stderr
        assert stat.S_IMODE(target.stat().st_mode) == mode
        assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []
