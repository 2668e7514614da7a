"""A long program compensated in two parts, one process each (`--jobs 2`).

This process compensates the lines before a cut.  A second process (a fork of this
one where that is safe, `_may_fork`; else a new interpreter) reads the whole program
too: it reads the lines before the cut for the state there (in an ISO program, runs of
plain lines it leaves unread, telling their effect: `motion/skim.py`; the others it
interprets, a fifth to a third of the cost of compensating them), compensates a window of lines
before the cut to reach the state the passes and the writer are in there, and
compensates the rest into a spool file.  It tells its state at the cut as it gets
there; where that equals this process's (the interpreter's too, where it left lines
unread), its output is what one run writes from the cut on (chunks end at the same
input lines, `geometry.line_chunks`), and is appended; where it does not (or the second
process failed before), this process goes on from its cut and writes the rest itself,
taking about the time of one process.  The output is that of one run, byte for byte,
either way, wherever the cut is.  An error of the program (`file:line:col: message`) that
the second process finds past its cut, from this process's state there, is reported
here once this part's lines are done (an error among them comes first), without the
second part's lines compensated again.

The cut is where both parts end together, chosen while they run (`share`): the
second process waits at the earliest line the cut may be near and says how fast it
read its lines; this process then splits what is left between them by how far it
has got, and sends the cut.  So that a CPU its host slows down slows both parts
alike, the two processes trade two CPUs while both run (`_TradedCpus`).
"""

from __future__ import annotations

import math
import os
import pickle
import select
import signal
import subprocess
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from typing import TYPE_CHECKING, BinaryIO, Callable

from ncpp.errors import _TEXTS_COUNTED, SHOWN_PER_TEXT, Location, NcppError, Warnings
from ncpp.fileio import count_lines
from ncpp.passes.context import UNDECIDED, CutLine
from ncpp.passes.geometry import LINE_CHUNK
from ncpp.passes.kernels import child_command, child_environment

if TYPE_CHECKING:
    from ncpp.pipeline import Part, Stats

# The first part's share of the lines when the second has not said it waits by the time the
# first nears the floor (it reads slowly, or failed): the second part also reads the first
# part's lines (`motion/skim.py`) and compensates a window before the cut, so it takes less.
FIRST_SHARE = 0.54
SHARES = (0.45, 0.75)  # the first part's share stays within these, measured or not
# The two CPUs of a shared host run at speeds that differ and change (the same pure-Python
# work, run on both at once, took 1.1-1.7x as long on one as on the other, either one):
# the parts trade CPUs this often, each running as long on each, so that they end together.
TRADE_S = 0.25
WINDOW = 2 * LINE_CHUNK  # lines before the cut the second part compensates to find its state
# Lines' worth of work the first part does past its cut: its passes read ahead (a batch of
# arcs, a chunk of lines) before its writer reaches the cut.  Its CPU less the second's,
# measured without it: +0.0 to +0.4 s on the generated 250k lines, +0.5 to +0.6 s on their
# first 40k posted as Sinumerik; counting 4096 lines, -0.4 to +0.3 s and -0.5 to -0.2 s.
READ_PAST = 2 * LINE_CHUNK
MIN_LINES = 4 * WINDOW  # shorter programs stay in one process


@dataclass
class Job:
    """What the second process is asked: the program and how to compensate it."""

    path: str
    file: str
    source: object  # pipeline.ErrorSource
    tolerance: float
    strict: bool
    force: bool
    dialect: str | None
    offsets: object  # WorkOffsets | None
    floor: int  # the earliest cut less WINDOW: where the second process waits for the cut (`_Pacer`)
    spool: str
    started: float  # time.time() when this process started the second


@dataclass
class _Said:
    """A warning kept to be given later (or not: where it was already given)."""

    message: str
    where: Location


@dataclass
class _Repeats:
    """A second part's warnings of one text after the first SHOWN_PER_TEXT: how many, the first
    and the last (the first part counts them, `Warnings.warn_repeats`; it prints none)."""

    message: str
    times: int
    first: Location
    last: Location


class _Kept(Warnings):
    """The second part's warnings from its cut on, kept for the first part to give after its
    own (strict ones raise as usual): of each text the first SHOWN_PER_TEXT, then its repeats
    as one `_Repeats`, so memory stays flat however often a long program warns.  Before the
    cut is decided, the lines before `lowest` (the earliest cut) are the first part's."""

    def __init__(self, strict: bool, cut: CutLine, lowest: int = 0):
        super().__init__(strict)
        self.cut, self.lowest = cut, lowest
        self.said: list[_Said | _Repeats] = []
        self._kept: dict[str, int | _Repeats] = {}  # per text: how many kept, or its repeats

    def say(self, message: str, where: Location) -> None:
        line, cut = where.line, self.cut.line
        if line is None or line < (self.lowest if cut == UNDECIDED else cut):
            return  # the first part's line: it has given that warning
        kept = self._kept.get(message, 0)
        if type(kept) is _Repeats:
            kept.times += 1
            kept.last = where
        elif kept < SHOWN_PER_TEXT:
            if kept or len(self._kept) < _TEXTS_COUNTED:  # (the others are kept each: each is printed)
                self._kept[message] = kept + 1
            self.said.append(_Said(message, where))
        else:
            self._kept[message] = repeats = _Repeats(message, 1, where, where)
            self.said.append(repeats)


def _give(kept: list[_Said | _Repeats], warnings: Warnings) -> None:
    """Give the second part's kept warnings (`_Kept.said`) to `warnings`, in the order they came."""
    for said in kept:
        if type(said) is _Said:
            warnings.warn(said.message, said.where)
        else:
            warnings.warn_repeats(said.message, said.times, said.first, said.last)


class _BeforeCut(Warnings):
    """The first part's warnings: those of lines from its cut on (it reads ahead past the
    cut) are held, the second part gives them (its replies' `said`), unless this part
    writes the rest itself (`Part.continued`): then they are given, in order."""

    def __init__(self, warnings: Warnings, part: "Part"):
        super().__init__(warnings.strict, warnings.stream)
        self.inner, self.part = warnings, part
        self.held: list[_Said] = []

    def say(self, message: str, where: Location) -> None:
        if self.part.continued:
            self.give_held()
        elif where.line is not None and where.line >= self.part.cut.line:
            self.held.append(_Said(message, where))
            return
        self.inner.warn(message, where)

    def give_held(self) -> None:
        for said in self.held:
            self.inner.warn(said.message, said.where)
        self.held.clear()


def lines_for(path: str) -> int | None:
    """The program's line count, or None when it is too short to pay for a second process."""
    lines = count_lines(path)
    return lines if lines >= MIN_LINES else None


def share(lines: int, done: int, ratio: float, floor: int) -> float:
    """The first part's share of `lines` with which both parts end together, decided when
    the second process waits at line `floor` and this process has compensated `done` lines.

    Both parts compensate at one pace, c; the second reads the lines between its floor
    and its window `ratio` times as fast as it would compensate them (c over its reading
    pace: it interprets them, or leaves plain ones unread, `motion/skim.py`).  From now on
    the first part takes x·N − done + READ_PAST lines' work, the second
    (x·N − W − floor)·ratio + (1 − x)·N + W."""
    x = (done - READ_PAST + lines + WINDOW - ratio * (WINDOW + floor)) / (lines * (2 - ratio))
    return min(max(x, SHARES[0]), SHARES[1])


def _rounded(lines: int, x: float) -> int:
    return max(round(x * lines / LINE_CHUNK), 1) * LINE_CHUNK


def process_in_two_parts(
    stream: BinaryIO,
    path: str,
    out: BinaryIO,
    lines: int,
    *,
    file: str,
    source,
    tolerance: float,
    strict: bool,
    force: bool,
    warnings: Warnings,
    progress: Callable[[int], None] | None,
    dialect: str | None,
    offsets,
) -> "Stats":
    """`pipeline.process` of the program `stream` (unread; the file at `path`, `lines` long)
    in two parts (the first part reads `stream`; `progress` is told the program's lines
    done, `_Pacer`)."""
    from ncpp.pipeline import Part, Stats, process

    options = dict(file=file, source=source, tolerance=tolerance, strict=strict, force=force, dialect=dialect, offsets=offsets)
    lowest = math.ceil(SHARES[0] * lines / LINE_CHUNK) * LINE_CHUNK  # no cut comes earlier
    with tempfile.TemporaryDirectory(prefix="ncpp-part-") as folder:
        spool = os.path.join(folder, "second.nc")
        cut = CutLine(UNDECIDED)  # decided while the parts run (`_Pacer`)
        job = Job(path, file, source, tolerance, strict, force, dialect, offsets, lowest - WINDOW, spool, time.time())
        second = _start(job)
        trading = _TradedCpus(second.pid)
        try:
            first = Part(cut)
            first.decide = decision = _Decision(first, second)
            mine = _BeforeCut(warnings, first)
            stats = process(stream, out, warnings=mine, progress=_Pacer(second, job, lines, first, progress), part=first, **options)  # type: ignore[arg-type]
            trading.stop()  # this part is done: the second runs where the scheduler puts it
            if first.reached is None or first.continued:  # the program ended before the cut, or this part wrote it all
                mine.give_held()
                return stats
            reply = _reply(second)
            if reply is not None:
                with open(spool, "rb") as rest:  # (as the first part's writer would have: `WriterState.append`)
                    first.reached[1].append(decision.taken[1], rest, out)  # type: ignore[index]
                if "error" in reply:  # the program's error past the cut (this part's lines had none): the run stops there
                    _give(reply["said"], warnings)
                    raise reply["error"]
                later = reply
            else:  # the second process failed after its cut: the rest from this part's own state
                later = _rest_here(path, out, cut, first.reached, strict, options)
        finally:
            trading.stop()
            if second.poll() is None:
                second.kill()
            second.wait()
    _give(later["said"], warnings)
    return Stats(later["lines_in"], stats.lines_out + later["lines_out"])


class _TradedCpus:
    """While both parts run on a machine that gives this process two CPUs (`cpus`: those
    two, for a test), the two processes swap them every TRADE_S, from a thread of this
    one; with more CPUs, or where affinities cannot be set, the scheduler's choice stands."""

    def __init__(self, second: int, cpus: list[int] | None = None):
        self.cpus = cpus if cpus is not None else _allowed_cpus()
        # the tasks pinned: this thread (the one that compensates, in a host application
        # not always the main one), and the second process's main thread
        self.tasks = (threading.get_native_id(), second)
        self.done = threading.Event()
        self.thread: threading.Thread | None = None
        if len(self.cpus) == 2:
            thread = threading.Thread(target=self._trade, name="ncpp-trade-cpus", daemon=True)
            try:
                thread.start()
            except RuntimeError:  # no thread to be had: the scheduler's choice stands
                return
            self.thread = thread

    def _trade(self) -> None:
        turn = 0
        while True:
            try:
                os.sched_setaffinity(self.tasks[0], {self.cpus[turn]})
                os.sched_setaffinity(self.tasks[1], {self.cpus[1 - turn]})
            except OSError:  # the second process has gone, or this host refuses
                break
            turn = 1 - turn
            if self.done.wait(TRADE_S):
                break
        for task in self.tasks:  # both free again (a process that has gone is no matter)
            try:
                os.sched_setaffinity(task, self.cpus)
            except OSError:
                pass

    def stop(self) -> None:
        """Stop trading, both processes free to run on either CPU (again and again: no matter)."""
        if self.thread is not None:
            self.done.set()
            self.thread.join()


def _allowed_cpus() -> list[int]:
    """The CPUs this thread may run on (none where affinities are not to be had)."""
    try:
        return sorted(os.sched_getaffinity(0)) if hasattr(os, "sched_setaffinity") else []
    except OSError:
        return []


class _Pacer:
    """This process's progress callback (every 1000 input lines read) while the cut is
    undecided: once the second process reports that it waits at its floor (and how fast
    it read its lines there), or this process's reading nears that floor, it decides the
    cut from the lines this process has compensated by then (`share`) and sends it.

    The caller's callback is told the program's lines done: the lines read, and once the
    cut is decided, as many of the program's as this part's are of its own (the parts end
    together), so that a progress bar reaches the end with the run, not halfway."""

    def __init__(self, child: "subprocess.Popen | _Forked", job: Job, lines: int, part: Part, progress: Callable[[int], None] | None):
        self.child, self.job, self.lines, self.part, self.progress = child, job, lines, part, progress
        self.report: object = _PENDING  # the second's pace (lines read a second), None if it ended without

    def __call__(self, read: int) -> None:
        cut = self.part.cut
        if self.progress is not None:  # (past the cut, where this part writes the rest itself, its own lines)
            self.progress(read if cut.line == UNDECIDED or self.part.continued else min(read * self.lines // cut.line, self.lines))
        if cut.line != UNDECIDED:
            return
        if self.report is _PENDING:
            self.report = _pace_report(self.child)
        # the second waits; its share is decided once this part has written a chunk (its own
        # start is behind it: from then on both parts compensate at one pace)
        done = self.part.written  # (the writer takes a chunk of LINE_CHUNK lines at a time)
        reported = isinstance(self.report, float)
        if not (reported and done > 0) and read + LINE_CHUNK < self.job.floor:
            return
        x = FIRST_SHARE  # the second is not waiting yet, though this part nears its floor (or it failed)
        if reported and done > 0:
            compensating = done / max(time.time() - self.job.started, 1e-3)
            x = share(self.lines, done, compensating / self.report, self.job.floor)
        # after every line read so far (their events may be on their way to the writer)
        cut.line = max(_rounded(self.lines, x), self.job.floor + WINDOW, (read // LINE_CHUNK + 2) * LINE_CHUNK)
        _send(self.child, cut.line)


_PENDING = object()  # no report yet


def _pace_report(child: "subprocess.Popen | _Forked") -> float | None | object:
    """The second process's pace (lines read a second before its floor) once it has sent it;
    _PENDING before; None if it ended without (it failed, or it does not report on this platform)."""
    try:
        ready, _, _ = select.select([child.stdout], [], [], 0)
        if not ready:
            return _PENDING
        said = pickle.load(child.stdout)  # type: ignore[arg-type]
    except (OSError, ValueError, EOFError, pickle.UnpicklingError):
        return None
    return float(said[1]) if isinstance(said, tuple) and said[0] == "pace" else None


def _send(child: "subprocess.Popen | _Forked", cut: int) -> None:
    try:
        pickle.dump(cut, child.stdin, protocol=pickle.HIGHEST_PROTOCOL)  # type: ignore[arg-type]
        child.stdin.close()  # type: ignore[union-attr]
    except (OSError, ValueError):  # the second process ended: this one does the rest (`_reply`)
        pass


def _rest_here(path: str, out: BinaryIO, cut: CutLine, reached: tuple, strict: bool, options: dict) -> dict:
    """The second part, compensated in this process from the first part's state."""
    from ncpp.pipeline import Part, process

    kept = _Kept(strict, cut)
    with open(path, "rb") as stream:
        stats = process(stream, out, warnings=kept, part=Part(cut, resume=reached, second=True), **options)
    return {"lines_in": stats.lines_in, "lines_out": stats.lines_out, "said": kept.said}


def _same(first: "Part", reply: dict) -> bool:
    """Whether the second part wrote the rest as the first would have: its state at the cut
    (apply_error_map.PassState, iso.WriterState) is the first's, and so is its interpreter's
    where it left lines unread (`motion/skim.py`; else it read what the first read)."""
    if first.reached != reply["reached"] or first.reached[0] is None:  # (None: the second's window did not move)
        return False
    return not reply["skipped"] or (first.interpreted is not None and first.interpreted == reply["interpreted"])


# -- the second process ---------------------------------------------------------------
def _start(job: Job) -> "subprocess.Popen | _Forked":
    """The second process, started at once: it works while this one compensates.  A fork
    of this process where that is safe (`_may_fork`): it has the imports and the machine
    already (a new interpreter spends 1.6G instructions on them); else a new interpreter."""
    if _may_fork():
        try:
            return _Forked(job)
        except OSError:  # no fork now (a process limit): a new interpreter may still start
            pass
    child = subprocess.Popen(
        child_command("from ncpp.parts import _serve; _serve()"),
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=child_environment(),
    )  # fmt: skip
    pickle.dump(job, child.stdin, protocol=pickle.HIGHEST_PROTOCOL)  # type: ignore[arg-type]
    child.stdin.flush()  # type: ignore[union-attr]
    return child


# s: how long a fork waits for a thread that Python has joined but the kernel still lists
# (1% of joins here; a trading thread of the run before, `_TradedCpus`), and between looks
EXITING_WAIT, EXITING_LOOK = 0.01, 0.0002


def _may_fork() -> bool:
    """Whether a fork is safe: on Linux, with this process's one thread (no other thread's
    lock, a BLAS pool's or a host application's, is copied held into the child)."""
    if not sys.platform.startswith("linux"):
        return False
    deadline = time.monotonic() + EXITING_WAIT
    try:
        while len(os.listdir("/proc/self/task")) > 1:
            # a thread Python runs, or one not Python's that outlives the wait, is there to stay
            if threading.active_count() > 1 or time.monotonic() > deadline:
                return False
            time.sleep(EXITING_LOOK)
    except OSError:
        return False
    return True


class _Forked:
    """The second process as a fork of this one, driven like a `subprocess.Popen`: the
    cut goes to its `stdin`, its pace and reply come from its `stdout` (pipes)."""

    def __init__(self, job: Job):
        cut_read, cut_write = os.pipe()
        reply_read, reply_write = os.pipe()
        try:
            self.pid = os.fork()
        except OSError:
            for fd in (cut_read, cut_write, reply_read, reply_write):
                os.close(fd)
            raise
        if self.pid == 0:  # the child: it never returns, nor flushes or cleans up what it shares with this process
            code = 1
            try:
                os.close(cut_write)
                os.close(reply_read)
                os.dup2(2, 1)  # a stray write must not reach the output, nor hold its pipe open
                with os.fdopen(cut_read, "rb") as requests, os.fdopen(reply_write, "wb") as replies:
                    _serve_job(job, requests, replies)
                code = 0
            finally:
                os._exit(code)
        os.close(cut_read)
        os.close(reply_write)
        self.stdin, self.stdout = os.fdopen(cut_write, "wb"), os.fdopen(reply_read, "rb")
        self.returncode: int | None = None

    def poll(self) -> int | None:
        if self.returncode is None:
            pid, status = os.waitpid(self.pid, os.WNOHANG)
            if pid:
                self.returncode = os.waitstatus_to_exitcode(status)
        return self.returncode

    def kill(self) -> None:
        if self.poll() is None:
            os.kill(self.pid, signal.SIGKILL)

    def wait(self) -> int:
        if self.returncode is None:
            self.returncode = os.waitstatus_to_exitcode(os.waitpid(self.pid, 0)[1])
        for pipe in (self.stdin, self.stdout):
            pipe.close()
        return self.returncode


class _Decision:
    """The first part's `decide`, at its cut: whether the second's state there (its report,
    waited for) is the first's, so that its output is taken (`taken`: that state).  If
    not, or the second failed before, it is stopped, and the first part writes the rest."""

    def __init__(self, first: "Part", child: "subprocess.Popen | _Forked"):
        self.first, self.child = first, child
        self.taken: tuple | None = None

    def __call__(self) -> bool:
        report = _report(self.child, "reached")
        if report is not None and _same(self.first, report):
            self.taken = report["reached"]
            return True
        self.child.kill()
        return False


def _report(child: "subprocess.Popen | _Forked", kind: str) -> dict | None:
    """The second process's next report of `kind` (the reports before it passed over), or
    None if it ended without."""
    try:
        while True:
            said = pickle.load(child.stdout)  # type: ignore[arg-type]
            if isinstance(said, tuple) and said[0] == kind:
                return said[1]
    except (EOFError, OSError, pickle.UnpicklingError):
        return None


def _reply(child: "subprocess.Popen | _Forked") -> dict | None:
    """What the second process did after its cut: its lines and warnings, or the program's
    error it stopped at ("error") and the warnings before it (None: it failed; this process
    does its part then)."""
    return _report(child, "done")


def _serve() -> None:
    """The second process in a new interpreter: the job comes as a pickle on stdin."""
    requests, replies = sys.stdin.buffer, sys.stdout.buffer
    sys.stdout = sys.stderr  # a stray print must not corrupt the reply
    _serve_job(pickle.load(requests), requests, replies)


def _serve_job(job: Job, requests: BinaryIO, replies: BinaryIO) -> None:
    """The second process: the second part into the spool, telling its state at the cut
    as it gets there, then its stats and warnings (None if anything failed, or it never
    got to its cut: the first process does the part then).  `requests`: where the cut
    comes from; `replies`: where the pace and the reports go."""
    from ncpp.pipeline import Part

    try:
        cut = CutLine(UNDECIDED)  # decided at `job.floor` (`ask`)
        kept = _Kept(job.strict, cut, lowest=job.floor + WINDOW)
        begun = time.time()

        def ask() -> int:
            """At `job.floor` with no cut yet: how fast this process reads its lines, then the cut."""
            pace = job.floor / max(time.time() - begun, 1e-3)
            pickle.dump(("pace", pace), replies, protocol=pickle.HIGHEST_PROTOCOL)
            replies.flush()
            return int(pickle.load(requests))

        def tell() -> None:
            """At the cut: this part's state there, which the first part compares with its own (`_Decision`)."""
            pickle.dump(("reached", {"reached": part.reached, "interpreted": part.interpreted, "skipped": part.skipped}),
                        replies, protocol=pickle.HIGHEST_PROTOCOL)  # fmt: skip
            replies.flush()

        part = Part(cut, second=True, window=WINDOW, floor=job.floor, ask=ask, tell=tell)
        reply = _second_part(job, part, kept)
    except Exception:  # noqa: BLE001 - an error is the first process's to report, when it gets there itself
        reply = None
    pickle.dump(("done", reply), replies, protocol=pickle.HIGHEST_PROTOCOL)
    replies.flush()


def _second_part(job: Job, part: "Part", kept: _Kept) -> dict | None:
    """The second part compensated into the spool (closed before the reply is sent): its
    stats and warnings, or the program's error past the cut; None if it never got to its cut."""
    from ncpp.pipeline import process

    with open(job.path, "rb") as stream, open(job.spool, "wb") as spool:
        try:
            stats = process(stream, spool, file=job.file, source=job.source, tolerance=job.tolerance, strict=job.strict,  # type: ignore[arg-type]
                            force=job.force, warnings=kept, dialect=job.dialect, offsets=job.offsets, part=part)  # fmt: skip
        except NcppError as error:  # the program's, past the cut, met from the first part's state: the first reports it
            if part.reached is None or error.where.line is None or error.where.line < part.cut.line:
                raise
            return {"error": error, "said": kept.said}
    if part.reached is None:
        return None
    return {"lines_in": stats.lines_in + part.skipped, "lines_out": stats.lines_out, "said": kept.said}
