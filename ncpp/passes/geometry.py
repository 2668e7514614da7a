"""Vectorised helpers shared by the passes: chunking a stream, converting
program points to machine positions and back, compensating many at once."""

from __future__ import annotations

from bisect import bisect_left
from collections.abc import Iterable, Iterator, Sequence
from itertools import chain, islice
from operator import attrgetter
from typing import TypeVar

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import Location, NcppError
from ncpp.motion.segments import PLANE_AXES, Arc, Context, Event, Line
from ncpp.passes.context import PassContext
from ncpp.passes.inverse import command_for

T = TypeVar("T")

_NO_TOOL = (0.0, 0.0, 0.0)
# Events per vectorised batch: large enough to amortise numpy's per-call cost,
# small enough that memory stays flat however long the program.
CHUNK = 2048


# A pass that settles a chunk as a whole (apply_error_map's directional solve) takes chunks
# of whole windows of this many input lines, at most LINE_CHUNK_CAP events.
LINE_CHUNK = 1024
LINE_CHUNK_CAP = 4096
_line_of = attrgetter("block.line")


def chunked(items: Iterable[T], size: int = CHUNK) -> Iterator[list[T]]:
    """Lists of `size` items, the last shorter.  Where reading them raises an NcppError (an
    earlier stage refused a line), the items read before it are handed on first."""
    it = iter(items)
    while True:
        chunk: list[T] = []
        try:
            chunk += islice(it, size)  # (what it appended before the error stays)
        except NcppError:
            if chunk:
                yield chunk
            raise
        if not chunk:
            return
        yield chunk


def line_chunks(
    events: Iterable[Event], lines: int = LINE_CHUNK, size: int = LINE_CHUNK_CAP
) -> Iterator[list[Event]]:
    """Lists of the events of one window of `lines` input lines each (windows start at
    multiples of `lines`), cut short at `size` events.  Where a chunk ends depends on
    the program, not on where the stream started: compensating a program from a later
    line on (with the state there) settles the same chunks the same way.  Where reading
    the events raises an NcppError, the events read before it are handed on first."""
    it = iter(events)
    chunk: list[Event] = []
    while True:
        try:
            chunk += islice(it, size - len(chunk))
        except NcppError:
            yield from _windows(chunk, lines)
            raise
        if not chunk:
            return
        k = _window_end(chunk, lines)
        yield chunk[:k]
        chunk = chunk[k:]


def _windows(events: list[Event], lines: int) -> Iterator[list[Event]]:
    """All of `events` (in line order), a window of `lines` input lines at a time."""
    while events:
        k = _window_end(events, lines)
        yield events[:k]
        events = events[k:]


def _window_end(chunk: list[Event], lines: int) -> int:
    """How many of the events (in line order) are in the window of `lines` lines of the first (>= 1)."""
    return bisect_left(chunk, (_line_of(chunk[0]) // lines + 1) * lines, key=_line_of)


def before_line(events: list[T], line: int | None) -> list[T]:
    """The events of the lines before `line` (events in line order; None: none)."""
    return [] if line is None else events[: bisect_left(events, line, key=_line_of)]


def spliced(items: list[T], at: list[int], replacements: list[list[T]]) -> list[T]:
    """`items` with the item at each index of `at` (ascending) replaced by the
    items of its replacement: whole runs of untouched items are copied at once."""
    if not at:
        return items
    out: list[T] = []
    done = 0
    for k, replacement in zip(at, replacements):
        out += items[done:k]
        out += replacement
        done = k + 1
    out += items[done:]
    return out


def frames(segments: Sequence[Line | Arc]) -> tuple[NDArray, NDArray, NDArray | None]:
    """(n,3) offsets (machine minus program, program units), (n,) mm per unit, and
    (n,3) tool length offsets in mm (None when no segment has one)."""
    every = [s.context for s in segments]
    if every and every.count(every[0]) == len(
        every
    ):  # one context (mostly one object: `count` tries `is` first)
        c = every[0]
        n, scale = len(every), 25.4 if c.inch else 1.0
        tools = None if c.tool == _NO_TOOL else np.tile(np.asarray(c.tool, dtype=float) * scale, (n, 1))
        return np.tile(np.asarray(c.offset, dtype=float), (n, 1)), np.full(n, scale), tools
    # a program has few contexts and consecutive segments share one: look each up once
    known: dict[int, int] = {}
    contexts: list[Context] = []
    rows: list[int] = []
    for s in segments:
        c = s.context
        row = known.get(id(c))
        if row is None:
            row = known[id(c)] = len(contexts)
            contexts.append(c)
        rows.append(row)
    index = np.array(rows, dtype=np.intp)
    offsets = np.array([c.offset for c in contexts], dtype=float).reshape(-1, 3)[index]
    scales = np.array([25.4 if c.inch else 1.0 for c in contexts])[index]
    if all(c.tool == _NO_TOOL for c in contexts):
        return offsets, scales, None
    return (
        offsets,
        scales,
        np.array([c.tool for c in contexts], dtype=float).reshape(-1, 3)[index] * scales[:, None],
    )


def rows_of(tools: NDArray | None, rows) -> NDArray | None:
    """`tools[rows]` of `frames`' tool offsets (None stays None)."""
    return None if tools is None else tools[rows]


def row_max(values: NDArray) -> NDArray:
    """`values.max(axis=-1)` for a short last axis, one column at a time (numpy's reduction
    walks a short last axis a few at a time, several times slower than this)."""
    out = values[..., 0].copy()
    for k in range(1, values.shape[-1]):
        np.maximum(out, values[..., k], out=out)
    return out


def tuples(rows: NDArray) -> list[tuple[float, float, float]]:
    """The (n,3) rows as n (x, y, z) tuples: by columns, so that no list is made per row."""
    return list(zip(*rows.T.tolist()))


def any3(flags: NDArray) -> NDArray:
    """Whether any of the three along the last axis is true: `flags.any(axis=-1)`, which
    numpy walks three at a time, several times slower than these three operations)."""
    return flags[..., 0] | flags[..., 1] | flags[..., 2]


def all3(flags: NDArray) -> NDArray:
    """Whether all three along the last axis are true (`any3`'s counterpart)."""
    return flags[..., 0] & flags[..., 1] & flags[..., 2]


def points(coordinates: Sequence[tuple[float, float, float]]) -> NDArray:
    """(n,3) array of n (x, y, z) tuples (twice as fast as np.array on the list)."""
    return np.fromiter(chain.from_iterable(coordinates), dtype=float, count=3 * len(coordinates)).reshape(
        -1, 3
    )


# PLANE_AXES as an array indexed by the plane's G code
_PLANE_AXES = np.zeros((max(PLANE_AXES) + 1, 3), dtype=np.intp)
_PLANE_AXES[list(PLANE_AXES)] = list(PLANE_AXES.values())


def plane_axes(arcs: Sequence[Arc]) -> NDArray:
    """(n,3) the u, v and normal axis of each arc's plane (`PLANE_AXES`)."""
    return _PLANE_AXES[np.fromiter((a.context.plane for a in arcs), dtype=np.intp, count=len(arcs))]


def in_plane(q: NDArray, axes: NDArray) -> tuple[NDArray, NDArray, NDArray]:
    """The u, v and normal coordinates of points `q` (p,...,3), each shaped like q[..., 0],
    in each row's plane (`axes` (p,3): its u, v and normal axis, `PLANE_AXES`).
    Three arrays, not one (p,...,2): numpy reduces over a last axis of two slowly."""
    if len(axes) and (axes == axes[0]).all():  # one plane (almost every chunk): slices
        a, b, c = axes[0].tolist()
        return q[..., a], q[..., b], q[..., c]
    index = axes.reshape(len(axes), *([1] * (q.ndim - 2)), 3)
    local = np.take_along_axis(q, np.broadcast_to(index, q.shape), axis=-1)
    return local[..., 0], local[..., 1], local[..., 2]


def from_plane(u: NDArray, v: NDArray, w: NDArray, axes: NDArray) -> NDArray:
    """Points (p,...,3) from their coordinates in each row's plane (`in_plane`'s inverse)."""
    out = np.empty((*u.shape, 3))
    if len(axes) and (axes == axes[0]).all():
        a, b, c = axes[0].tolist()
        out[..., a], out[..., b], out[..., c] = u, v, w
        return out
    local = np.stack([u, v, w], axis=-1)
    index = axes.reshape(len(axes), *([1] * (u.ndim - 1)), 3)
    np.put_along_axis(out, np.broadcast_to(index, local.shape), local, axis=-1)
    return out


def compensate(
    points: NDArray,
    offsets: NDArray,
    scales: NDArray,
    lines: NDArray,
    ctx: PassContext,
    directions: NDArray | None = None,
    tools: NDArray | None = None,
    ends: NDArray | None = None,
) -> NDArray:
    """Compensated program points for wanted program points.

    points (n,m,3) or (n,3): point(s) of segment k in its program frame;
    offsets (n,3), scales (n,); lines (n,): the line of segment k's block (numbers,
    not events); directions: travel signs shaped
    like points, for direction-dependent (reversal) error tables; tools (n,3): the tool length
    offsets in effect, mm (`frames`; None: none).  Refuses corrections
    beyond the machine's limit and commands outside its travel, naming the line; with
    `ends` ((n,3) bools, set here), a point inside the travel whose command the correction
    puts outside it (a move to a travel end) is commanded at the travel's end instead, and
    `ends` marks the axis."""
    shape = points.shape
    pts = points.reshape(len(lines), -1, 3)
    wanted = (pts + offsets[:, None, :]) * scales[:, None, None]
    signs = None if directions is None else np.asarray(directions, dtype=float).reshape(-1, 3)
    tool = None if tools is None else np.broadcast_to(tools[:, None, :], wanted.shape).reshape(-1, 3)
    command = command_for(ctx.model, wanted.reshape(-1, 3), signs, tool, ctx.iterations).reshape(wanted.shape)
    if ends is not None:
        ends |= _at_travel_ends(wanted, command, ctx).any(axis=1)
    _check(wanted, command, lines, ctx)
    return (command / scales[:, None, None] - offsets[:, None, :]).reshape(shape)


def _at_travel_ends(wanted: NDArray, command: NDArray, ctx: PassContext) -> NDArray:
    """(n,m,3) where a command is outside the travel at a wanted point inside it: the command is
    set to the travel's end there (the machine can go no further; the tool stops short of the
    point by the correction's overshoot)."""
    lo, hi = ctx.limit_arrays()
    inside = (wanted >= lo - _AT_END) & (wanted <= hi + _AT_END)
    held = inside & ((command < lo) | (command > hi))
    if held.any():
        np.copyto(command, np.clip(command, lo, hi), where=held)
    return held


_AT_END = 1e-9  # mm: a wanted point this close outside a travel end is at it (its number's rounding)


def _number(value: float) -> str:
    """A position as a message gives it: to 0.1 µm, or in powers of ten past any travel."""
    return f"{value:.4f}" if abs(value) < 1e9 else f"{value:.4g}"


def _check(wanted: NDArray, command: NDArray, lines: NDArray, ctx: PassContext) -> None:
    lo, hi = ctx.limit_arrays()
    flat = command.reshape(-1, 3)
    if not len(flat):
        return
    # the common case in a few reductions: every command inside the travel (axis by axis: numpy's
    # min(axis=0) over (n,3) walks three at a time, far slower) and the largest correction within
    # the limit (NaN fails each test: the full checks below find it); the largest is noted for the verifier
    inside = all(flat[:, k].min() >= lo[k] and flat[:, k].max() <= hi[k] for k in range(3))
    off = (command - wanted).reshape(-1, 3)
    largest = float(np.sqrt(np.einsum("nk,nk->n", off, off).max()))
    if inside and largest <= ctx.max_correction:
        ctx.corrections.note(largest)
        return
    # NaN compares false with every limit: a point or a model that is not a number would pass
    broken = np.flatnonzero(~np.isfinite(command).all(axis=-1).all(axis=-1))
    if broken.size:
        k = int(broken[0])
        what = "the program point" if not np.isfinite(wanted[k]).all() else "the machine model's correction"
        raise NcppError(
            f"{what} is not a finite number: nothing to command", Location(ctx.file, int(lines[k]))
        )
    correction = np.linalg.norm(command - wanted, axis=-1).max(axis=-1)
    outside = np.asarray(((command < lo) | (command > hi)).any(axis=-1).any(axis=-1))
    bad = np.flatnonzero((correction > ctx.max_correction) | outside)
    if bad.size:
        k = int(bad[0])
        if not outside[k]:  # (a point outside the travel tells more than the correction it gets there)
            raise NcppError(
                f"correction of {correction[k]:.4f} mm exceeds the machine file's limit of {ctx.max_correction} mm",
                Location(ctx.file, int(lines[k])),
            )
        pts = command[k].reshape(-1, 3)
        axis_index = int(np.flatnonzero(((pts < lo) | (pts > hi)).any(axis=0))[0])
        axis = "XYZ"[axis_index]
        value = pts[:, axis_index][
            (pts[:, axis_index] < lo[axis_index]) | (pts[:, axis_index] > hi[axis_index])
        ][0]
        raise NcppError(
            f"command {axis}{_number(value)} mm is outside the {axis} travel [{lo[axis_index]:g}, {hi[axis_index]:g}] mm",
            Location(ctx.file, int(lines[k]), word=axis),
        )
    ctx.corrections.note(largest)
