"""A long program compensated in two parts, one process each (`--jobs 2`).

This process compensates the lines before a cut.  A second process reads the
whole program too: it interprets the lines before the cut (a fifth of the cost
of compensating them), compensates a window of lines before the cut to reach the
state the passes and the writer are in there, and compensates the rest into a
spool file.  Where its state at the cut equals this process's, its output is what
one run writes from the cut on (chunks end at the same input lines,
`geometry.line_chunks`), and is appended; where it does not (or the second
process failed), this process compensates the rest itself from its own state.
The output is that of one run, byte for byte, either way.
"""

from __future__ import annotations

import os
import pickle
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from typing import TYPE_CHECKING, BinaryIO, Callable

from ncpp.errors import Location, NcppError, Warnings
from ncpp.passes.geometry import LINE_CHUNK

if TYPE_CHECKING:
    from ncpp.pipeline import Stats

# The first part's share of the lines: the second part also starts a Python,
# interprets the first part's lines and compensates a window before the cut, so it
# takes less than half (both end together on the generated benchmark program and
# on stellabee1.ngc).
FIRST_SHARE = 0.58
WINDOW = 2 * LINE_CHUNK  # lines before the cut the second part compensates to find its state
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
    cut: int
    spool: str


@dataclass
class _Said:
    """A warning kept to be given later (or not: where it was already given)."""

    message: str
    where: Location


class _Kept(Warnings):
    """Warnings kept instead of printed; strict ones raise as usual."""

    def __init__(self, strict: bool):
        super().__init__(strict)
        self.said: list[_Said] = []

    def warn(self, message: str, where: Location) -> None:
        if self.strict:
            raise NcppError(f"{message} (refused in strict mode)", where)
        self.said.append(_Said(message, where))


def cut_for(path: str) -> int | None:
    """The input line where the second part starts (a multiple of LINE_CHUNK), or None
    when the program is too short to pay for a second process."""
    with open(path, "rb") as f:
        lines = sum(chunk.count(b"\n") for chunk in iter(lambda: f.read(1 << 20), b""))
    if lines < MIN_LINES:
        return None
    return round(FIRST_SHARE * lines / LINE_CHUNK) * LINE_CHUNK


def process_in_two_parts(
    stream: BinaryIO,
    path: str,
    out: BinaryIO,
    cut: int,
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
    """`pipeline.process` of the program `stream` (unread; the file at `path`) in two parts
    split at input line `cut` (the first part reads `stream`: its progress is the file's)."""
    from ncpp.pipeline import Part, Stats, process

    options = dict(file=file, source=source, tolerance=tolerance, strict=strict, force=force, dialect=dialect, offsets=offsets)
    with tempfile.TemporaryDirectory(prefix="ncpp-part-") as folder:
        spool = os.path.join(folder, "second.nc")
        second = _start(Job(path, file, source, tolerance, strict, force, dialect, offsets, cut, spool))
        try:
            first = Part(cut)
            stats = process(stream, out, warnings=warnings, progress=progress, part=first, **options)  # type: ignore[arg-type]
            if first.reached is None:  # the program ended before the cut
                return stats
            reply = _reply(second)
            if reply is not None and _same(first.reached, reply["reached"]):
                with open(spool, "rb") as rest:
                    shutil.copyfileobj(rest, out, 1 << 20)
                later = reply
            else:  # the second part guessed another state: the rest from this part's own
                later = _rest_here(path, out, cut, first.reached, strict, options)
        finally:
            if second.poll() is None:
                second.kill()
            second.wait()
    for said in later["said"]:
        if said.where.line is not None and said.where.line >= cut:  # the first part gave those before
            warnings.warn(said.message, said.where)
    return Stats(later["lines_in"], stats.lines_out + later["lines_out"])


def _rest_here(path: str, out: BinaryIO, cut: int, reached: tuple, strict: bool, options: dict) -> dict:
    """The second part, compensated in this process from the first part's state."""
    from ncpp.pipeline import Part, process

    kept = _Kept(strict)
    with open(path, "rb") as stream:
        stats = process(stream, out, warnings=kept, part=Part(cut, resume=reached, second=True), **options)
    return {"lines_in": stats.lines_in, "lines_out": stats.lines_out, "said": kept.said}


def _same(a: tuple, b: tuple) -> bool:
    """Whether two states at the cut (apply_error_map.PassState, iso.WriterState) write the rest alike."""
    return a == b


# -- the second process ---------------------------------------------------------------
def _start(job: Job) -> subprocess.Popen:
    """The second process, started at once: it works while this one compensates."""
    child = subprocess.Popen(
        [sys.executable, "-c", "from ncpp.parts import _serve; _serve()"],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, env={**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)},
    )  # fmt: skip
    pickle.dump(job, child.stdin, protocol=pickle.HIGHEST_PROTOCOL)  # type: ignore[arg-type]
    child.stdin.close()  # type: ignore[union-attr]
    return child


def _reply(child: subprocess.Popen) -> dict | None:
    """What the second process did (None: it failed; this process does its part then)."""
    try:
        reply = pickle.load(child.stdout)  # type: ignore[arg-type]
    except (EOFError, OSError, pickle.UnpicklingError):
        return None
    return reply if reply.get("reached") is not None else None


def _serve() -> None:
    """The second process: the second part into the spool, then its state at the cut,
    stats and warnings (none if anything failed: the first process does the part then)."""
    from ncpp.pipeline import Part, process

    replies = sys.stdout.buffer
    sys.stdout = sys.stderr  # a stray print must not corrupt the reply
    reply: dict = {"reached": None}
    try:
        job: Job = pickle.load(sys.stdin.buffer)
        kept = _Kept(job.strict)
        part = Part(job.cut, second=True, window=WINDOW)
        with open(job.path, "rb") as stream, open(job.spool, "wb") as spool:
            stats = process(stream, spool, file=job.file, source=job.source, tolerance=job.tolerance, strict=job.strict,  # type: ignore[arg-type]
                            force=job.force, warnings=kept, dialect=job.dialect, offsets=job.offsets, part=part)  # fmt: skip
        reply = {"reached": part.reached, "lines_in": stats.lines_in, "lines_out": stats.lines_out, "said": kept.said}
    except Exception:  # noqa: BLE001 - an error is the first process's to report, when it gets there itself
        reply = {"reached": None}
    pickle.dump(reply, replies, protocol=pickle.HIGHEST_PROTOCOL)
    replies.flush()
