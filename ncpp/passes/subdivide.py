"""Pass: split feed lines along which the error does not vary linearly (thesis 6.2).

Compensating only a line's end points corrects the path between them by the
straight interpolation of the end-point errors.  Where the error varies more
than that along the line (a bow, a kink in an error table), the line is split
into pieces short enough that the remaining deviation is below the tolerance.
"""

from __future__ import annotations

from typing import Iterable, Iterator

import numpy as np

from ncpp.motion.segments import Event, Line
from ncpp.passes.context import PassContext, deviation
from ncpp.passes.geometry import chunked, frames, points, rows_of, spliced

# Interior samples where linearity is checked.
SAMPLES = np.linspace(0.0, 1.0, 7)
# Sampling misses the worst point between samples; a piecewise-linear error
# table can also kink anywhere: aim below the tolerance by this factor.
SAFETY = 4.0
MAX_PIECES = 10_000


def subdivide_lines(events: Iterable[Event], ctx: PassContext) -> Iterator[Event]:
    for chunk in chunked(events):
        yield from _subdivide_chunk(chunk, ctx)


def _subdivide_chunk(chunk: list[Event], ctx: PassContext) -> list[Event]:
    index = [k for k, e in enumerate(chunk) if type(e) is Line and not e.rapid and not e.changed]
    if not index:
        return chunk
    lines = [chunk[k] for k in index]
    starts = points([ln.start for ln in lines])
    ends = points([ln.end for ln in lines])
    offsets, scales, tools = frames(lines)
    long = np.flatnonzero(np.linalg.norm(ends - starts, axis=1) * scales >= ctx.min_line_check)
    if long.size == 0:
        return chunk
    index, lines = [index[i] for i in long.tolist()], [lines[i] for i in long.tolist()]
    starts, ends, offsets, scales, tools = starts[long], ends[long], offsets[long], scales[long], rows_of(tools, long)
    t = SAMPLES[None, :, None]
    program = starts[:, None, :] + t * (ends - starts)[:, None, :]
    machine = (program + offsets[:, None, :]) * scales[:, None, None]
    direction = np.broadcast_to(np.sign(ends - starts)[:, None, :], machine.shape).reshape(-1, 3)
    tool = None if tools is None else np.broadcast_to(tools[:, None, :], machine.shape).reshape(-1, 3)
    error = deviation(ctx.model, machine.reshape(-1, 3), direction, tool).reshape(machine.shape)
    straight = error[:, :1] + t * (error[:, -1:] - error[:, :1])
    bow = np.linalg.norm(error - straight, axis=-1).max(axis=1)
    # The deviation of piecewise-linear interpolation shrinks with the square of the piece count.
    pieces = np.ceil(np.sqrt(SAFETY * bow / ctx.tolerance)).astype(int).clip(1, MAX_PIECES)
    split = np.flatnonzero(pieces > 1).tolist()
    return spliced(chunk, [index[i] for i in split], [_split(lines[i], int(pieces[i])) for i in split])


def _split(line: Line, n: int) -> list[Line]:
    a, b = np.array(line.start), np.array(line.end)
    cuts = [tuple(a + (b - a) * (i / n)) for i in range(n + 1)]
    cuts[0], cuts[-1] = line.start, line.end
    return [Line(cuts[i], cuts[i + 1], line.rapid, line.feed, line.block, line.context, line.extra, line.changed) for i in range(n)]
