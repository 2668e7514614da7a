"""Pass: move every line's end point to the command that lands the tool on it.

For the wanted point P the command is C with C + E(C) = P (`inverse.py`).
Rapid moves are compensated too, so that positions stay consistent in
incremental (G91) programs.  Arcs arrive here already replaced by
`replace_arcs`; they move the current position and, with reversal errors,
are shifted for the direction their normal axis really travels in.

With direction-dependent (reversal) tables, an axis's direction is the one
the machine will see (`travel.py`): the sign of the compensated motion as
written, or the held direction of an axis that stands.  The command depends
on that direction and the direction on the commands, so a chunk is solved by
a few rounds of fixed-point iteration.  Where an axis reverses, the line's
start is compensated with its own direction and a step move is inserted.

The solve gathers rows of its (n,3) arrays with `take` (and masks them with `compress`):
numpy's indexing by an array of rows is several times slower on a chunk's few hundred rows.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, fields, replace
from itertools import chain
from typing import overload

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import Location, NcppError
from ncpp.motion import cycles
from ncpp.motion.segments import CYCLE, HOLE, PLANE_AXES, Arc, Event, Hole, Line, Pass, Setting, plane_point
from ncpp.passes.context import PassContext, deviation
from ncpp.passes.geometry import (
    any3,
    compensate,
    frames,
    from_plane,
    in_plane,
    line_chunks,
    plane_axes,
    points,
    rows_of,
    tuples,
)
from ncpp.passes.travel import Travel, grid, hold, quantize, steps
from ncpp.program.blocks import Word

# Compensations per line at most: each changes a direction only where a
# correction of the previous round flipped a µm motion; two rounds settle almost all.
ROUNDS = 4
# mm an axis may stay off its compensated position rather than reverse for a
# fraction of a micron (the reversal's jump is several microns)
STILL_MM = 0.00025
# mm: a line moving an axis this far moves it that way whatever its compensation (errors are µm)
NEAR_STILL = 0.05


def apply_error_map(events: Iterable[Event], ctx: PassContext) -> Iterator[Event]:
    # the events a chunk at a time, handed on by `chain` (in C): no generator's step per event
    return chain.from_iterable(_chunks(events, ctx))


def _chunks(events: Iterable[Event], ctx: PassContext) -> Iterator[list[Event]]:
    """The compensated events, a list per chunk."""
    solve = Solve(ctx)
    holes = _Holes(ctx)
    last = None  # the last segment written: its compensated end, in its own program frame
    for chunk, segs, rows in _rowed(_drilled(line_chunks(events), holes, solve), ctx.directional, last):
        if rows is None:  # no segments
            yield _placed(chunk, last)
            continue
        try:
            solved = solve(rows)
        except NcppError as error:
            error.locate(e.block for e in chunk)
            raise
        if solved.at_end.any():
            _warn_at_travel_ends(segs, rows, solved, ctx)
        out = _written(chunk, segs, rows, solved, last)
        # (a carried row's end is not its event's: `_carry`)
        last = holes.last = _ended(segs[-1], solved.end[-1])
        yield out


def _drilled(chunks: Iterable[list[Event]], holes: _Holes, solve: Solve) -> Iterator[list[Event]]:
    """The chunks, each compensated cycle block's moves cut out as a chunk of their own and
    written again from the corrected hole (`_Holes`): from where the output stands then
    (`holes.last`, read when the chunk is taken, after the chunks before it are solved), holding
    `solve`'s directions."""
    for chunk in chunks:
        if not any(type(e) is Line and e.fixed == HOLE for e in chunk):
            yield chunk
            continue
        for piece, drilled in _at_holes(chunk):
            yield piece if drilled is None else holes.drilled(piece, solve.travel.held)


def _at_holes(chunk: list[Event]) -> Iterator[tuple[list[Event], Hole | None]]:
    """The chunk cut before and after the moves of each compensated hole, with that hole
    (None: a piece of other events)."""
    piece: list[Event] = []
    drilled = None
    for event in chunk:
        here = event.hole if type(event) is Line and event.fixed == HOLE else None
        if here is not drilled and piece:
            yield piece, drilled
            piece = []
        drilled = here
        piece.append(event)
    if piece:
        yield piece, drilled


class _Holes:
    """Compensated canned cycles (`Line.hole`): each block's position in the plane and its depth
    corrected at the hole's bottom, its R at the R point above the hole, its moves as the control
    runs them from those words (`cycles.drilled`)."""

    def __init__(self, ctx: PassContext):
        self.ctx = ctx
        self.hole: Hole | None = None  # the last hole written again (its moves may span two chunks)
        # the level (along the normal) the series under way started at, as the control stands there
        self.start_level = 0.0
        self.last: Line | None = None  # the last segment written, with its compensated end (`_chunks` tells)

    def drilled(self, moves: list[Event], held: NDArray) -> list[Event]:
        """The block's moves (`moves`, Lines of one block) from the corrected words, starting
        where the output stands (`last`'s end; None: nothing was compensated, the programmed start)."""
        last = self.last
        first = moves[0]
        assert type(first) is Line and first.hole is not None  # (`_at_holes`)
        if first.hole is self.hole:  # the rest of a hole cut by a chunk's end: written already
            return []
        self.hole = hole = first.hole
        axes = PLANE_AXES[hole.plane]
        at = first.start if last is None else _end_in_frame_of(last, first)
        if hole.series_start:
            self.start_level = at[axes[2]]
        cut, r_point, *under = self._commands(moves, hole, at, held).tolist()
        # (G87: the bottom has a row of its own; Fanuc's G87 starts its cut at R)
        bottom = r_point if hole.fanuc_back else under[0] if under else cut
        command = (cut[axes[0]], cut[axes[1]], bottom[axes[2]], r_point[axes[2]])
        top = None if hole.top is None else cut[axes[2]]
        if not first.context.absolute:
            command, top = self._incremental(first, at, axes, command, top, hole.fanuc_back)
        corrected = replace(hole, command=command, series_level=self.start_level, top_command=top)
        aa, bb, level, r = command
        back = None if top is None else (hole.offset[0], hole.offset[1], top)
        out: list[Event] = []
        start = tuple(at)
        # (not `changed`: that marks the pieces replace_arcs made, which the solve moves; the writer
        # tells a written hole by its `command`)
        here = (at[axes[0]], at[axes[1]], at[axes[2]])
        if hole.fanuc_back and top is not None:
            moves_run = cycles.fanuc_back_bore(here, aa, bb, hole.offset[0], hole.offset[1], r, top,
                                               self.start_level)  # fmt: skip
        else:
            moves_run = cycles.drilled(hole.motion, here, self.start_level, aa, bb, r, level, hole.peck,
                                       hole.rapid_delta, hole.retract_to_r, back)  # fmt: skip
        for move in moves_run:
            end = plane_point(hole.plane, *move[:3])
            out.append(replace(first, start=start, end=end, rapid=move[3], hole=corrected))
            start = end
        return out

    def _incremental(
        self,
        first: Line,
        at: tuple,
        axes: tuple[int, int, int],
        command: tuple,
        top: float | None,
        fanuc_back: bool = False,
    ) -> tuple[tuple[float, float, float, float], float | None]:
        """The command of a hole in G91 on the output's grid as the control adds it up: the plane's
        axes from where it stands, R from the series' start level, the bottom from R, G87's `top`
        from the bottom (rs274ngc's G91 cycle; Fanuc's G87: its top, Z, from R, where its cut starts),
        each a whole number of the last digit written, so that the roundings do not add up along a row
        of holes."""
        step = float(grid(self.ctx, frames([first, first])[1][:1])[0])

        def on_grid(value: float, base: float) -> float:
            return base + round((value - base) / step) * step

        aa, bb, bottom, r = command
        r = on_grid(r, self.start_level)
        bottom = r if fanuc_back else on_grid(bottom, r)
        placed = (on_grid(aa, at[axes[0]]), on_grid(bb, at[axes[1]]), bottom, r)
        return placed, None if top is None else on_grid(top, bottom)

    def _commands(self, moves: list[Event], hole: Hole, at: tuple, held: NDArray) -> NDArray:
        """(2,3) the commands (X Y Z) for the end of the hole's cut (`Hole.cut`) and its R point (one
        position in the plane for both: the cut's), and G87's bottom below it (3,3), the control
        standing at `at`.  With reversal errors, an axis that the corrections alone move on the way
        to the hole (an axis of the plane the program keeps, the normal to an R plane it stands at)
        may go against the direction it holds: by a rounding step or so it stays where it is rather
        than reverse, by more it reverses and is compensated so."""
        first = moves[0]
        levels = [hole.cut, hole.r] + ([] if hole.top is None or hole.fanuc_back else [hole.bottom])
        offsets, scales, tools = frames([first] * len(levels))  # type: ignore[list-item]
        wanted = np.array([hole.point(level) for level in levels])
        lines = np.full(len(levels), first.block.line)
        if not self.ctx.directional:
            return compensate(wanted, offsets, scales, lines, self.ctx, None, tools)
        normal = PLANE_AXES[hole.plane][2]
        reached = _reached(normal)
        in_plane = np.arange(3) != normal
        direction, still = _hole_directions(moves, hole, held)
        command = compensate(wanted, offsets, scales, lines, self.ctx, direction, tools)
        gap = command[reached] - np.array(at)  # the plane's axes over the hole, the normal at R
        against = still & (gap * direction[reached] < 0)
        if not against.any():
            return command
        stay = against & (np.abs(gap) <= _snap_limit(grid(self.ctx, scales[:1]), scales[:1]))
        turn = against & ~stay
        if turn.any():  # (the plane's axes are reached once for both points)
            direction[:, turn & in_plane] *= -1.0
            direction[1, normal] = -direction[1, normal] if turn[normal] else direction[1, normal]
            command = compensate(wanted, offsets, scales, lines, self.ctx, direction, tools)
            # reversed, the command may move the axis the way it held after all (an axis that runs
            # ahead on reversal cannot reach the points between): it stays, the nearest it gets
            stay |= turn & ((command[reached] - np.array(at)) * direction[reached] < 0)
        over = np.where(stay, np.array(at), command[0])  # (the plane's axes: one position for both rows)
        command[:, in_plane] = over[in_plane]
        command[1, normal] = at[normal] if stay[normal] else command[1, normal]
        return command


def _reached(normal: int) -> tuple[NDArray, NDArray]:
    """Where `_Holes._commands`' rows reach the hole first: the plane's axes of the bottom's row,
    the normal (index `normal`) of the R point's."""
    return (np.arange(3) == normal).astype(int), np.arange(3)


def _hole_directions(moves: list[Event], hole: Hole, held: NDArray) -> tuple[NDArray, NDArray]:
    """(2,3) the directions the hole's bottom and its R point are reached in: the plane's axes as
    the rapid to the hole moves them, the normal down to the bottom, and to R as the move that
    reaches it (an axis that stands holds the direction it had); (3,) the axes the program keeps
    still there (the plane's over the hole, the normal at R: `_reached`).  G87 (3,3): its top,
    the normal up, and its bottom, down, both with the plane's axes as the move back from the
    offset moves them (`cycles.back_bore`), an axis the offset leaves as the rapid to the hole."""
    normal = PLANE_AXES[hole.plane][2]
    start = np.array(moves[0].start)  # type: ignore[union-attr]
    if hole.fanuc_back:
        return _fanuc_back_directions(start, hole, held)
    r_point = hole.point(hole.r)
    reach_r = next(m for m in moves if m.end == r_point)  # type: ignore[union-attr]
    toward = np.sign(np.array(r_point) - start)
    toward[normal] = np.sign(hole.r - reach_r.start[normal])  # type: ignore[union-attr]
    still = toward == 0
    toward = np.where(still, held, toward)
    bottom = toward.copy()
    if hole.top is not None:
        back = -np.sign(plane_point(hole.plane, hole.offset[0], hole.offset[1], 0.0))
        bottom = np.where(back != 0, back, bottom)
        still &= back == 0
        top = bottom.copy()
        top[normal], bottom[normal] = 1.0, -1.0
        return np.array([top, toward, bottom]), still
    bottom[normal] = -1.0
    return np.array([bottom, toward]), still


def _fanuc_back_directions(start: NDArray, hole: Hole, held: NDArray) -> tuple[NDArray, NDArray]:
    """`_hole_directions` of Fanuc's G87 (`cycles.fanuc_back_bore`): (2,3) its top, the normal up, and its
    R, the normal down (it comes down at the shift), both with the plane's axes as the move back from
    the shift moves them, an axis the shift leaves as the rapid to the hole; (3,) the axes the program
    keeps still over the hole (neither moves them)."""
    normal = PLANE_AXES[hole.plane][2]
    back = -np.sign(plane_point(hole.plane, hole.offset[0], hole.offset[1], 0.0))
    toward = np.sign(np.array(hole.point(hole.r)) - start)
    across = np.where(back != 0, back, np.where(toward != 0, toward, held))
    still = (back == 0) & (toward == 0)
    still[normal] = False
    top, r_level = across.copy(), across.copy()
    top[normal], r_level[normal] = 1.0, -1.0
    return np.array([top, r_level]), still


def _warn_at_travel_ends(segs: list, rows: _Rows, solved: _Solved, ctx: PassContext) -> None:
    """One warning per line end left at a travel end (`compensate`'s `ends`), at its axis word."""
    machine = (solved.end + rows.offsets) * rows.scales[:, None]
    for k, axis in zip(*np.nonzero(solved.at_end)):
        letter, block = "XYZ"[axis], segs[k].block
        word = next((item for item in block.items if type(item) is Word and item.letter == letter), None)
        ctx.warnings.warn(
            f"{letter} goes to the end of its travel ({machine[k, axis]:g} mm on the machine), where the "
            f"compensated command would be outside the travel: {letter} stops at the end, uncompensated there",
            Location(ctx.file, block.line, 1 if word is None else word.start + 1),
        )


def _rowed(chunks: Iterable[list[Event]], directional: bool, last: Line | Arc | None) -> Iterator[tuple]:
    """Each chunk with its segments and their rows (`_with_rows`); `last`: the segment before
    the first chunk (None: none)."""
    fixed_before = last is None or bool(last.fixed)
    for chunk in chunks:
        rowed = _with_rows(chunk, directional, fixed_before)
        if rowed[1]:
            fixed_before = bool(rowed[1][-1].fixed)
        yield rowed


def _with_rows(chunk: list[Event], directional: bool, fixed_before: bool = True) -> tuple[list[Event], list, _Rows | None]:  # fmt: skip
    """The chunk, its segments, and their rows (None without segments); `fixed_before`:
    whether the segment before the chunk's first was left as programmed (or there is none)."""
    segs = [e for e in chunk if type(e) is Line or type(e) is Arc]
    return chunk, segs, _rows(segs, directional, fixed_before) if segs else None


@dataclass
class _Rows:
    """A chunk's segments (rows) as the solve needs them: arrays, no events."""

    start: NDArray  # (n,3) program units
    end: NDArray  # (n,3)
    offsets: NDArray  # (n,3) machine minus program, program units
    scales: NDArray  # (n,) mm per program unit
    tools: NDArray | None  # (n,3) tool length offsets, mm (None: none)
    free: NDArray  # (n,) lines no pass has changed: their ends are compensated here
    arc: NDArray  # (n,) pieces replace_arcs made (arcs, and lines for slivers)
    pieces: NDArray  # (n,) the lines among them
    assumed: (
        NDArray | None
    )  # (n,3) directions replace_arcs compensated the pieces with (reversal errors only)
    lines: NDArray  # (n,) the line of each segment's block, for messages
    rapid: NDArray  # (n,) rapid moves (G0) and rigid taps: no reversal step before them
    carried: NDArray  # (n,) moves left as programmed that run from where the control is (`_carry`)
    kept: NDArray  # (n,3) their axes that do so (the others the control puts at their programmed end)
    lead_in: NDArray  # (n,) a canned cycle's first move after a compensated one: a step to its start first
    # under cutter compensation: each segment's (`Line.centre_shift`) and the end shifts (n,3) of the lines to
    # compensate (zero elsewhere), the lines that move no axis of the plane (`_pin_plane`), those that
    # turn a corner from a line (`_corners`), and each segment's plane axes (n,3) (`PLANE_AXES`); None: none is
    comp: NDArray | None = None
    shift: NDArray | None = None
    still: NDArray | None = None
    corner: NDArray | None = None
    axes: NDArray | None = None


def _rows_before(rows: _Rows, line: int | None) -> _Rows | None:
    """The rows of the lines before `line` (None: none, or all of them: nothing to solve again)."""
    k = 0 if line is None else int(np.searchsorted(rows.lines, line))
    if k == 0 or k == len(rows.lines):
        return None
    head: dict[str, NDArray | None] = {
        f.name: None if (v := getattr(rows, f.name)) is None else v[:k] for f in fields(_Rows)
    }
    return _Rows(**head)  # type: ignore[arg-type]  # each field as it is in `rows`: None only where it may be


def _rows(segs: list, directional: bool, fixed_before: bool = True) -> _Rows:
    offsets, scales, tools = frames(segs)
    start, end = points([e.start for e in segs]), points([e.end for e in segs])
    # one walk over the events for six flags (1 arc, 2 fixed: a move left as programmed, 4 changed, 8 rapid or tap,
    # 16 carried: fixed in G91, 32 a canned cycle's)
    # (a rigid tap's moves count as rapids there: no reversal step can be written inside its block)
    kind = np.fromiter([(type(e) is Arc) + (0 if not e.fixed else (2 if e.context.absolute else 18) + 32 * (e.fixed == CYCLE))
                        + 4 * bool(e.changed) + 8 * (type(e) is Line and (e.rapid or e.tap > 0)) for e in segs],
                       dtype=np.int8, count=len(segs))  # fmt: skip
    arc, changed = (kind & 1) != 0, (kind & 4) != 0
    line = (kind & 3) == 0
    free = line & ~changed
    kept = _kept_axes(segs, kind)
    # (not after a compensated hole: that is in the cycle's series, whose modal cycle and start level
    # a step there would end)
    fixed = (kind & 2) != 0
    lead_in = ((kind & 32) != 0) & ~np.concatenate([[fixed_before], fixed[:-1]])
    return _Rows(
        start, end, offsets, scales, tools, free, changed, changed & line,
        _arc_assumed(segs, np.flatnonzero(changed & arc), start, end) if directional else None,
        np.fromiter([e.block.line for e in segs], dtype=np.int64, count=len(segs)), (kind & 8) != 0, any3(kept), kept,
        lead_in, *_under_comp(segs, free, start, end),
    )  # fmt: skip


def _under_comp(segs: list, free: NDArray, start: NDArray, end: NDArray) -> tuple[NDArray | None, ...]:
    """`_Rows.comp`, `.shift`, `.still`, `.corner` and `.axes` of the segments (all None: none is under
    compensation).  A line under compensation that moves no axis of the plane (G17: X Y, G18: Z X)
    leaves the tool centre where it stands (`ncpp.motion.cutter.centre_offset`): the same shift at both ends."""
    if all(e.centre_shift is None for e in segs):
        return None, None, None, None, None
    comp = np.fromiter((e.centre_shift is not None for e in segs), dtype=bool, count=len(segs))
    shift = np.zeros((len(segs), 3))
    own = np.flatnonzero(comp & free)
    shift[own] = np.array([segs[k].centre_shift[1] for k in own.tolist()], dtype=float).reshape(-1, 3)
    same = np.zeros(len(segs), dtype=bool)
    same[own] = [segs[k].centre_shift[0] == segs[k].centre_shift[1] for k in own.tolist()]
    axes = plane_axes(segs)
    (su, sv, _), (eu, ev, _) = in_plane(start, axes), in_plane(end, axes)
    moves = (su != eu) | (sv != ev)
    still = same & ~moves
    # a line whose tool centre stands off it by a radius (not the entry move, nor the exit move after G40),
    # after a line under compensation in the same frame
    entry = np.zeros(len(segs), dtype=bool)
    entry[own] = [segs[k].centre_shift[0] is None for k in own.tolist()]
    offset = comp & free & moves & any3(shift != 0) & ~entry
    corner = np.zeros(len(segs), dtype=bool)
    corner[1:] = offset[1:] & (comp & free & moves)[:-1]
    for k in np.flatnonzero(corner).tolist():
        a, b = segs[k - 1].context, segs[k].context
        corner[k] = a.offset == b.offset and a.inch == b.inch and a.plane == b.plane
    return comp, shift, still, corner, axes


# |sin| of the turn between two lines below which their corner is left to the line that ends there
# (the lines' crossing, `_corners`, moves far along them for a small shift across), and the cosine of a
# turn back beyond which it is too
SHALLOW = 0.2
HAIRPIN = -0.9


def _corners(
    rows: _Rows, out_end: NDArray, crossing: Callable[[NDArray], NDArray], step: NDArray | None = None
) -> None:
    """Corners between two lines under cutter compensation: the control offsets each line by the
    radius, and the corner point corrected for the first line's tool centre leaves the second line
    off by the error's gradient times the radius times the turn.  The corner is put where the first
    line's corrected contour crosses the second's: `out_end` of the first, moved along it, its
    coordinate along the plane's normal corrected for the tool centre there, at the crossing (the
    first line's correction changes along it as from its start to its end: linearly).
    `crossing(rows)`: the lines' corrected starts (their own tool centre's correction); `step`
    (n,): the output grid the moved ends are put on (None: none)."""
    if rows.corner is None or rows.axes is None or not rows.corner.any():
        return
    k = np.flatnonzero(rows.corner)
    axes = rows.axes[k]  # (the two lines' plane: `_under_comp`)
    d1 = np.stack(in_plane(rows.end[k - 1] - rows.start[k - 1], axes)[:2], axis=1)
    d2 = np.stack(in_plane(rows.end[k] - rows.start[k], axes)[:2], axis=1)
    d1 /= np.linalg.norm(d1, axis=1)[:, None]
    d2 /= np.linalg.norm(d2, axis=1)[:, None]
    across = d1[:, 1] * d2[:, 0] - d1[:, 0] * d2[:, 1]  # d1 · n2, n2 = d2 turned a quarter
    turn = (np.abs(across) >= SHALLOW) & ((d1 * d2).sum(axis=1) >= HAIRPIN)
    k, d1, d2, across, axes = k[turn], d1[turn], d2[turn], across[turn], axes[turn]
    if k.size == 0:
        return
    gap = np.stack(in_plane(crossing(k) - out_end[k - 1], axes)[:2], axis=1)
    along = (gap[:, 1] * d2[:, 0] - gap[:, 0] * d2[:, 1]) / across  # (gap · n2) / (d1 · n2)
    _depth_at_crossing(rows, out_end, crossing, k, (d1, d2, across, axes))
    out_end[k - 1] += from_plane(along * d1[:, 0], along * d1[:, 1], np.zeros(len(k)), axes)
    if step is not None:
        out_end[k - 1] = quantize(out_end[k - 1], step[k - 1])


def _depth_at_crossing(
    rows: _Rows, out_end: NDArray, crossing: Callable[[NDArray], NDArray], k: NDArray, turns: tuple
) -> None:
    """At an inside corner the control stops the tool centre where the two offset lines cross, `a`
    along the first line from where it stands square to its end (`_Rows.shift`): the corner's
    coordinate along the plane's normal is corrected for the tool centre there, the first line's
    correction changing along it as from its start to its end (`crossing` of its start).  `turns`:
    `_corners`' (d1, d2, across, axes) of the corners `k`."""
    d1, d2, across, axes = turns
    assert rows.shift is not None  # (under compensation: `_corners`)
    first = k - 1
    gap = np.stack(in_plane(rows.shift[k] - rows.shift[first], axes)[:2], axis=1)
    a = (gap[:, 1] * d2[:, 0] - gap[:, 0] * d2[:, 1]) / across  # (gap × d2) / (d1 × d2)
    inside = a < 0.0
    if not inside.any():
        return
    k, first, a, axes = k[inside], first[inside], a[inside], axes[inside]
    n = axes[:, 2]
    length = np.hypot(*in_plane(rows.end[first] - rows.start[first], axes)[:2])
    at_end = out_end[first, n] - rows.end[first, n]
    at_start = crossing(first)[np.arange(len(k)), n] - rows.start[first, n]
    out_end[first, n] += a * (at_end - at_start) / length


def _pin_plane(rows: _Rows, out_end: NDArray, before: NDArray | None) -> None:
    """The lines under compensation that move no axis of the plane keep the plane's axes (G17: X Y)
    of the end before them: a correction that differs there (with the normal axis) would be a tiny
    move in the plane, which the control offsets along its own direction.  `before`: the previous
    chunk's last end, in the first row's frame (None: none)."""
    if rows.still is None or rows.axes is None:
        return
    if rows.still[0] and before is not None:
        out_end[0, rows.axes[0, :2]] = before[rows.axes[0, :2]]
    for k, plane in _pins(rows).items():  # in order: a run of them keeps the first's
        out_end[k, plane] = out_end[k - 1, plane]


def _pins(rows: _Rows) -> dict[int, tuple[int, int]]:
    """The rows `_pin_plane` pins in their predecessor's frame, and the plane axes each keeps."""
    if rows.still is None or rows.axes is None:
        return {}
    return {
        k: (int(rows.axes[k, 0]), int(rows.axes[k, 1]))
        for k in np.flatnonzero(rows.still).tolist()
        if k > 0 and (rows.offsets[k] == rows.offsets[k - 1]).all() and rows.scales[k] == rows.scales[k - 1]
    }


def _kept_axes(segs: list, kind: NDArray) -> NDArray:
    """(n,3) the axes of moves left as programmed that run from where the control stands: every
    axis in G91 (`kind` 16), those a move's `placed` does not put at its end (G28/G30)."""
    kept = np.zeros((len(segs), 3), dtype=bool)
    kept[(kind & 16) != 0] = True
    for k in np.flatnonzero(kind & 2).tolist():  # (moves left as programmed are few)
        placed = getattr(segs[k], "placed", None)
        if placed is not None:
            kept[k] = [not p for p in placed]
    return kept


class Solve:
    """The numbers of the pass, chunk after chunk: compensated ends, reversal steps
    and shifted arc pieces.  Keeps what the machine has done so far (`Travel`),
    so chunks must come in order."""

    def __init__(self, ctx: PassContext):
        self.ctx = ctx
        self.travel = Travel()

    def __call__(self, rows: _Rows) -> _Solved:
        return self._solve(rows, self.travel)

    def _solve(self, rows: _Rows, travel: Travel) -> _Solved:
        try:
            return (
                _directional(rows, self.ctx, travel)
                if self.ctx.directional
                else _plain(rows, self.ctx, travel)
            )
        except NcppError as error:  # (`travel` is advanced only once a chunk is solved)
            # the chunk's line ends are checked before its reversal steps: an earlier line's fault
            # among these is found solving the rows before the refused line alone, and raised instead
            head = _rows_before(rows, error.where.line)
            if head is not None:
                self._solve(head, travel.copy())
            raise


@dataclass
class _Solved:
    """A chunk's segments (rows) as compensation leaves them, program units."""

    start: NDArray  # (n,3) where each piece starts (replace_arcs' pieces may have moved)
    end: NDArray  # (n,3) where each segment ends
    free: NDArray  # (n,) the lines whose end was compensated here (the others came compensated)
    moved: NDArray  # (n,) replace_arcs' pieces moved here for the direction they really travel in
    turn: NDArray  # (n,) lines that reverse an axis: they start with a step to `turn_start`
    turn_start: NDArray  # (n,3) their start compensated for the new direction
    keep: NDArray  # (n,3) axes that keep their direction (they must not move in that step)
    limit: NDArray  # (n,) program units an axis may be left off its compensated position
    at_end: NDArray  # (n,3) line ends left at a travel end their command would pass (`compensate`'s `ends`)
    direction: NDArray  # (n,3) the direction each axis travels in (+1, -1; 0: no reversal errors)


# What `_written` does with a segment (bits of its row's code)
_FREE, _MOVED, _TURNS, _CONNECTS = 1, 2, 4, 8


def _written(chunk: list[Event], segs: list, rows: _Rows, solved: _Solved, last) -> list[Event]:
    """The chunk's events with each segment replaced: a connecting or reversal
    step where needed, then the segment with its compensated ends, starting where
    the previous one ended."""
    offsets, scales = rows.offsets, rows.scales
    previous = np.empty_like(solved.end)
    previous[1:] = solved.end[:-1]
    has_previous = np.ones(len(segs), dtype=bool)
    # where units or offsets change, the previous end is seen from the new frame
    reframed = np.flatnonzero(any3(offsets[1:] != offsets[:-1]) | (scales[1:] != scales[:-1])) + 1
    starts_from: dict[int, tuple | None] = {}  # rows whose start is not the previous row's end
    for i, before in [(0, last), *((i, None) for i in reframed.tolist())]:
        p = _end_in_frame_of(before if i == 0 else _ended(segs[i - 1], solved.end[i - 1]), segs[i])
        has_previous[i] = p is not None
        previous[i] = p if p is not None else np.nan
        starts_from[i] = None if p is None else tuple(map(float, p))
    turning = solved.turn & has_previous & ~rows.rapid
    # A reversal step's target, with the axes that keep their direction left where they
    # are when they differ only by output rounding: a one-digit move there would reverse
    # that axis on the machine.
    target = np.where(
        solved.keep & (np.abs(solved.turn_start - previous) <= solved.limit[:, None]),
        previous,
        solved.turn_start,
    )
    # An axis that runs ahead on reversal (a reversal table below its other) would reach its
    # start for the new direction travelling the old way, past the corner: it reverses where
    # it is, and its jump lands the tool back along the way it came.
    target = np.where(~solved.keep & ((target - previous) * solved.direction < 0), previous, target)
    turning &= _apart(previous, target)
    # replace_arcs' pieces start where they start: a step from the previous end first
    connect = ~solved.free & has_previous & rows.arc & _apart(previous, solved.start)
    code = (
        solved.free * _FREE + (solved.moved & ~solved.free) * _MOVED + turning * _TURNS + connect * _CONNECTS
    ).tolist()
    ends = tuples(solved.end)
    targets = _by_row(target, turning & solved.free)
    moved_starts = _by_row(solved.start, solved.moved & ~solved.free)
    between = _between(chunk) if len(chunk) > len(segs) else {}
    lead_in = set(np.flatnonzero(rows.lead_in).tolist())
    out: list[Event] = []
    start = None  # where the output is: the previous segment's compensated end
    for i, seg, row, end in zip(range(len(segs)), segs, code, ends):
        if i in between:
            out += _placed(between[i], last if i == 0 else _ended(segs[i - 1], solved.end[i - 1]))
        start = starts_from.get(i, start)
        if row & _FREE:
            begin = seg.start if start is None else start
            if (
                row & _TURNS
            ):  # the reversal step (the axes beyond X Y Z still), then the line from where it ends
                still = seg.extra_start or seg.extra
                out.append(
                    Line(
                        begin,
                        targets[i],
                        seg.rapid,
                        seg.feed,
                        seg.block,
                        seg.context,
                        still,
                        True,
                        extra_start=still,
                    )
                )
                begin = targets[i]
            out.append(
                Line(
                    begin,
                    end,
                    seg.rapid,
                    seg.feed,
                    seg.block,
                    seg.context,
                    seg.extra,
                    True,
                    extra_start=seg.extra_start,
                    tap=seg.tap,
                )
            )
        else:
            if i in lead_in:
                step = _lead_in(seg, last if i == 0 else _ended(segs[i - 1], solved.end[i - 1]))
                out += () if step is None else (step,)
            if row & _MOVED:
                seg = _moved_arc(seg, moved_starts[i], end)
            if row & _CONNECTS:
                # (a step connects only after an end: `has_previous`, so `start` is one)
                out.append(Line(start, seg.start, False, seg.feed, seg.block, seg.context, seg.extra, True))  # type: ignore[arg-type]
            out.append(seg)
        start = end
    if len(segs) in between:
        out += _placed(between[len(segs)], _ended(segs[-1], solved.end[-1]))
    return out


def _placed(events: list[Event], last: Line | Arc | None) -> list[Event]:
    """The events, a G92 / G10 L10/L11/L20 block's `Setting` told where the control stands (`last`: the last
    segment written, with its compensated end; None: nothing written yet, no shift)."""
    if last is None:
        return events
    out = events
    for k, event in enumerate(events):
        if type(event) is not Pass or event.setting is None:
            continue
        setting = event.setting
        at = _end_in_frame_of(last, setting)
        shift = (at[0] - setting.position[0], at[1] - setting.position[1], at[2] - setting.position[2])
        if out is events:
            out = list(events)
        out[k] = Pass(event.block, event.skipped, event.motion, replace(setting, shift=shift))
    return out


def _between(chunk: list[Event]) -> dict[int, list[Event]]:
    """The chunk's other events by the segment they stand before (n: after the last of n)."""
    found: dict[int, list[Event]] = {}
    i = 0
    for event in chunk:
        if type(event) is Line or type(event) is Arc:
            i += 1
        else:
            found.setdefault(i, []).append(event)
    return found


def _by_row(points: NDArray, rows: NDArray) -> dict[int, tuple]:
    """{row: (x, y, z)} of the (n,3) points at the rows where `rows` (n,) is true."""
    index = np.flatnonzero(rows)
    return dict(zip(index.tolist(), tuples(points[index])))


def _plain(rows: _Rows, ctx: PassContext, travel: Travel) -> _Solved:
    """Compensated ends of the chunk's lines, for a map without reversal errors; advances
    `travel.last` (where the carried G91 moves start from, `_carry`)."""
    start, end, free, offsets, scales = rows.start, rows.end.copy(), rows.free, rows.offsets, rows.scales
    at = np.flatnonzero(free)
    at_end = np.zeros(end.shape, dtype=bool)
    if at.size:
        ends = np.zeros((at.size, 3), dtype=bool)
        shift = 0.0 if rows.shift is None else rows.shift[at]
        end[at] = (
            compensate(
                end[at] + shift,
                offsets[at],
                scales[at],
                rows.lines[at],
                ctx,
                np.sign(end[at] - start[at]),
                rows_of(rows.tools, at),
                ends,
            )
            - shift
        )
        at_end[at] = ends
    if rows.shift is not None:
        centre = rows.shift

        def crossing(k: NDArray) -> NDArray:
            direction, wanted = np.sign(rows.end[k] - start[k]), start[k] + centre[k]
            tools = rows_of(rows.tools, k)
            return compensate(wanted, offsets[k], scales[k], rows.lines[k], ctx, direction, tools) - centre[k]

        _corners(rows, end, crossing)
    before = None if travel.last is None else travel.last / scales[0] - offsets[0]
    _pin_plane(rows, end, before)
    out_start, moved = _joined(rows, end, before)
    if rows.carried.any():
        _carry(rows, end, before)
    travel.last = (end[-1] + offsets[-1]) * scales[-1]
    none = np.zeros(len(free), dtype=bool)
    keep = np.ones(start.shape, dtype=bool)
    return _Solved(
        out_start, end, free, moved, none, start, keep, np.zeros(len(free)), at_end, np.zeros(start.shape)
    )


def _joined(rows: _Rows, out_end: NDArray, before: NDArray | None) -> tuple[NDArray, NDArray]:
    """(n,3) the starts of the segments and (n,) the arc pieces moved: an arc piece under cutter
    compensation that does not start where the end before it is (after a move along Z alone kept in
    the plane, `_pin_plane`) moves onto it, `out_end` with it, and the pieces after it of its arc: a
    connecting step there would be a move the control offsets along its own direction.  (With
    reversal errors `_settle` does it.)"""
    moved = np.zeros(len(rows.start), dtype=bool)
    if rows.comp is None:
        return rows.start, moved
    pieces = rows.comp & rows.arc
    out_start = rows.start.copy()
    pins = _pins(rows)  # (a line along the normal after a piece moved keeps its plane axes: moved with it)
    in_order = sorted(pins.keys() | set(np.flatnonzero(pieces).tolist()))
    for k in in_order:  # in order: a piece moved moves the next
        if k in pins:
            out_end[k, pins[k]] = out_end[k - 1, pins[k]]
            continue
        same = (
            k > 0 and (rows.offsets[k] == rows.offsets[k - 1]).all() and rows.scales[k] == rows.scales[k - 1]
        )
        previous = out_end[k - 1] if same else (before if k == 0 else None)
        if previous is None or not _apart(previous[None], out_start[k][None])[0]:
            continue
        gap = previous - out_start[k]
        out_start[k] += gap
        out_end[k] += gap
        moved[k] = True
    return out_start, moved


class _Commands:
    """Compensated line starts and ends of a chunk on the output grid, per row for
    the direction last asked: the rounds ask again for rows whose direction is
    unchanged, and the reversal check and the reversal steps ask for the same."""

    def __init__(self, rows: _Rows, wanted: dict[str, NDArray], step: NDArray, ctx: PassContext):
        self.rows, self.wanted, self.step, self.ctx = rows, wanted, step, ctx
        self.values = {which: np.empty_like(p) for which, p in wanted.items()}
        self.at_end = {which: np.zeros(p.shape, dtype=bool) for which, p in wanted.items()}  # as last asked
        self.directions = {which: np.full(p.shape, np.nan) for which, p in wanted.items()}

    def __call__(self, which: str, rows: NDArray, d: NDArray) -> NDArray:
        """(r,3) commands for the `which` ("start"/"end") points of `rows` travelled in `d` (r,3)."""
        stale = any3(self.directions[which].take(rows, axis=0) != d)
        todo, d_todo = rows[stale], d.compress(stale, axis=0)
        if todo.size:
            segs = self.rows
            ends = np.zeros((todo.size, 3), dtype=bool)
            # (under cutter compensation a line's end is corrected where the tool centre is: `_Rows.shift`;
            # a line's is the same at its start)
            shift = 0.0 if segs.shift is None else segs.shift.take(todo, axis=0)
            c = compensate(self.wanted[which].take(todo, axis=0) + shift, segs.offsets.take(todo, axis=0), segs.scales[todo], segs.lines[todo], self.ctx,
                           d_todo, rows_of(segs.tools, todo), ends) - shift  # fmt: skip
            self.values[which][todo] = quantize(c, self.step[todo])
            self.at_end[which][todo] = ends
            self.directions[which][todo] = d_todo
        return self.values[which].take(rows, axis=0)


def _directional(rows: _Rows, ctx: PassContext, travel: Travel) -> _Solved:
    """Compensated line ends and starts, and shifted arcs, of one chunk, with the
    directions the machine will travel in; advances `travel` past the chunk."""
    offsets, scales = rows.offsets, rows.scales
    step = grid(ctx, scales)
    threshold = step * scales / 2  # mm: half the output resolution
    machine = lambda p, rows=slice(None): (p + offsets[rows]) * scales[rows, None]  # noqa: E731
    free, arc, pieces, start_p, end_p = rows.free, rows.arc, rows.pieces, rows.start, rows.end
    start_m, end_m = machine(start_p), machine(end_p)
    first = travel.last if travel.last is not None else start_m[0]
    before = None if travel.last is None else travel.last / scales[0] - offsets[0]  # in the first row's frame
    limit = _snap_limit(step, scales)
    # arc pieces under cutter compensation move onto the end before them, however far: a connecting step
    # there would be a move the control offsets along its own direction
    joined = limit if rows.comp is None else np.where(rows.comp & arc, np.inf, limit)

    out_start, out_end = start_p.copy(), end_p.copy()
    compensated = end_p.copy()  # line ends before _settle leaves axes standing
    commands = _Commands(rows, {"start": start_p, "end": end_p}, step, ctx)
    assumed = rows.assumed
    assert assumed is not None  # (rows of a directional map: `_rows`)
    used = np.full(start_p.shape, np.nan)  # the directions each row is compensated with
    used[arc] = assumed[arc]
    # start from the nominal motion, standing axes holding their direction
    d = hold(steps(end_m - start_m, threshold), travel.held)
    for round_ in range(ROUNDS):
        redo = np.flatnonzero(free & any3(d != used))
        if redo.size:
            compensated[redo] = commands("end", redo, d.take(redo, axis=0))
        shift = np.flatnonzero(arc & any3(d != used))
        if shift.size:
            _shift_arcs(shift, rows, d, assumed, step, ctx, out_start, out_end)
        used[redo], used[shift] = d.take(redo, axis=0), d.take(shift, axis=0)
        np.copyto(out_end, compensated, where=free[:, None])
        _corners(rows, out_end, lambda k: commands("start", k, d.take(k, axis=0)), step)  # noqa: B023  # (called here)
        _hold_pieces_still(pieces, d, travel.held, limit, out_start, out_end)
        _pin_plane(rows, out_end, before)
        _settle(free, arc, d, travel.held, offsets, scales, joined, out_start, out_end, before, _pins(rows))
        if rows.carried.any():
            _carry(rows, out_end, before)
        cur_end, cur_start = machine(out_end), machine(out_start)
        previous = np.vstack([first[None, :], cur_end[:-1]])
        # a piece moves from the previous end to its start first (a connecting step), then along itself
        own = steps(np.where(free[:, None], cur_end - previous, cur_end - cur_start), threshold)
        moved = np.where(arc[:, None] & (own == 0), steps(cur_start - previous, threshold), own)
        d_new = _own_motion(
            moved, hold(moved, travel.held), free, start_p, end_p, scales, threshold, commands, travel
        )
        if np.array_equal(d_new, d) or round_ == ROUNDS - 1:
            break  # unsettled: keep the directions the ends were computed for
        d = d_new

    moved = arc & any3((out_start != start_p) | (out_end != end_p))
    # where an axis reverses, the line must start where its own direction puts the tool
    before = np.vstack([travel.held[None, :], d[:-1]])
    flips = (d != before) & (before != 0)
    turn = free & any3(flips)
    if rows.comp is not None:  # (no reversal step under cutter compensation: `joined`)
        turn &= ~rows.comp
    turn_start = np.full(start_p.shape, np.nan)
    turned = np.flatnonzero(turn)
    if turned.size:
        turn_start[turned] = commands("start", turned, d.take(turned, axis=0))
    travel.held = d[-1].copy()
    travel.last = machine(out_end[-1:], slice(len(free) - 1, None))[0]
    return _Solved(
        out_start,
        out_end,
        free,
        moved,
        turn,
        turn_start,
        ~flips,
        limit,
        commands.at_end["end"] & free[:, None],
        d,
    )


def _carry(rows: _Rows, out_end: NDArray, before: NDArray | None) -> None:
    """Move the ends of the carried rows (left as programmed, in G91: the moves of loops and
    subroutines, and under cutter compensation; the axes a G28/G30 does not put at its
    intermediate or home point) by where the control stands when each run of them starts: the program's increments run from the compensated end before them, which is
    off their programmed start by that end's correction.  `before`: the previous chunk's last
    end, in the first row's frame."""
    carried, offsets, scales = rows.carried, rows.offsets, rows.scales
    reframed = np.concatenate([[True], any3(offsets[1:] != offsets[:-1]) | (scales[1:] != scales[:-1])])
    # a run starts after a row not carried, or where the frame changes (G20/G21 in it)
    starts = np.flatnonzero(carried & (reframed | ~np.concatenate([[False], carried[:-1]]))).tolist()
    for n, k in enumerate(starts):
        if k == 0:
            previous = before
        else:  # the end before, seen from this row's frame
            previous = (out_end[k - 1] + offsets[k - 1]) * scales[k - 1] / scales[k] - offsets[k]
        if previous is None or rows.lead_in[k]:  # (a cycle starts from its programmed start: `_lead_in`)
            continue
        # the run: up to the next run's start or the first row not carried, whichever comes first
        stop = starts[n + 1] if n + 1 < len(starts) else len(carried)
        rest = carried[k:stop]
        run = stop if rest.all() else k + int(np.argmin(rest))
        # an axis a move of the run puts at its programmed end runs from there on
        placed = np.logical_or.accumulate(~rows.kept[k:run], axis=0)
        out_end[k:run] = rows.end[k:run] + np.where(placed, 0.0, previous - rows.start[k])


def _settle(free, arc, d, held, offsets, scales, limit, out_start, out_end, before, pins=None) -> None:
    """Keep axes from reversing by less than `limit` (n,), in order of travel.

    A line whose compensated end moves an axis a little against the direction
    it holds (the error drifting along an axis that does not move) leaves that
    axis where it is: the reversal's jump would be larger.  An arc piece that
    starts within `limit` of the previous end moves rigidly onto it (radii stay
    equal), so that no µm connecting step reverses an axis.  In order, because
    each moved end is the next row's start and a drift over many rows stays bounded.
    `before`: the previous chunk's last end in the first row's frame (or None).  A line
    after a change of units or offsets settles onto its predecessor's end seen from its own
    frame (the program's numbers there are other numbers for the same place).  `pins`: the rows that
    keep axes of their predecessor's end (`_pins`), kept so when a settled row before them moves."""
    pins = pins or {}
    ends, dirs, ok = _with_previous(out_end, d, held, offsets, scales, before)
    reframed = np.flatnonzero(any3(offsets[1:] != offsets[:-1]) | (scales[1:] != scales[:-1])) + 1
    pred_end, pred_dir = ends[:-1].copy(), dirs[:-1]  # row k's predecessor's end (in k's frame), direction
    pred_end[reframed] = _reframed(pred_end[reframed], reframed - 1, reframed, offsets, scales)
    same = ok.copy()  # the predecessor is in the row's frame
    same[reframed] = False
    within = limit[:, None]
    line_gap = out_end - pred_end
    lines = (
        free & ok & any3((line_gap * pred_dir < 0) & (dirs[1:] == pred_dir) & (np.abs(line_gap) <= within))
    )
    arc_gap = pred_end - out_start
    pieces = arc & same & any3((np.abs(arc_gap) <= within) & (arc_gap != 0))
    todo = np.flatnonzero(lines | pieces).tolist()
    if not todo:
        return
    # in order, on Python floats: a numpy call per row would cost more than the row.  Only the
    # rows looked at are read (about one in five on a generated program); `ends` has the
    # predecessor of row 0 in front: row k's end is ends[k + 1], its predecessor's ends[k].
    # A run's first row's predecessor is as it was: a row changed is followed by the next, so
    # a run ends after an unchanged row or before one that does not settle (never in `todo`).
    n = len(free)
    is_line, limits, settles = free.tolist(), limit.tolist(), ((ok & free) | (same & arc)).tolist()
    new_frame = set(reframed.tolist())
    moved, moved_ends = [], []  # the rows changed, in order, and their new ends
    shifted, shifted_starts = [], []  # the arc pieces among them, and their new starts
    k = -1  # the last row looked at
    for first in todo:  # each row to look at, then the rows after it while their predecessor's end moves
        if first <= k:
            continue
        k = first
        pred = pred_end[k].tolist()
        while k < n and settles[k]:
            limit_k, changed, end = limits[k], False, ends[k + 1].tolist()
            if is_line[k]:
                held_k, own = dirs[k].tolist(), dirs[k + 1].tolist()  # the predecessor's direction, row k's
                for a in (0, 1, 2):
                    p, held_a = pred[a], held_k[a]
                    gap = end[a] - p
                    if gap * held_a < 0 and own[a] == held_a and -limit_k <= gap <= limit_k:
                        end[a] = p
                        changed = True
                for a in pins.get(k, ()):
                    if end[a] != pred[a]:
                        end[a] = pred[a]
                        changed = True
            else:
                start = out_start[k].tolist()
                for a in (0, 1, 2):
                    move = pred[a] - start[a]
                    if move != 0 and -limit_k <= move <= limit_k:
                        start[a] += move
                        end[a] += move
                        changed = True
                if changed:
                    shifted.append(k)
                    shifted_starts.append(start)
            if not changed:
                break
            moved.append(k)
            moved_ends.append(end)
            pred = end
            k += 1
            if k in new_frame and k < n:
                pred = _reframed(np.array([pred]), np.array([k - 1]), np.array([k]), offsets, scales)[0].tolist()  # fmt: skip
    if moved:
        out_end[moved] = moved_ends
    if shifted:
        out_start[shifted] = shifted_starts


def _with_previous(out_end, d, held, offsets, scales, before) -> tuple[NDArray, NDArray, NDArray]:
    """Ends and directions with the previous chunk's last row in front, and
    (n,) whether each row has a predecessor."""
    ends = np.vstack([before if before is not None else np.full(3, np.nan), out_end])
    dirs = np.vstack([held, d])
    ok = np.ones(len(out_end), dtype=bool)
    ok[0] = before is not None
    return ends, dirs, ok


def _reframed(points: NDArray, rows: NDArray, to: NDArray, offsets: NDArray, scales: NDArray) -> NDArray:
    """(r,3) points of the frames of `rows` seen from the frames of rows `to`."""
    return (points + offsets[rows]) * (scales[rows] / scales[to])[:, None] - offsets[to]


def _hold_pieces_still(pieces, d, held, limit, out_start, out_end) -> None:
    """The same for the lines replace_arcs made (slivers): an axis they move by
    less than `limit` against the held direction stays where the piece starts."""
    rows = np.flatnonzero(pieces)
    if rows.size == 0:
        return
    before = np.vstack([held[None, :], d[:-1]]).take(rows, axis=0)
    start, end = out_start.take(rows, axis=0), out_end.take(rows, axis=0)
    motion = end - start
    keep = (
        (np.sign(motion) == -before)
        & (d.take(rows, axis=0) == before)
        & (np.abs(motion) <= limit[rows, None])
    )
    out_end[rows] = np.where(keep, start, end)


def _own_motion(moved, d, free, start_p, end_p, scales, threshold, commands: _Commands, travel) -> NDArray:
    """Directions (n,3) with the lines that reverse an axis judged by their own motion.

    Such a line starts with a step to its start compensated for the new
    direction; if the line then moves that axis the other way (the error
    varies along it), the machine ends up travelling the old way and the
    reversal was not one: the line keeps the old direction instead."""
    before = np.vstack([travel.held[None, :], d[:-1]])
    # only where the line itself moves that axis by less than any error could turn round
    short = np.abs(end_p - start_p) * scales[:, None] < NEAR_STILL
    flips = (d != before) & (before != 0) & free[:, None] & short
    rows = np.flatnonzero(any3(flips))
    if rows.size == 0:
        return d
    along = d.take(rows, axis=0)
    own = steps(
        (commands("end", rows, along) - commands("start", rows, along)) * scales[rows, None], threshold[rows]
    )
    contrary = flips.take(rows, axis=0) & (own != 0) & (own != along)
    if not contrary.any():
        return d
    moved = moved.copy()
    moved[rows] = np.where(contrary, own, moved.take(rows, axis=0))
    return hold(moved, travel.held)


def _arc_assumed(segs: list, rows: NDArray, start: NDArray, end: NDArray) -> NDArray:
    """Directions replace_arcs compensated each arc piece (`rows`, with the chunk's
    `start` and `end` points) with: the sign of the tangent at the middle in the plane,
    `Arc.normal` on the normal axis; and the mean on every axis for the lines it made."""
    out = np.zeros((len(segs), 3))
    if rows.size == 0:
        return out
    arcs = [segs[i] for i in rows.tolist()]
    axes = plane_axes(arcs)
    (su, sv, _), (eu, ev, _), (cu, cv, _) = (
        in_plane(p, axes) for p in (start[rows], end[rows], points([a.center for a in arcs]))
    )
    u0, v0, u1, v1 = su - cu, sv - cv, eu - cu, ev - cv
    with np.errstate(invalid="ignore", divide="ignore"):
        r0, r1 = np.sqrt(u0 * u0 + v0 * v0), np.sqrt(u1 * u1 + v1 * v1)
        mid_u, mid_v = u0 / r0 + u1 / r1, v0 / r0 + v1 / r1
    turn = np.sign(np.fromiter((a.turn for a in arcs), dtype=float, count=len(arcs)))
    # the tangent is the middle's radius turned a quarter the way the arc turns
    normal = np.fromiter((a.normal for a in arcs), dtype=float, count=len(arcs))
    out[rows] = from_plane(np.sign(turn * -mid_v), np.sign(turn * mid_u), normal, axes)
    return out


def _shift_arcs(at, rows: _Rows, d, assumed, step, ctx, out_start, out_end) -> None:
    """Move arc pieces (rows `at`) by the change of the error between the directions
    they were compensated with (`assumed`) and those they are travelled in (`d`)."""
    pts = np.stack([rows.start.take(at, axis=0), rows.end.take(at, axis=0)], axis=1)  # (r,2,3) program
    scale = rows.scales[at, None, None]
    pairs = ((pts + rows.offsets.take(at, axis=0)[:, None, :]) * scale).reshape(-1, 3)
    act, was = np.repeat(d.take(at, axis=0), 2, axis=0), np.repeat(assumed.take(at, axis=0), 2, axis=0)
    tool = None if rows.tools is None else np.tile(np.repeat(rows.tools.take(at, axis=0), 2, axis=0), (2, 1))
    # both directions in one call (the map's cost per call is that of some 500 points)
    both = deviation(ctx.model, np.vstack([pairs, pairs]), np.vstack([act, was]), tool)
    change = both[: len(pairs)] - both[len(pairs) :]
    delta = change.reshape(pts.shape) / scale
    out_start[at] = quantize(pts[:, 0] - delta[:, 0], step[at])
    out_end[at] = quantize(pts[:, 1] - delta[:, 1], step[at])


def _snap_limit(step: NDArray, scales: NDArray) -> NDArray:
    """(n,) program units an axis may be left off its compensated position
    rather than reversed: a rounding step, or STILL_MM (whatever the tolerance:
    within the 0.5 µm the guarantee allows beyond it)."""
    return np.maximum(1.01 * step, STILL_MM / scales)


def _moved_arc(arc: Arc | Line, start: tuple, end: tuple) -> Arc | Line:
    """The piece with new ends; an arc's centre moves with the mean shift of the
    ends (equal for planar arcs: radii still agree)."""
    if type(arc) is Line:
        return Line(start, end, arc.rapid, arc.feed, arc.block, arc.context, arc.extra, True)
    (s0, s1, s2), (e0, e1, e2), (c0, c1, c2) = arc.start, arc.end, arc.center
    centre = (
        c0 + (start[0] - s0 + end[0] - e0) / 2,
        c1 + (start[1] - s1 + end[1] - e1) / 2,
        c2 + (start[2] - s2 + end[2] - e2) / 2,
    )
    return Arc(start, end, centre, arc.turn, arc.feed, arc.block, arc.context, arc.extra, True)


@overload
def _end_in_frame_of(last: Line | Arc, event: Line | Arc | Setting) -> tuple: ...
@overload
def _end_in_frame_of(last: Line | Arc | None, event: Line | Arc | Setting) -> tuple | None: ...
def _end_in_frame_of(last: Line | Arc | None, event: Line | Arc | Setting) -> tuple | None:
    """The last segment's end in `event`'s program frame: units (G20/G21) and
    offsets (G92, G54.., tool length) may have changed between them."""
    if last is None:
        return None
    a, b = last.context, event.context
    if a.inch == b.inch and a.offset == b.offset:
        return last.end
    return b.to_program(a.to_machine(last.end))


def _ended(segment: Line | Arc, end: NDArray) -> Line:
    """Stands in for a written segment where only its end, frame and `fixed` matter."""
    end_point = tuple(end.tolist())
    return Line(segment.start, end_point, False, 0.0, segment.block, segment.context, fixed=segment.fixed)


def _lead_in(cycle: Line | Arc, before: Line | None) -> Line | None:
    """A rapid step from where the output is (`before`'s end) to the programmed start of a
    canned cycle, in `before`'s frame and mode (the cycle's block may set G91), written ahead
    of the cycle's block (`fixed` and changed: `IsoWriter`).  Where a cycle puts its holes
    depends on where it starts: in G91 its holes, R and Z levels run from there (polar words
    turning about XY zero), in G90 a hole without X Y, a polar word without `@` or `^`, and
    the G98 retract take the start's; from a compensated start they would carry its
    correction, turned.  From the programmed start the holes are where the program puts
    them, with the machine's errors.  None: no step is needed."""
    if before is None:
        return None
    mode, frame = before.context, cycle.context
    same = mode.inch == frame.inch and mode.offset == frame.offset
    target = cycle.start if same else mode.to_program(frame.to_machine(cycle.start))
    if max(abs(p - q) for p, q in zip(target, before.end)) <= 1e-9:
        return None
    return Line(before.end, target, True, cycle.feed, cycle.block, mode, changed=True, fixed=CYCLE)


def _apart(a: NDArray, b: NDArray, tolerance: float = 1e-7) -> NDArray:
    """(n,) whether the points differ by more than `tolerance` on some axis."""
    return any3(np.abs(a - b) > tolerance)
