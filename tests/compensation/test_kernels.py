"""Compensation's numeric kernels in a worker process (`--jobs 2`): the same
output as in one process, byte for byte; the same errors; no hang when the
worker dies."""

import io
import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

import ncpp
from ncpp.cli.compensate import AUTO_JOBS_BYTES, jobs_for, spool_from
from ncpp.cli.io import open_input
from ncpp.errors import NcppError
from ncpp.motion.offsets import WorkOffsets
from ncpp.passes.kernels import Worker, WorkerError, child_command, child_environment, run_ahead
from ncpp.pipeline import ErrorSource, process

ROOT = Path(__file__).resolve().parents[2]
CORPUS = ROOT.parent / "shared/corpus/iso_gcode/linuxcnc"
OFFSET = (400.0, 350.0, 300.0)


def _pattern(k: int) -> str:
    """A few lines of every kind the passes treat apart: long lines, arcs in
    three planes (IJK and R), a helix, incremental moves, inch, a rapid."""
    x, y = 10 + k % 50, 5 + k % 30
    return (
        f"G17 G90 G0 X{x} Y{y}\nG1 Z-1\nX{x + 30}\nG2 X{x + 50} Y{y} I10 J0\nG3 X{x + 40} Y{y + 10} R10\n"
        f"G18 G2 X{x + 44} Z-5 I2 K-2\nG19 G3 Y{y + 14} Z-1 J2 K2 X{x + 46}\n"
        f"G17 G91 G1 X-3 Y2\nX1.5 Y-0.5 Z0.2\nG90\nG20 G1 X{(x + 3) / 25.4:.4f} Y{y / 25.4:.4f}\nG21\nG0 Z5\n"
    )


PROGRAM = ("G21 G90 G17 F600\n" + "".join(_pattern(k) for k in range(400)) + "M2\n").encode()


def _compensated(data: bytes, source: ErrorSource, jobs: int) -> bytes:
    out = io.BytesIO()
    process(io.BytesIO(data), out, file="t.ngc", source=source, jobs=jobs, offsets=WorkOffsets.at(OFFSET))
    return out.getvalue()


@pytest.mark.parametrize("machine", ["hr5b", "tl_tuotanto"])  # with and without reversal errors
def test_a_worker_writes_the_same_program(machine):
    source = ErrorSource.from_machine_file(str(ROOT / f"samples/machines/{machine}.toml"))
    inline = _compensated(PROGRAM, source, jobs=1)
    assert inline.count(b"\n") > 5200  # several chunks of the passes
    assert _compensated(PROGRAM, source, jobs=2) == inline


def test_with_a_worker_this_process_evaluates_the_error_map_only_to_probe_it(monkeypatch):
    """Every pass's numbers (subdivide's samples, the arc fit, the solve) run in the worker:
    this process parses, interprets, glues and writes (and probes the map: whether it has
    reversal errors, 2 x 16 points, `is_directional`, and how many steps its inverse needs,
    2 x 4096 on HR5B, whose first step already suffices, `iterations_for`)."""
    import numpy as np

    from ncpp.machine.model import Machine
    from ncpp.passes.inverse import RESIDUAL_SAMPLES

    points = []
    original = Machine.deviation
    monkeypatch.setattr(Machine, "deviation", lambda self, P, *a, **k: points.append(len(np.atleast_2d(P))) or original(self, P, *a, **k))
    source = ErrorSource.from_machine_file(str(ROOT / "samples/machines/hr5b.toml"))
    program = b"".join(PROGRAM.splitlines(keepends=True)[:1500])
    assert _compensated(program, source, jobs=1) and sum(points) > 10_000  # inline: here
    points.clear()
    assert _compensated(program, source, jobs=2) and points == [16, 16, RESIDUAL_SAMPLES, RESIDUAL_SAMPLES]


def test_a_worker_compensates_a_corpus_program_from_a_measurement_the_same():
    data = (CORPUS / "arcspiral.ngc").read_bytes()
    source = ErrorSource.from_measurement(str(ROOT / "samples/measurements/ballbar_XY_R150.csv"))
    assert _compensated(data, source, jobs=2) == _compensated(data, source, jobs=1)


def test_an_error_in_the_worker_names_the_line():
    source = ErrorSource.from_machine_file(str(ROOT / "samples/machines/hr5b.toml"))
    data = PROGRAM.replace(b"M2\n", b"G1 X900\nM2\n")  # beyond X travel (800 mm - 400 offset)
    messages = []
    for jobs in (1, 2):
        with pytest.raises(NcppError) as err:
            _compensated(data, source, jobs)
        messages.append(str(err.value))
    assert messages[0] == messages[1]
    line = data.count(b"\n") - 1  # the G1 X900
    assert f"t.ngc:{line}:" in messages[0] and "outside the X travel" in messages[0]


def _die(code: int) -> None:
    os._exit(code)


def test_a_worker_that_dies_is_an_error_not_a_hang():
    with Worker() as worker:
        call = worker.bind(_die)
        with pytest.raises(WorkerError, match="exit code 3"):
            call(3).result()


def _fail() -> None:
    raise ValueError("a bug")


def test_a_bug_in_the_worker_comes_back_with_its_traceback():
    with Worker() as worker:
        with pytest.raises(WorkerError, match="ValueError: a bug"):
            worker.bind(_fail)().result()


def test_jobs_follow_the_input_size_unless_given(tmp_path):
    big, small = tmp_path / "big.ngc", tmp_path / "small.ngc"
    big.write_bytes(b"G1 X1\n" * (AUTO_JOBS_BYTES // 6 + 1))
    small.write_bytes(b"G1 X1\n")
    cores = len(os.sched_getaffinity(0))
    with open(big, "rb") as b, open(small, "rb") as s:
        assert jobs_for(None, b) == (2 if cores >= 2 else 1)
        assert jobs_for(None, s) == 1
        assert jobs_for(1, b) == 1 and jobs_for(2, s) == 2
    assert jobs_for(None, io.BytesIO(b"G1 X1\n")) == 1  # no file behind it
    read, write = os.pipe()
    with os.fdopen(read, "rb") as pipe:
        os.close(write)
        assert jobs_for(None, pipe) == 1


def _feed(fd: int, text: bytes) -> None:
    with os.fdopen(fd, "wb") as pipe:
        pipe.write(text)


def test_a_piped_program_is_read_from_memory_or_from_a_file_by_its_size(monkeypatch):
    """`open_input`'s spool: from `spool_from` bytes on the pipe is copied to a file, which
    `jobs_for` gives two processes by default; a shorter program is read from memory."""
    for size, spool, kind in ((100, AUTO_JOBS_BYTES, io.BytesIO), (AUTO_JOBS_BYTES + 100, AUTO_JOBS_BYTES, io.BufferedRandom), (100, 0, io.BufferedRandom)):
        text = (b"G1 X1 F100\n" * (size // 11 + 1))[:size]
        read, write = os.pipe()
        with os.fdopen(read, "rb") as pipe:
            writer = threading.Thread(target=_feed, args=(write, text))  # (a pipe holds 64 kB: written while read)
            writer.start()
            monkeypatch.setattr(sys, "stdin", io.TextIOWrapper(pipe))
            with open_input(None, spool) as (stream, name):
                assert (type(stream), name, stream.read()) == (kind, "<stdin>", text)
                assert jobs_for(None, stream) == (2 if kind is io.BufferedRandom and size >= AUTO_JOBS_BYTES and len(os.sched_getaffinity(0)) >= 2 else 1)
            writer.join()
    assert spool_from(1) is None and spool_from(2) == 0


def test_run_ahead_starts_that_many_items_before_giving_the_first():
    started: list[int] = []
    given = []
    for item, handle in run_ahead(range(5), lambda n: started.append(n) or -n, ahead=2):
        given.append((item, handle, len(started)))
    assert given == [(0, 0, 3), (1, -1, 4), (2, -2, 5), (3, -3, 5), (4, -4, 5)]
    started.clear()  # inline: each item is started just before it is given
    assert [(n, len(started)) for n, _ in run_ahead(range(3), started.append, ahead=0)] == [(0, 1), (1, 2), (2, 3)]


def _shadowing_checkout(folder: Path) -> None:
    """A folder holding another ncpp, as a checkout of another version does."""
    (folder / "ncpp" / "passes").mkdir(parents=True)
    (folder / "ncpp" / "__init__.py").write_text("")
    (folder / "ncpp" / "passes" / "__init__.py").write_text("")
    (folder / "ncpp" / "passes" / "kernels.py").write_text("raise ImportError('the working folder\\'s ncpp')\n")
    (folder / "ncpp" / "parts.py").write_text("raise ImportError('the working folder\\'s ncpp')\n")


def test_a_child_process_imports_this_ncpp_not_the_working_folders(tmp_path, monkeypatch):
    """The second part (`parts.py`) and the worker start `python -c`, which puts the working
    folder first on the import path: run in a checkout of another version, they imported it
    (a part compensated by other code, found comparing two parts with one run)."""
    _shadowing_checkout(tmp_path)
    monkeypatch.chdir(tmp_path)
    found = subprocess.run(child_command("import ncpp.parts, ncpp.passes.kernels; print(ncpp.__file__)"), env=child_environment(),
                           capture_output=True, text=True, check=True)  # fmt: skip
    assert Path(found.stdout.strip()) == Path(ncpp.__file__)
    with Worker() as worker:  # and a worker started there does its work
        assert worker.bind(abs)(-2.5).result() == 2.5
