"""`--jobs 2` on a long ISO program file: two parts, one process each (`ncpp/parts.py`).
The output is one run's, byte for byte: when the second process reaches the state
the first has at the cut, and when it does not or fails (the first then does it)."""

import io
import os
import subprocess
import sys
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import ncpp.parts as parts
from ncpp.errors import NcppError, Warnings
from ncpp.fileio import program_file
from ncpp.integrations.linuxcnc import FilterProgress
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process

from .test_kernels import OFFSET, ROOT, _pattern

# long enough for two parts; a canned cycle warns (once per series) all along: before the
# cut, in the second part's window, in what the first part reads ahead past its cut, after it
LINES = [_pattern(k) for k in range(2 * parts.MIN_LINES // 13)]
for _k in range(40, len(LINES), 50):
    LINES[_k] += "G81 X20 Y20 Z-2 R1 F100\nG80\n"
PROGRAM = ("G21 G90 G17 F600\n" + "".join(LINES) + "M2\n").encode()


@pytest.fixture(scope="module")
def program(tmp_path_factory):
    path = tmp_path_factory.mktemp("parts") / "long.ngc"
    path.write_bytes(PROGRAM)
    return path


@pytest.fixture(scope="module")
def source():
    return ErrorSource.from_machine_file(str(ROOT / "samples/machines/hr5b.toml"))


def _compensated(path, source, jobs: int, said: io.StringIO | None = None) -> tuple[bytes, str, object]:
    out, said = io.BytesIO(), said if said is not None else io.StringIO()
    with open(path, "rb") as stream:  # (the dialect is told by the content and the file's name)
        stats = process(stream, out, file=f"long{path.suffix}", source=source, jobs=jobs, warnings=Warnings(stream=said), offsets=WorkOffsets.at(OFFSET))
    return out.getvalue(), said.getvalue(), stats


@pytest.fixture(scope="module")
def one_run(program, source):
    return _compensated(program, source, jobs=1)


def test_two_parts_write_what_one_run_writes(program, source, one_run, monkeypatch):
    split, same = [], parts._same
    monkeypatch.setattr(parts, "_same", lambda a, b: split.append(same(a, b)) or split[-1])
    assert _compensated(program, source, jobs=2) == one_run
    assert split == [True]  # the second process's part was taken


def test_when_the_states_differ_the_first_process_writes_the_rest(program, source, one_run, monkeypatch):
    """It goes on from its cut (it has the state there): no line is read twice."""
    monkeypatch.setattr(parts, "_same", lambda a, b: False)
    monkeypatch.setattr(parts, "_rest_here", lambda *a: pytest.fail("the rest read again"))
    assert _compensated(program, source, jobs=2) == one_run


def test_when_the_second_process_fails_after_its_cut_the_first_writes_the_rest(program, source, one_run, monkeypatch):
    """Its state there was the first's, but it wrote no part: the first reads the program
    again to its cut and writes the rest from its own state (`_rest_here`)."""
    again, rest_here = [], parts._rest_here
    monkeypatch.setattr(parts, "_reply", lambda child: None)
    monkeypatch.setattr(parts, "_rest_here", lambda *a: again.append(1) or rest_here(*a))
    assert _compensated(program, source, jobs=2) == one_run
    assert again == [1]


def test_when_the_second_process_fails_the_first_writes_the_rest(program, source, one_run, monkeypatch):
    monkeypatch.setattr(parts, "_start", lambda job: subprocess.Popen([sys.executable, "-c", "raise SystemExit(3)"], stdin=subprocess.PIPE, stdout=subprocess.PIPE))
    assert _compensated(program, source, jobs=2) == one_run


def _error_of(path, source, jobs: int) -> tuple[str, str]:
    """The error compensating the program stops at, and the warnings given before it."""
    said = io.StringIO()
    with pytest.raises(NcppError) as stopped:
        _compensated(path, source, jobs, said)
    return str(stopped.value), said.getvalue()


@pytest.mark.parametrize("bad", ["G1 X10 (unclosed\n", "G1 X5000\n"])  # unreadable; outside the X travel
def test_an_error_past_the_cut_is_one_runs_without_the_rest_compensated_again(tmp_path, source, monkeypatch, bad):
    """The second process finds it from the first part's state: the first part reports it
    once its own lines are done, with the warnings given before it (none of the lines after
    the cut compensated again)."""
    # twice as long as PROGRAM: the error lies further past the cut than the second part reads ahead
    lines = "".join(LINES * 2).splitlines(keepends=True)
    late = len(lines) * 9 // 10
    while "G81" not in lines[late]:  # before a warning: the warnings before the error are given
        late += 1
    path = tmp_path / "late-error.ngc"
    path.write_text("G21 G90 G17 F600\n" + "".join(lines[:late]) + bad + "".join(lines[late:]) + "M2\n")
    one = _error_of(path, source, jobs=1)
    decided, same = [], parts._same
    monkeypatch.setattr(parts, "_same", lambda a, b: decided.append(same(a, b)) or decided[-1])
    monkeypatch.setattr(parts, "_rest_here", lambda *a: pytest.fail("the rest compensated again"))
    assert _error_of(path, source, jobs=2) == one
    assert decided == [True] and one[0].startswith(f"long.ngc:{late + 2}:")  # the second part was taken, up to its error


# Run in a new interpreter with one BLAS thread (as `ncpp` runs): one thread, so the second
# process is a fork.  Output written before and not yet flushed must reach the file once.
FORKED = """
import io, sys
import ncpp.parts as parts
from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
program, machine, result, offset = sys.argv[1:5]
forked, fork = [], parts._Forked
parts._Forked = lambda job: forked.append(job) or fork(job)
source = ErrorSource.from_machine_file(machine)
with open(program, "rb") as stream, open(result, "wb") as out:
    out.write(b"(before)\\n")
    process(stream, out, file="long.ngc", source=source, jobs=2, warnings=Warnings(stream=io.StringIO()),
            offsets=WorkOffsets.at(tuple(map(float, offset.split(",")))))
print(len(forked))
"""


def test_a_forked_second_process_writes_what_one_run_writes(program, source, one_run, tmp_path):
    result = tmp_path / "out.ngc"
    env = {**os.environ, "OPENBLAS_NUM_THREADS": "1"}
    done = subprocess.run([sys.executable, "-c", FORKED, str(program), str(ROOT / "samples/machines/hr5b.toml"), str(result), ",".join(map(str, OFFSET))],
                          capture_output=True, text=True, env=env, check=True)  # fmt: skip
    assert done.stdout.split() == ["1"]  # the second process was a fork
    assert result.read_bytes() == b"(before)\n" + one_run[0]


def test_a_process_with_another_thread_starts_a_new_interpreter():
    """A fork would copy whatever the other thread holds (a lock, a BLAS pool) held.
    (In a new interpreter with one BLAS thread: this one may have a BLAS pool already.)"""
    script = """
import threading
import numpy
import ncpp.parts as parts
alone = parts._may_fork()
stop = threading.Event()
other = threading.Thread(target=stop.wait)
other.start()
print(alone, parts._may_fork())
stop.set()
other.join()
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env={**os.environ, "OPENBLAS_NUM_THREADS": "1"}, check=True)
    assert done.stdout.split() == ["True", "False"]


def test_a_thread_just_joined_does_not_stop_a_fork():
    """The kernel lists a joined thread a moment longer (1% of joins here): a run right after
    a two-part run (its trading thread joined) still forks."""
    script = """
import threading
import ncpp.parts as parts
refused = 0
for _ in range(3000):
    thread = threading.Thread(target=lambda: None)
    thread.start()
    thread.join()
    refused += not parts._may_fork()
print(refused)
"""
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env={**os.environ, "OPENBLAS_NUM_THREADS": "1"}, check=True)
    assert done.stdout.split() == ["0"]


@pytest.mark.skipif(not hasattr(os, "sched_setaffinity") or len(os.sched_getaffinity(0)) < 2, reason="two CPUs to trade")
def test_the_two_processes_trade_their_cpus_until_stopped(monkeypatch):
    original = os.sched_getaffinity(0)
    cpus = sorted(original)[:2]
    monkeypatch.setattr(parts, "TRADE_S", 0.02)
    other = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        trading = parts._TradedCpus(other.pid, cpus)
        seen, deadline = set(), time.time() + 10
        while len(seen) < 2 and time.time() < deadline:
            mine, theirs = os.sched_getaffinity(0), os.sched_getaffinity(other.pid)
            if len(mine) == 1 and len(theirs) == 1 and mine != theirs:
                seen |= mine
            time.sleep(0.002)
        trading.stop()
        assert seen == set(cpus)  # this process ran on each CPU, the other on the other one
        assert os.sched_getaffinity(0) == os.sched_getaffinity(other.pid) == set(cpus)  # both free again
        trading.stop()  # (twice: no matter)
    finally:
        os.sched_setaffinity(0, original)
        other.kill()
        other.wait()


def test_with_more_than_two_cpus_the_scheduler_places_the_parts():
    assert parts._TradedCpus(os.getpid(), [0, 1, 2]).thread is None


def test_the_warnings_are_one_runs(one_run):
    _, said, _ = one_run
    series = len(range(40, len(LINES), 50))  # five printed, the rest counted: the comparisons above check each is given once
    assert series > 20 and said.count("canned cycle") == 6 and f"({series - 5} not printed, from line " in said


def test_a_short_program_stays_in_one_process(tmp_path):
    path = tmp_path / "short.ngc"
    path.write_bytes(b"G1 X1 F100\n" * (parts.MIN_LINES - 10))
    assert parts.lines_for(str(path)) is None


def test_the_first_part_reads_the_stream_it_is_given(program, source):
    """Progress by the file's position (the LinuxCNC filter's) moves while the first part runs."""
    seen = []
    with open(program, "rb") as stream:
        process(stream, io.BytesIO(), file="long.ngc", source=source, jobs=2, warnings=Warnings(stream=io.StringIO()),
                offsets=WorkOffsets.at(OFFSET), progress=lambda lines: seen.append(stream.tell()))  # fmt: skip
    assert seen and 0 < max(seen) < len(PROGRAM)


def test_a_motion_mode_set_once_at_the_top_is_known_at_the_cut(tmp_path, source, monkeypatch):
    """The second part's writer learns the lines before its window: the program's G1 too."""
    moves = "".join(f"X{10 + (k * 7) % 40}.{k % 10} Y{5 + (k * 3) % 30}\n" for k in range(parts.MIN_LINES + 100))
    path = tmp_path / "modal.ngc"
    path.write_bytes(("G21 G90 G17\nG1 F600\n" + moves + "M2\n").encode())
    split, same = [], parts._same
    monkeypatch.setattr(parts, "_same", lambda a, b: split.append(same(a, b)) or split[-1])
    assert _compensated(path, source, jobs=2)[:2] == _compensated(path, source, jobs=1)[:2]
    assert split == [True]


def test_the_parts_count_the_lines_one_run_writes(program, source, one_run):
    _, _, stats = _compensated(program, source, jobs=2)
    _, _, alone = one_run
    assert (stats.lines_in, stats.lines_out) == (alone.lines_in, alone.lines_out)


def test_states_at_the_cut_differ_where_the_rest_would():
    import numpy as np

    from ncpp.motion.segments import Line
    from ncpp.passes.apply_error_map import PassState
    from ncpp.passes.travel import Travel
    from ncpp.program.blocks import Block

    block = Block("X1", "\n", (), 1)
    motion = (1, -1, 0, 7, 9, 0)
    state = lambda held=(1.0, -1.0, 0.0), last=(1.0, 2.0, 3.0), end=(1.0, 2.0, 0.0), motion=motion: PassState(  # noqa: E731
        Travel(np.array(held), np.array(last)), Line((0.0, 0.0, 0.0), end, False, 100.0, block), motion
    )
    assert state() == state()
    assert state(held=(1.0, 1.0, 0.0)) != state()
    assert state(last=(1.0, 2.0, 3.0001)) != state()
    assert state(end=(1.0, 2.0, 0.0001)) != state()
    assert state(motion=(1, 1, 0, 7, 9, 0)) != state()  # replace_arcs' guesses from the cut on would differ
    assert state(motion=None) != state(motion=None)  # not recorded (the cut was decided late): never the same


def test_a_cut_from_the_parts_paces_writes_what_one_run_writes(program, source, one_run, monkeypatch):
    """On a long program the cut is chosen while the parts run (`parts._Pacer`): the second
    process reports its pace and waits for the cut there; the output is one run's wherever it is."""
    sent, split, same = [], [], parts._same
    send = parts._send
    monkeypatch.setattr(parts, "_send", lambda child, cut: sent.append(cut) or send(child, cut))
    monkeypatch.setattr(parts, "_same", lambda a, b: split.append(same(a, b)) or split[-1])
    assert _compensated(program, source, jobs=2) == one_run
    lines = PROGRAM.count(b"\n")
    assert len(sent) == 1 and sent[0] % parts.LINE_CHUNK == 0
    assert parts.SHARES[0] * lines - parts.LINE_CHUNK <= sent[0] <= parts.SHARES[1] * lines + parts.LINE_CHUNK
    assert split == [True]  # the second process's part, from the cut it was sent


def test_without_the_second_process_pace_the_cut_is_the_usual_share(program, source, one_run, monkeypatch):
    """A second process that ends before it reports: this process decides the cut alone
    when its reading nears the earliest cut, and writes the rest itself."""
    monkeypatch.setattr(parts, "_start", lambda job: subprocess.Popen([sys.executable, "-c", "raise SystemExit(3)"], stdin=subprocess.PIPE, stdout=subprocess.PIPE))
    sent, send = [], parts._send
    monkeypatch.setattr(parts, "_send", lambda child, cut: sent.append(cut) or send(child, cut))
    assert _compensated(program, source, jobs=2) == one_run
    lines = PROGRAM.count(b"\n")
    assert sent == [parts._rounded(lines, parts.FIRST_SHARE)]


@pytest.mark.parametrize("done, ratio", [(3_000, 0.2), (10_000, 0.3), (2_000, 0.0), (40_000, 0.9), (6_000, 0.04)])
def test_the_share_ends_both_parts_together(done, ratio):
    """Decided when the second process waits at its floor and this one has compensated
    `done` lines: from then on both take as long, at one pace (lines to compensate, and
    lines the second reads at `ratio` of their cost)."""
    lines, floor = 250_000, 110_000
    x = parts.share(lines, done, ratio, floor)
    first = x * lines - done + parts.READ_PAST
    second = (x * lines - parts.WINDOW - floor) * ratio + (1 - x) * lines + parts.WINDOW
    if parts.SHARES[0] < x < parts.SHARES[1]:
        assert first == pytest.approx(second, rel=1e-9)
    else:  # beyond the bounds: the nearer one
        assert x in parts.SHARES


def test_the_paced_first_part_still_tells_progress(program, source, one_run, monkeypatch):
    """The pace is measured through the progress callback: the caller's (the LinuxCNC
    filter's FILTER_PROGRESS) is still told every 1000 lines, the program's lines done:
    the first part's, scaled to the whole program once the cut is decided."""
    seen, out, cuts = [], io.BytesIO(), []
    send = parts._send
    monkeypatch.setattr(parts, "_send", lambda child, cut: cuts.append(cut) or send(child, cut))
    with open(program, "rb") as stream:
        stats = process(stream, out, file="long.ngc", source=source, jobs=2, warnings=Warnings(stream=io.StringIO()),
                        offsets=WorkOffsets.at(OFFSET), progress=seen.append)  # fmt: skip
    assert out.getvalue() == one_run[0]
    assert seen[0] == 1000 and seen == sorted(seen) and len(seen) >= 8
    assert cuts[0] < 0.6 * stats.lines_in and seen[-1] == stats.lines_in  # a bar does not stop at the cut


def test_filter_progress_is_the_percentage_of_the_programs_lines_done(program, source):
    said = io.StringIO()
    progress = FilterProgress(str(program), said)
    with open(program, "rb") as stream:
        process(stream, io.BytesIO(), file="long.ngc", source=source, jobs=2, warnings=Warnings(stream=io.StringIO()),
                offsets=WorkOffsets.at(OFFSET), progress=progress)  # fmt: skip
    percents = [int(line.split("=")[1]) for line in said.getvalue().split()]
    assert percents == sorted(percents) and percents[0] <= 10 and 90 <= percents[-1] <= 99


def test_standard_input_redirected_from_a_program_file_is_read_in_two_parts(program, source, one_run, monkeypatch):
    """`ncpp compensate ... < long.ngc`: standard input has no name, but it holds the file."""
    started, start = [], parts._start
    monkeypatch.setattr(parts, "_start", lambda job: started.append(job.path) or start(job))
    with open(program, "rb") as named, open(os.dup(named.fileno()), "rb") as stdin:  # a descriptor, no name
        assert not isinstance(stdin.name, str)
        out, said = io.BytesIO(), io.StringIO()
        process(stdin, out, file="long.ngc", source=source, jobs=2, warnings=Warnings(stream=said), offsets=WorkOffsets.at(OFFSET))
    assert started == [os.path.realpath(program)]
    assert (out.getvalue(), said.getvalue()) == one_run[:2]


def test_the_program_file_behind_a_stream(program, tmp_path):
    with open(program, "rb") as named:
        assert program_file(named) == os.path.realpath(program)
        with open(os.dup(named.fileno()), "rb") as unnamed:
            assert program_file(unnamed) == os.path.realpath(program)
        named.read(10)
        assert program_file(named) is None  # read from elsewhere than its start: the parts could not both start there
    gone = tmp_path / "gone.ngc"
    gone.write_bytes(PROGRAM)
    with open(gone, "rb") as stream:
        gone.unlink()
        assert program_file(stream) is None  # no path names it: the second process could not open it
    read, write = os.pipe()
    with open(read, "rb") as pipe, open(write, "wb"):
        assert program_file(pipe) is None
    assert program_file(io.BytesIO(PROGRAM)) is None


def test_a_file_this_process_may_not_open_by_name_is_not_a_program_file(program, monkeypatch):
    """`sudo -u nc ncpp < /root/in.nc`: the shell opened it; the parts could not (root may
    open anything, so the refusal is told here)."""
    monkeypatch.setattr(os, "access", lambda path, mode: False)
    with open(program, "rb") as stream:
        assert program_file(stream) is None


def test_the_command_with_standard_input_redirected_writes_one_runs_output(program, one_run):
    offset = ",".join(map(str, OFFSET))
    with open(program, "rb") as stdin:
        done = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(ROOT / "samples/machines/hr5b.toml"),
                               "--work-offset", offset, "--jobs", "2"], stdin=stdin, capture_output=True, check=True)  # fmt: skip
    assert done.stdout == one_run[0]


# The command, its input piped: `process_in_two_parts` is told how often it ran
PIPED = """
import sys
import ncpp.parts as parts
from ncpp.cli import main
runs, two_parts = [], parts.process_in_two_parts
parts.process_in_two_parts = lambda *a, **k: runs.append(a[1]) or two_parts(*a, **k)
code = main(sys.argv[1:])
print(len(runs), file=sys.stderr)
raise SystemExit(code)
"""


@pytest.mark.parametrize("jobs", [["--jobs", "2"], ["--jobs", "1"]])
def test_a_piped_program_is_copied_to_a_file_and_read_in_two_parts(program, one_run, jobs):
    """With --jobs 2 (or, by default, from 2 MB on) a piped program is read to its end into
    a temporary file first, which two processes can read; with --jobs 1 it streams."""
    args = ["compensate", "--machine", str(ROOT / "samples/machines/hr5b.toml"), "--work-offset", ",".join(map(str, OFFSET)), *jobs]
    done = subprocess.run([sys.executable, "-c", PIPED, *args], input=PROGRAM, capture_output=True, check=True)
    assert done.stdout == one_run[0]
    assert done.stderr.split()[-1] == (b"1" if jobs[1] == "2" else b"0")


def _posted(dialect: str) -> bytes:
    """The long program written as a `dialect` program by ncpp's own post generator (the same moves)."""
    from ncpp.motion import interpret
    from ncpp.post import GENERATORS
    from ncpp.program.parser import parse_stream

    quiet = Warnings(stream=io.StringIO())
    events = interpret(parse_stream(io.BytesIO(PROGRAM), "long.ngc"), file="long.ngc", warnings=quiet)
    return "".join(line + "\n" for line in GENERATORS[dialect](quiet).write(events, lambda event: None)).encode("latin-1")


@pytest.mark.parametrize("dialect, suffix", [("sinumerik", ".mpf"), ("heidenhain", ".h")])
def test_other_dialects_in_two_parts_write_what_one_run_writes(tmp_path, source, monkeypatch, dialect, suffix):
    """Their second parts read every line before the window; a Klartext second part's block
    numbers are put right by the blocks the first part inserted (`HeidenhainState.append`)."""
    path = tmp_path / f"long{suffix}"
    path.write_bytes(_posted(dialect))
    one = _compensated(path, source, jobs=1)
    split, same = [], parts._same
    monkeypatch.setattr(parts, "_same", lambda a, b: split.append(same(a, b)) or split[-1])
    assert parts.lines_for(str(path)) is not None
    assert _compensated(path, source, jobs=2) == one
    assert split == [True]  # the second process's part was taken
    monkeypatch.setattr(parts, "_same", lambda a, b: False)  # the first process does the rest from its state
    assert _compensated(path, source, jobs=2) == one


def test_a_klartext_pole_set_before_the_window_is_learnt(tmp_path, source, monkeypatch):
    """A `CC` at the top and polar moves after it: the second part's writer learns the pole
    from the lines before its window (`learn_event`), so its part is taken."""
    moves = [f"LP PR+{10 + k % 40} PA+{(37 * k) % 360}" if k % 2 else f"L X+{k % 50} Y+{(3 * k) % 50} Z-{2 + k % 3}" for k in range(parts.MIN_LINES + 2000)]
    text = ["BEGIN PGM POLAR MM", "L Z+5 R0 FMAX", "CC X+0 Y+0", "L X+10 Y+0 R0 F500", "L Z-2 R0 F300", *moves, "END PGM POLAR MM"]
    path = tmp_path / "long.h"
    path.write_text("".join(f"{n} {line}\n" for n, line in enumerate(text)))
    one = _compensated(path, source, jobs=1)
    split, same = [], parts._same
    monkeypatch.setattr(parts, "_same", lambda a, b: split.append(same(a, b)) or split[-1])
    assert _compensated(path, source, jobs=2) == one
    assert split == [True]


def test_a_klartext_second_part_is_renumbered_by_the_first_parts_insertions():
    from ncpp.program.dialects.heidenhain import HeidenhainWriter

    first, second = HeidenhainWriter(), HeidenhainWriter()
    first.shift, first.last_number, second.shift, second.last_number = 7, 507, 2, 502
    assert first.state() == second.state()  # the numbering is carried, not compared
    out = io.BytesIO()
    first.state().append(second.state(), io.BytesIO(b"503 L X+1 R0\n504 CC X+0 Y+0\n  505 C X+2 Y+0 DR+\n; 12 a comment\n506 L X+1 ~\n5 Y+2\n"), out)
    assert out.getvalue() == b"508 L X+1 R0\n509 CC X+0 Y+0\n  510 C X+2 Y+0 DR+\n; 12 a comment\n511 L X+1 ~\n5 Y+2\n"


def test_a_sinumerik_writer_learns_the_modal_cip_and_ct():
    """A second part's writer learns the program's motion mode from the lines before its
    window: Sinumerik's CIP and CT are motion modes too."""
    from ncpp.program.dialects import parse_program
    from ncpp.program.dialects.sinumerik import SinumerikWriter

    _, blocks = parse_program(io.BytesIO(b"G1 X0 Y0 F100\nCIP X10 Y10 I1=5 J1=8\nCT X20 Y5\nX30\n"), "t.mpf", "sinumerik")
    writer, learnt = SinumerikWriter(), []
    for block in blocks:
        writer.learn(block)
        learnt.append(writer.program_motion)
    assert learnt == [1, "CIP", "CT", "CT"]


def _given_in_two_parts(warned: list[tuple[str, int]], cut: int) -> tuple[str, int]:
    """What a run in two parts prints of `warned` ((text, line), in order) and its count: the
    first part's lines before `cut`, then the second part's, kept (`_Kept`) and given."""
    from ncpp.errors import Location
    from ncpp.passes.context import CutLine

    out = io.StringIO()
    first, second = Warnings(stream=out), parts._Kept(False, CutLine(cut))
    for text, line in warned:
        where = Location("p.ngc", line, 1)
        if line < cut:
            first.warn(text, where)
        second.warn(text, where)  # the second part reads the lines before its cut too
    parts._give(second.said, first)
    first.finish()
    return out.getvalue(), first.count


def _given_in_one_run(warned: list[tuple[str, int]]) -> tuple[str, int]:
    from ncpp.errors import Location

    out = io.StringIO()
    one = Warnings(stream=out)
    for text, line in warned:
        one.warn(text, Location("p.ngc", line, 1))
    one.finish()
    return out.getvalue(), one.count


@given(st.lists(st.tuples(st.sampled_from("abc"), st.integers(1, 40)), max_size=60), st.integers(1, 41))
@settings(max_examples=300, deadline=None)
def test_warnings_given_in_two_parts_are_one_runs(warned, cut):
    warned = sorted(warned, key=lambda w: w[1])  # a program warns in line order
    assert _given_in_two_parts(warned, cut) == _given_in_one_run(warned)


def test_the_second_part_keeps_a_few_warnings_of_each_text_however_many_it_gives():
    from ncpp.errors import SHOWN_PER_TEXT
    from ncpp.passes.context import UNDECIDED, CutLine

    cut = CutLine(UNDECIDED)
    kept = parts._Kept(False, cut, lowest=1000)
    for line in range(1, 200_001):
        if line == 1000:
            cut.line = 5000  # decided: before it, the first part's lines
        kept.warn("canned cycle" if line % 2 else "other", parts.Location("p.ngc", line, 1))
    assert len(kept.said) == 2 * (SHOWN_PER_TEXT + 1)
    assert kept.said[0].where.line == 5000 and kept.said[-1].times == (200_000 - 5000) // 2 - SHOWN_PER_TEXT
    warned = [("canned cycle" if line % 2 else "other", line) for line in range(1, 200_001)]
    assert _given_in_two_parts(warned, 5000) == _given_in_one_run(warned)


def test_a_cut_under_cutter_compensation_writes_what_one_run_writes(tmp_path, source, monkeypatch):
    """Every input line a cut may fall on (a multiple of LINE_CHUNK) lies under G41.1, between the
    entry move and the exit move after G40: the parts' states there (the interpreter's
    compensation, the passes' last segment) must still be one run's."""
    from ncpp.passes.geometry import LINE_CHUNK

    lines = ["G21 G90 G17 G94 G0 X0 Y0 Z5", "G1 Z-1 F600"]
    while len(lines) < 2 * parts.MIN_LINES + 100:
        n = len(lines) + 1  # the line about to be written
        if (n + 40) % LINE_CHUNK == 0:
            lines += ["G41.1 D4", "G1 X20 Y0"]
        elif (n - 40) % LINE_CHUNK == 0:
            lines += ["G40", "G1 X10 Y10"]
        else:
            lines.append(f"G1 X{10 + n % 11 * 3} Y{n % 13 * 2}")
    path = tmp_path / "comp.ngc"
    path.write_text("\n".join(lines) + "\nG40\nM2\n")
    split, same = [], parts._same
    monkeypatch.setattr(parts, "_same", lambda a, b: split.append(same(a, b)) or split[-1])
    one, said, _ = _compensated(path, source, jobs=1)
    assert "cutter compensation" in said
    assert _compensated(path, source, jobs=2)[:2] == (one, said)
    assert split == [True]
