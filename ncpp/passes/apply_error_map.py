"""Pass: move every line's end point to the command that lands the tool on it.

For the wanted point P the command is C with C + E(C) = P (`inverse.py`).
Rapid moves are compensated too, so that positions stay consistent in
incremental (G91) programs.  Arcs arrive here already replaced by
`replace_arcs`; they only move the current position.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Iterable, Iterator

import numpy as np

from ncpp.motion.segments import Arc, Event, Line
from ncpp.passes.context import PassContext
from ncpp.passes.geometry import chunked, compensate, frames


def apply_error_map(events: Iterable[Event], ctx: PassContext) -> Iterator[Event]:
    last = None  # the last segment written: its compensated end, in its own program frame
    for chunk in chunked(events):
        index = [k for k, e in enumerate(chunk) if type(e) is Line and not e.changed]
        new_ends: dict[int, tuple] = {}
        new_starts: dict[int, tuple] = {}
        if index:
            lines = [chunk[k] for k in index]
            offsets, scales = frames(lines)
            starts, ends = np.array([ln.start for ln in lines]), np.array([ln.end for ln in lines])
            direction = np.sign(ends - starts)
            new_ends = {k: tuple(map(float, p)) for k, p in zip(index, compensate(ends, offsets, scales, lines, ctx, direction))}
            if ctx.directional:  # where this line must start, approached its own way
                starts = compensate(starts, offsets, scales, lines, ctx, direction)
                new_starts = {k: tuple(map(float, p)) for k, p in zip(index, starts)}
        for k, event in enumerate(chunk):
            if type(event) is not Line and type(event) is not Arc:
                yield event
                continue
            previous_end = _end_in_frame_of(last, event)
            if k in new_ends:
                start = event.start if previous_end is None else previous_end
                if k in new_starts and previous_end is not None and not event.rapid and _apart(previous_end, new_starts[k]):
                    yield replace(event, start=previous_end, end=new_starts[k], changed=True)
                    start = new_starts[k]
                event = replace(event, start=start, end=new_ends[k], changed=True)
            elif event.changed and previous_end is not None and _apart(previous_end, event.start):
                # a reversal step between compensated pieces: move there first
                yield Line(previous_end, event.start, False, event.feed, event.block, event.context, event.extra, changed=True)
            last = event
            yield event


def _end_in_frame_of(last: Line | Arc | None, event: Line | Arc) -> tuple | None:
    """The last segment's end in `event`'s program frame: units (G20/G21) and
    offsets (G92, G54.., tool length) may have changed between them."""
    if last is None:
        return None
    a, b = last.context, event.context
    if a.inch == b.inch and a.offset == b.offset:
        return last.end
    return b.to_program(a.to_machine(last.end))


def _apart(a: tuple, b: tuple, tolerance: float = 1e-7) -> bool:
    return abs(a[0] - b[0]) > tolerance or abs(a[1] - b[1]) > tolerance or abs(a[2] - b[2]) > tolerance
