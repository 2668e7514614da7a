"""Pass: split feed lines along which the error does not vary linearly (M. Rahman,
*Modeling and measurement of multi-axis machine tools to improve positioning accuracy in a
software way*, University of Oulu, 2004, section 6.2).

Compensating only a line's end points corrects the path between them by the
straight interpolation of the end-point errors.  Where the error varies more
than that along the line (a bow, a kink in an error table), the line is split
into pieces short enough that the remaining deviation is below the tolerance.
The error is sampled a chunk at a time (`PieceCounts`); not along a line that a
bound of the error's curvature already keeps whole (`ncpp.machine.curvature`,
where the map gives one: its `bow_bound`).
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ncpp.machine.chain import norm3
from ncpp.machine.curvature import BowBound, ripple_bow
from ncpp.motion.segments import Event, Line
from ncpp.passes.context import PassContext, deviation
from ncpp.passes.geometry import chunked, frames, points, row_max, rows_of, spliced
from ncpp.passes.rotary import interpolated, turns

# Interior samples where linearity is checked.
SAMPLES = np.linspace(0.0, 1.0, 7)
# Sampling misses the worst point between samples; a piecewise-linear error
# table can also kink anywhere: aim below the tolerance by this factor.
SAFETY = 4.0
MAX_PIECES = 10_000
# A line is kept whole unsampled where SAFETY times its bound of the bow is within this part
# of the tolerance: below it, rounding in the samples could not make them split it
SURE = 0.99


def subdivide_lines(events: Iterable[Event], ctx: PassContext) -> Iterator[Event]:
    count = PieceCounts(ctx)
    bound = getattr(ctx.model, "bow_bound", None)
    for chunk, index, lines, rows in (_with_rows(chunk, ctx, bound) for chunk in chunked(events)):
        if rows is None:
            yield from chunk
            continue
        pieces = count(rows).tolist()
        split = [i for i, n in enumerate(pieces) if n > 1]
        yield from spliced(chunk, [index[i] for i in split], [_split(lines[i], pieces[i]) for i in split])


@dataclass
class _LineRows:
    """A chunk's feed lines of at least `min_line_check` as the kernel needs them (no events)."""

    starts: NDArray  # (n,3) program units
    ends: NDArray  # (n,3)
    offsets: NDArray  # (n,3) machine minus program, program units
    scales: NDArray  # (n,) mm per program unit
    tools: NDArray | None  # (n,3) tool length offsets, mm (None: none)


def _with_rows(
    chunk: list[Event], ctx: PassContext, bound: BowBound | None = None
) -> tuple[list[Event], list[int], list[Line], _LineRows | None]:
    """The chunk, where its lines to check are, those lines, and their rows (None: none)."""
    # (not under cutter compensation: each piece would be a move the control offsets by itself; nor a
    # rigid tap: each piece would be a tap of its own)
    index = [
        k
        for k, e in enumerate(chunk)
        if type(e) is Line
        and not e.rapid
        and not e.changed
        and not e.fixed
        and e.centre_shift is None
        and not e.tap
    ]
    if not index:
        return chunk, [], [], None
    lines = cast(list[Line], [chunk[k] for k in index])
    starts = points([ln.start for ln in lines])
    ends = points([ln.end for ln in lines])
    offsets, scales, tools = frames(lines)
    length = norm3(ends - starts) * scales
    long = np.flatnonzero(length >= ctx.min_line_check)
    if (
        long.size and bound is not None
    ):  # and not kept whole by the bound (the samples would find less bow than it)
        machine = lambda p: (p[long] + offsets[long]) * scales[long, None]  # noqa: E731
        bow = length[long] ** 2 / 8 * bound(machine(starts), machine(ends), rows_of(tools, long))
        long = long[SAFETY * bow > SURE * ctx.tolerance]
    ripple = getattr(ctx.model, "ripple", None)
    if ripple is not None and ripple.any():  # (and any line, however short, a screw-lead error bows)
        rippled = _ripple_pieces(starts, ends, scales, ripple, ctx.tolerance) > 1
        long = np.union1d(long, np.flatnonzero(rippled))
    if long.size == 0:
        return chunk, [], [], None
    keep = long.tolist()
    rows = _LineRows(starts[long], ends[long], offsets[long], scales[long], rows_of(tools, long))
    return chunk, [index[i] for i in keep], [lines[i] for i in keep], rows


class PieceCounts:
    """The numbers of the pass: into how many pieces each line must be split."""

    def __init__(self, ctx: PassContext):
        self.ctx = ctx

    def __call__(self, rows: _LineRows) -> NDArray:
        return _piece_counts(rows, self.ctx)


def _piece_counts(rows: _LineRows, ctx: PassContext) -> NDArray:
    """(n,) pieces per line: the error along it, sampled, bows from the straight
    interpolation of its end errors by less than the tolerance in each piece."""
    starts, ends, offsets, scales, tools = rows.starts, rows.ends, rows.offsets, rows.scales, rows.tools
    t = SAMPLES[None, :, None]
    program = starts[:, None, :] + t * (ends - starts)[:, None, :]
    machine = (program + offsets[:, None, :]) * scales[:, None, None]
    direction = np.broadcast_to(np.sign(ends - starts)[:, None, :], machine.shape).reshape(-1, 3)
    tool = None if tools is None else np.broadcast_to(tools[:, None, :], machine.shape).reshape(-1, 3)
    error = deviation(ctx.model, machine.reshape(-1, 3), direction, tool).reshape(machine.shape)
    straight = error[:, :1] + t * (error[:, -1:] - error[:, :1])
    bow = row_max(norm3(error - straight))
    # The deviation of piecewise-linear interpolation shrinks with the square of the piece count.
    # (capped before the cast: a tolerance of 1e-300 makes the ratio inf, which casts to a negative int)
    pieces = np.ceil(np.sqrt(SAFETY * bow / ctx.tolerance))
    ripple = getattr(ctx.model, "ripple", None)
    if ripple is not None and ripple.any():  # the samples alias an error that repeats between them
        pieces = np.maximum(pieces, _ripple_pieces(starts, ends, scales, ripple, ctx.tolerance))
    return np.minimum(pieces, MAX_PIECES).astype(int).clip(1, None)


def _ripple_pieces(
    starts: NDArray, ends: NDArray, scales: NDArray, ripple: NDArray, tolerance: float
) -> NDArray:
    """(n,) pieces each line needs for the errors that repeat along an axis (`Machine.ripple`): a
    piece spanning ℓ_k mm of axis k bows by at most Σ ripple[k]·ℓ_k²/8 from its chord."""
    bow = ripple_bow((ends - starts) * scales[:, None], ripple)
    return np.minimum(np.ceil(np.sqrt(SAFETY * bow / tolerance)), MAX_PIECES)


def _split(line: Line, n: int) -> list[Event]:
    """The line in `n` equal pieces; each turns its share of the axes beyond X Y Z (A B C, U V W)."""
    a, b = np.array(line.start), np.array(line.end)
    cuts = [tuple(a + (b - a) * (i / n)) for i in range(n + 1)]
    cuts[0], cuts[-1] = line.start, line.end
    if turns(line):
        extras = [line.extra_start] + [
            interpolated(line.extra_start, line.extra, i / n) for i in range(1, n + 1)
        ]
    else:
        extras = [line.extra] * (n + 1)
    return [Line(cuts[i], cuts[i + 1], line.rapid, line.feed, line.block, line.context, extras[i + 1], line.changed,
                 extra_start=extras[i]) for i in range(n)]  # fmt: skip
