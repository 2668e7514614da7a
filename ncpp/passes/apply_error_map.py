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
    previous_end = None  # compensated end of the last segment, program coordinates
    for chunk in chunked(events):
        index = [k for k, e in enumerate(chunk) if type(e) is Line and not e.changed]
        new_ends: dict[int, tuple] = {}
        if index:
            lines = [chunk[k] for k in index]
            offsets, scales = frames(lines)
            ends = compensate(np.array([ln.end for ln in lines]), offsets, scales, lines, ctx)
            new_ends = {k: tuple(map(float, end)) for k, end in zip(index, ends)}
        for k, event in enumerate(chunk):
            if k in new_ends:
                start = event.start if previous_end is None else previous_end
                event = replace(event, start=start, end=new_ends[k], changed=True)
                previous_end = event.end
            elif type(event) is Line or type(event) is Arc:
                previous_end = event.end
            yield event
