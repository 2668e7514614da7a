"""The CL-data postprocessor: APT CL data -> events -> compensation passes -> NC.

    post(stream, out, file="part.cls", dialect="heidenhain", source=ErrorSource...)

The events are the ones the NC interpreter makes (`ncpp.cldata.motion`), run
through the same pass tuple as the filter (`ncpp.pipeline.make_context`), and
written by a generator per dialect that writes whole programs from scratch
(`ncpp.post.iso`, `.heidenhain`, `.sinumerik`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from typing import BinaryIO, TextIO

from ncpp.cldata import Record, motion, read_cldata
from ncpp.errors import NcppError, Warnings
from ncpp.guard import Placement, with_guard
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import Event
from ncpp.passes.context import Corrections
from ncpp.post.generator import Generator
from ncpp.post.heidenhain import HeidenhainGenerator
from ncpp.post.iso import FanucGenerator, IsoGenerator, LinuxCncGenerator
from ncpp.post.sinumerik import SinumerikGenerator
from ncpp.summary import Summary

GENERATORS: dict[str, type[Generator]] = {
    "iso": IsoGenerator,
    "linuxcnc": LinuxCncGenerator,
    "fanuc": FanucGenerator,
    "heidenhain": HeidenhainGenerator,
    "sinumerik": SinumerikGenerator,
}


class _RecordIndex:
    """Remembers the non-motion records by line so the generator can spell them;
    an entry leaves when its event is written, so memory stays bounded."""

    def __init__(self, progress: Callable[[int], None] | None = None):
        self.by_line: dict[int, Record] = {}
        self.progress = progress
        self.count = 0

    def watch(self, records: Iterable[Record]) -> Iterator[Record]:
        for record in records:
            self.count += 1
            if self.progress is not None and self.count % 1000 == 0:
                self.progress(self.count)
            if record.major != "GOTO":
                self.by_line[record.line] = record
            yield record

    def __call__(self, event: Event) -> Record | None:
        return self.by_line.pop(event.block.line, None)


def post(
    stream: TextIO,
    out: BinaryIO,
    *,
    file: str = "<stdin>",
    dialect: str = "iso",
    source=None,
    tolerance: float = 0.001,
    warnings: Warnings | None = None,
    progress: Callable[[int], None] | None = None,
    offsets: WorkOffsets | None = None,
    verify: bool = True,
    summary: Summary | None = None,
    guard: Placement | None = None,
) -> int:
    """Post one CL file as a `dialect` program (compensated when `source` is an
    `ncpp.pipeline.ErrorSource`, the CL origin at `offsets`' G54 zero);
    returns the number of lines written.

    A compensated program is verified before it is written (`ncpp/verify.py`): the CL
    data is posted a second time without compensation, and the compensated program
    must do what that one does (`verify=False` skips it).  `summary` is told what compensation did
    (its lines in are the CL records); a compensated program starts with the placement `guard`
    (`ncpp/guard.py`) when one is given."""
    if source is not None and verify:
        return _verified(stream, out, file=file, dialect=dialect, source=source, tolerance=tolerance,
                         warnings=warnings, progress=progress, offsets=offsets, summary=summary, guard=guard)  # fmt: skip
    return _post(stream, out, file=file, dialect=dialect, source=source, tolerance=tolerance,
                 warnings=warnings, progress=progress, offsets=offsets, summary=summary, guard=guard)  # fmt: skip


def _verified(stream: TextIO, out: BinaryIO, *, file: str, dialect: str, source, tolerance: float, warnings: Warnings | None,
              progress: Callable[[int], None] | None, offsets: WorkOffsets | None, summary: Summary | None,
              guard: Placement | None) -> int:  # fmt: skip
    """Post compensated and uncompensated to temporary files; verify, then copy to `out`."""
    import io
    import shutil
    import tempfile

    from ncpp.pipeline import verify_bound
    from ncpp.verify import verify

    corrections = Corrections()
    with tempfile.TemporaryFile("w+", encoding="latin-1") as cl, tempfile.TemporaryFile() as plain, \
            tempfile.TemporaryFile() as written:  # fmt: skip
        shutil.copyfileobj(stream, cl)
        cl.seek(0)
        count = _post(cl, written, file=file, dialect=dialect, source=source, tolerance=tolerance, warnings=warnings,
                      progress=progress, offsets=offsets, summary=summary, guard=guard, corrections=corrections)  # fmt: skip
        cl.seek(0)
        _post(
            cl,
            plain,
            file=file,
            dialect=dialect,
            source=None,
            warnings=Warnings(stream=io.StringIO()),
            offsets=offsets,
        )
        plain.seek(0)
        written.seek(0)
        nc = "iso" if dialect in ("linuxcnc", "fanuc") else dialect
        verify(plain, written, file=f"{file} (posted uncompensated)", dialect=nc, offsets=offsets,
               bound=verify_bound(source, tolerance, corrections))  # fmt: skip
        written.seek(0)
        shutil.copyfileobj(written, out)
    return count


def _post(
    stream: TextIO,
    out: BinaryIO,
    *,
    file: str,
    dialect: str,
    source=None,
    tolerance: float = 0.001,
    warnings: Warnings | None = None,
    progress: Callable[[int], None] | None = None,
    offsets: WorkOffsets | None = None,
    summary: Summary | None = None,
    guard: Placement | None = None,
    corrections: Corrections | None = None,
) -> int:
    """Post one CL file (`post`); `corrections`: where compensation notes the largest it makes."""
    from ncpp.passes import PASSES, run_passes
    from ncpp.pipeline import HEADER_TAG, header_text, make_context, warn_fixed

    if dialect not in GENERATORS:
        raise NcppError(f"unknown dialect {dialect!r} (known: {', '.join(GENERATORS)})")
    warnings = warnings or Warnings()
    index = _RecordIndex(progress)
    zero = offsets.program_zero() if offsets is not None else (0.0, 0.0, 0.0)
    events: Iterable[Event] = motion(index.watch(read_cldata(stream, file)), warnings, zero)
    header = None
    if source is not None:
        events = warn_fixed(events, warnings, file)  # canned cycles, cutter compensation: as programmed
        summary = summary if summary is not None else Summary(file)
        warnings.listeners.append(summary.heard)
        ctx = make_context(source, tolerance, warnings, file, corrections)
        events = summary.written(run_passes(summary.programmed(events), ctx, PASSES))
        header = header_text(source, tolerance)
    generator = GENERATORS[dialect](warnings, header, file)
    lines: Iterator[str] = (line + "\n" for line in generator.write(events, index))
    if header is not None and guard is not None:
        lines = with_guard(lines, guard, dialect, HEADER_TAG)
    written = 0
    for line in lines:
        out.write(line.encode("latin-1", errors="replace"))
        written += 1
    if summary is not None:
        summary.lines_in, summary.lines_out = index.count, written
    warnings.finish()
    return written


__all__ = ["GENERATORS", "Generator", "post"]
