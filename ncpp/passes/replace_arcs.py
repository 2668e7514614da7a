"""Pass: replace each arc by arcs through compensated points (thesis Figs. 36–37).

For a piece of an arc, the compensated start and end points are fixed; the
new centre is chosen on their perpendicular bisector, so the start and end
radii agree exactly (a controller checks that), at the position that fits
the compensated interior points best (an algebraic least-squares fit, closed
form).  A piece whose fit leaves more than the tolerance is halved; a piece
that is still off when it is shorter than `MIN_PIECE` mm becomes lines
through compensated points.  Helical arcs: the normal axis is fitted as a
straight ramp over the angle and checked the same way.

All arcs of a chunk are processed together, piece arrays in, piece arrays out.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from typing import cast

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import Location, NcppError
from ncpp.machine.chain import norm3
from ncpp.machine.curvature import ripple_bow
from ncpp.motion.centre_path import turns_back_inside
from ncpp.motion.segments import PLANE_AXES, Arc, Event, Line
from ncpp.passes.context import PassContext
from ncpp.passes.geometry import (
    any3,
    before_line,
    compensate,
    frames,
    from_plane,
    in_plane,
    plane_axes,
    points,
    row_max,
    rows_of,
    spliced,
    tuples,
)
from ncpp.passes.subdivide import SAFETY
from ncpp.passes.travel import grid, quantize

# Points per piece where the fit is checked (ends included).  Fewer on short
# pieces: over a few mm the error's curvature bends the path by far less than
# the tolerance, and a kink of an error table between samples by ~slope change × length / 8.
SAMPLES = 9
MIN_PIECE = 0.05  # mm of arc length below which a piece is not halved again
MAX_ROUNDS = 24
# An axis reversing this close (mm of path) to a piece's end moves back by
# r·θ²/2 < 0.2 nm (r ≥ 10 mm) to 20 nm (r = 0.1 mm): a rounding of the written centre,
# not a reversal a step must prepare for.
REVERSAL_WINDOW = 0.002
# mm: nor is one that takes the axis back by less than this (a 10⁻⁵ rad rotation
# of the compensated frame moves a quadrant's extreme a µm past its end)
REVERSAL_HEIGHT = 1e-7
# Arcs are replaced independently, a batch at a time: a batch holds up to BATCH_ARCS
# arcs (their events and sample arrays bound the memory) and up to BATCH_EVENTS events,
# so that programs with few arcs among their lines do not pay numpy's per-call cost per arc,
# and nothing waits long to be written.
BATCH_ARCS = 1024
BATCH_EVENTS = 4096
# Turns of one arc at most: an arc's pieces are made at once (~8 kB a turn: 10,000 turns take
# 170 MB; a helix of 10⁸ turns ran out of 24 GB).
MAX_TURNS = 10_000
# Pieces sampled and fitted together in a round of `_replace` (their samples' memory: `_slices`)
ROUND_PIECES = 8192
SLIVER = (
    0.01  # mm of arc length below which a piece becomes a line (its bulge is < 0.1 µm for radii over 0.1 mm)
)
# Lines back that an arc's guess of its normal axis's direction looks (`Motion`)
HELD_LINES = 1024


@dataclass
class _Pieces:
    """Pieces of arcs, one row each: which arc, start angle, signed sweep."""

    arc: NDArray  # (p,) index into the chunk's arcs
    a0: NDArray  # (p,) rad
    sweep: NDArray  # (p,) rad, signed (+ counter-clockwise)


def replace_arcs(events: Iterable[Event], ctx: PassContext) -> Iterator[Event]:
    fit = FitArcs(ctx)
    motion = Motion(directional=ctx.directional)
    for batch, index, arcs, normals in (_with_arcs(batch, motion) for batch in _batches(events)):
        if not arcs:
            yield from batch
            continue
        try:
            fitted = fit(_ArcRows.of(arcs, normals))
        except (
            NcppError
        ) as error:  # the lines before the refused one go on first: a later pass may refuse one of them
            error.locate(e.block for e in batch)
            earlier = before_line(batch, error.where.line)
            if len(earlier) < len(batch):
                yield from replace_arcs(earlier, ctx)
            raise
        yield from spliced(batch, index, _assemble(arcs, fitted, normals))


def _with_arcs(batch: list[Event], motion: Motion) -> tuple[list[Event], list[int], list[Arc], list[int]]:
    """The batch, where its arcs to replace are, those arcs, and the direction each one's
    normal axis is compensated for (`Motion`)."""
    index = [k for k, e in enumerate(batch) if type(e) is Arc and not e.changed and not e.fixed]
    arcs = cast(list[Arc], [batch[k] for k in index])
    return batch, index, arcs, motion.normals(batch, arcs)


class Motion:
    """The sign of each axis's last programmed move (+1, -1), and its line, event after event.

    An arc leaves its plane's normal axis standing, and the machine holds that axis in the
    direction it last moved in, whose reversal error applies: an arc's pieces are compensated
    for it (a helix's for its rise).  It is a guess, from the program's motion, of the
    direction apply_error_map finds from the compensated motion: that pass shifts a piece
    whose guess was wrong (`Arc.normal`).  A move more than HELD_LINES lines before the arc
    is not used (the mean, 0, instead), which keeps outputs those of earlier versions."""

    def __init__(self, state: tuple | None = None, directional: bool = True):
        self.state = state or (0, 0, 0, 0, 0, 0)  # x, y, z signs (0: none yet), and their lines
        self.directional = directional

    def normals(self, batch: list[Event], arcs: list[Arc]) -> list[int]:
        """The direction of the normal axis of each of `arcs` (the batch's arcs to replace, in
        order); reads the batch's moves (where the map has reversal errors: else all 0)."""
        if not self.directional:
            return [0] * len(arcs)
        out: list[int] = []
        pending = iter(arcs)
        arc = next(pending, None)
        x, y, z, lx, ly, lz = self.state
        for event in batch:
            kind = type(event)
            if kind is not Line and kind is not Arc:
                continue
            at = event.block.line
            (s0, s1, s2), (e0, e1, e2) = event.start, event.end  # type: ignore[union-attr]  # a Line or an Arc
            if event is arc:
                arc = next(pending, None)
                w = PLANE_AXES[event.context.plane][2]
                rise = (e0 - s0, e1 - s1, e2 - s2)[w]
                if rise:
                    out.append(1 if rise > 0 else -1)
                else:
                    held, since = (x, y, z)[w], (lx, ly, lz)[w]
                    out.append(held if at - since <= HELD_LINES else 0)
            if e0 != s0:
                x, lx = 1 if e0 > s0 else -1, at
            if e1 != s1:
                y, ly = 1 if e1 > s1 else -1, at
            if e2 != s2:
                z, lz = 1 if e2 > s2 else -1, at
        self.state = (x, y, z, lx, ly, lz)
        return out


def _batches(events: Iterable[Event]) -> Iterator[list[Event]]:
    """Lists of up to BATCH_EVENTS events holding up to BATCH_ARCS arcs.  Where reading
    the events raises an NcppError, the events read before it are handed on first."""
    batch: list[Event] = []
    arcs = 0
    try:
        for event in events:
            batch.append(event)
            if type(event) is Arc:
                arcs += 1
            if arcs == BATCH_ARCS or len(batch) == BATCH_EVENTS:
                yield batch
                batch, arcs = [], 0
    except NcppError:
        if batch:
            yield batch
        raise
    if batch:
        yield batch


@dataclass
class _ArcRows:
    """A batch's arcs as the fit needs them: arrays, no events."""

    start: NDArray  # (n,3) program units
    end: NDArray  # (n,3)
    centre: NDArray  # (n,3)
    axes: NDArray  # (n,3) indices of the plane's u, v and normal axis
    turn: NDArray  # (n,) `Arc.turn`: +1 counter-clockwise, -1 clockwise, more for full turns
    offsets: NDArray  # (n,3) machine minus program, program units
    scales: NDArray  # (n,) mm per program unit
    tools: NDArray | None  # (n,3) tool length offsets, mm (None: none)
    lines: NDArray  # (n,) the line of each arc's block, for messages
    normal: NDArray  # (n,) the direction each arc's normal axis is compensated for (`Motion`)
    # under cutter compensation (`Arc.centre_shift`): how far the tool centre stands off the arc towards
    # its outside (n,) (negative: inside), and off its start (n,3), program units, and the entry arcs (n,),
    # which stay whole; None: no arc is under compensation
    tool_centre: tuple[NDArray, NDArray, NDArray] | None = None
    under_comp: NDArray | None = None  # (n,) the arcs under cutter compensation (None: none)

    @classmethod
    def of(cls, arcs: list[Arc], normals: list[int]) -> _ArcRows:
        offsets, scales, tools = frames(arcs)
        return cls(
            points([a.start for a in arcs]), points([a.end for a in arcs]), points([a.center for a in arcs]),
            plane_axes(arcs), np.fromiter([a.turn for a in arcs], dtype=float, count=len(arcs)),
            offsets, scales, tools, np.fromiter([a.block.line for a in arcs], dtype=np.int64, count=len(arcs)),
            np.array(normals, dtype=float), _centre_offsets(arcs),
            np.fromiter((a.centre_shift is not None for a in arcs), dtype=bool, count=len(arcs)),
        )  # fmt: skip


def _centre_offsets(arcs: list[Arc]) -> tuple[NDArray, NDArray, NDArray] | None:
    """`_ArcRows.tool_centre` of the arcs: the radial offset read from the shift at each one's end."""
    if all(a.centre_shift is None for a in arcs):
        return None
    radial, start, entry = np.zeros(len(arcs)), np.zeros((len(arcs), 3)), np.zeros(len(arcs), dtype=bool)
    for k, arc in enumerate(arcs):
        if arc.centre_shift is not None:
            at_start, shift = arc.centre_shift
            entry[k] = at_start is None
            a, b, _ = PLANE_AXES[arc.context.plane]
            du, dv = arc.end[a] - arc.center[a], arc.end[b] - arc.center[b]
            radial[k] = (shift[a] * du + shift[b] * dv) / math.hypot(du, dv)
            su, sv = arc.start[a] - arc.center[a], arc.start[b] - arc.center[b]
            along = [0.0, 0.0, 0.0]
            along[a], along[b] = radial[k] * su / math.hypot(su, sv), radial[k] * sv / math.hypot(su, sv)
            own = (along[0], along[1], along[2])
            # (turned right back at an inside corner, the tool enters the arc on its own offset, far from where
            # the move before left it, on the other side of the contour)
            start[k] = (
                (0.0, 0.0, 0.0)
                if at_start is None
                else own
                if turns_back_inside(arc, at_start, own)
                else at_start
            )
    return radial, start, entry


@dataclass
class _Fitted:
    """What the fit makes of a batch's arcs, as numbers: pieces in no particular
    order, each with its arc and start angle (`_assemble` orders them)."""

    a0: NDArray  # (n,) each arc's start angle
    sign: NDArray  # (n,) +1 counter-clockwise, -1 clockwise
    arcs: list[tuple[NDArray, ...]] = field(default_factory=list)  # (arc, a0, start, end, centre) per round
    lines: list[tuple[NDArray, ...]] = field(
        default_factory=list
    )  # (arc, a0, points (p,m,3)): lines through the points


class FitArcs:
    """The numbers of the pass: compensated pieces of each arc of a batch."""

    def __init__(self, ctx: PassContext):
        self.ctx = ctx

    def __call__(self, arcs: _ArcRows) -> _Fitted:
        return _replace(arcs, self.ctx)


class _ArcGeometry:
    """Plane-local geometry of a list of arcs: centre (u,v), radius, start
    angle, total sweep, normal-axis start and rise; axis order per arc."""

    def __init__(self, rows: _ArcRows):
        self.axes = rows.axes
        self.tool_centre = rows.tool_centre
        (su, sv, sw), (eu, ev, ew), (cu, cv, _) = (
            in_plane(p, self.axes) for p in (rows.start, rows.end, rows.centre)
        )
        self.centre_u, self.centre_v = cu, cv
        self.radius = np.hypot(su - cu, sv - cv)
        self.a0 = np.arctan2(sv - cv, su - cu)
        self.sweep = _sweeps(self.a0, np.arctan2(ev - cv, eu - cu), rows.turn)
        self.w0 = sw
        self.rise = ew - sw
        self.end_radius = np.hypot(eu - cu, ev - cv)
        self.normal = rows.normal
        self.under_comp = rows.under_comp

    def points(self, arc: NDArray, angles: NDArray) -> NDArray:
        """(p,m,3) program points at the given angles of the given arcs.

        The radius blends from the start to the end radius, as controllers
        do for arcs whose radii differ within their tolerance."""
        sweep = self.sweep[arc]
        frac = (angles - self.a0[arc, None]) / np.where(sweep == 0, 1.0, sweep)[:, None]
        r = self.radius[arc, None] + frac * (self.end_radius - self.radius)[arc, None]
        u = self.centre_u[arc, None] + r * np.cos(angles)
        v = self.centre_v[arc, None] + r * np.sin(angles)
        return from_plane(u, v, self.w0[arc, None] + frac * self.rise[arc, None], self.axes[arc])

    def centre_shifts(self, arc: NDArray, angles: NDArray) -> NDArray | None:
        """(p,m,3) where the tool centre stands off the points at `angles` under cutter compensation
        (`Arc.centre_shift`): radially, but at an arc's start where the move before left it (a
        corner belongs to the move that ends there).  None: no arc is under compensation."""
        if self.tool_centre is None:
            return None
        radial, start, _ = self.tool_centre
        k = radial[arc, None]
        shift = from_plane(k * np.cos(angles), k * np.sin(angles), np.zeros_like(angles), self.axes[arc])
        first = angles == self.a0[arc, None]  # (the first piece starts at the arc's angle, exactly)
        return np.where(first[..., None], start[arc, None, :], shift)

    def free(self, arc: NDArray) -> NDArray:
        """(p,) the arcs (of `arc`) not under cutter compensation."""
        if self.under_comp is None:
            return np.ones(len(arc), dtype=bool)
        return ~self.under_comp[arc]

    def whole(self, arc: NDArray) -> NDArray:
        """(p,) the arcs (of `arc`) that stay one piece: the entry arcs of cutter compensation (the
        control checks that arc against the tool radius, and offsets only its end)."""
        return np.zeros(len(arc), dtype=bool) if self.tool_centre is None else self.tool_centre[2][arc]


def _sweeps(a0: NDArray, a1: NDArray, turn: NDArray) -> NDArray:
    """(n,) signed sweeps, rad (+ counter-clockwise), of arcs from angle a0 to a1 turning `turn`:
    `Arc.sweep` for all of them at once, step for step."""
    full = 2 * math.pi
    ccw = turn > 0
    d = np.mod(np.where(ccw, a1 - a0, a0 - a1), full)
    d = np.where(d > 1e-12, d, full)
    return np.where(ccw, d + full * (turn - 1), -(d + full * (-turn - 1)))


def _initial_pieces(geometry: _ArcGeometry, directional: bool) -> _Pieces:
    """Pieces of at most half a turn: a chord defines a centre only up to that.

    With reversal errors, also cut where an axis reverses (every quarter turn
    in plane-local angle): the command must step there, which an arc cannot."""
    if directional:
        return _quadrant_pieces(geometry)
    counts = np.maximum(1, np.ceil(np.abs(geometry.sweep) / math.pi - 1e-9)).astype(int)
    arc = np.repeat(np.arange(len(counts)), counts)
    step = (geometry.sweep / counts)[arc]
    nth = np.arange(len(arc)) - np.repeat(np.cumsum(counts) - counts, counts)
    return _Pieces(arc, geometry.a0[arc] + nth * step, step)


def _whole(pieces: _Pieces, geometry: _ArcGeometry) -> _Pieces:
    """The pieces, those of an arc that stays whole (`_ArcGeometry.whole`) made one again."""
    whole = geometry.whole(pieces.arc)
    if not whole.any():
        return pieces
    arcs = np.unique(pieces.arc[whole])
    keep = ~whole
    return _Pieces(
        np.concatenate([pieces.arc[keep], arcs]),
        np.concatenate([pieces.a0[keep], geometry.a0[arcs]]),
        np.concatenate([pieces.sweep[keep], geometry.sweep[arcs]]),
    )


def _quadrant_pieces(geometry: _ArcGeometry) -> _Pieces:
    quarter = math.pi / 2
    a0, sweep = geometry.a0, geometry.sweep
    lo, hi = np.minimum(a0, a0 + sweep), np.maximum(a0, a0 + sweep)
    # multiples of a quarter strictly inside (lo, hi), 1e-9 away from the ends
    first = np.floor(lo / quarter) + 1
    last = np.ceil(hi / quarter) - 1
    first = np.where(quarter * first <= lo + 1e-9, first + 1, first)
    last = np.where(quarter * last >= hi - 1e-9, last - 1, last)
    cuts = np.maximum(last - first + 1, 0).astype(int)
    arc = np.repeat(np.arange(len(a0)), cuts + 1)
    nth = np.arange(len(arc)) - np.repeat(np.cumsum(cuts + 1) - (cuts + 1), cuts + 1)  # piece within its arc
    forward = sweep[arc] > 0
    # the j-th cut in the order of travel
    cut = lambda j: quarter * np.where(forward, first[arc] + j - 1, last[arc] - j + 1)  # noqa: E731
    start = np.where(nth == 0, a0[arc], cut(nth))
    end = np.where(nth == cuts[arc], a0[arc] + sweep[arc], cut(nth + 1))
    return _Pieces(arc, start, end - start)


def _replace(arcs: _ArcRows, ctx: PassContext) -> _Fitted:
    many = np.flatnonzero(np.abs(arcs.turn) > MAX_TURNS)
    if many.size:
        turns, line = int(abs(arcs.turn[many[0]])), int(arcs.lines[many[0]])
        raise NcppError(
            f"an arc of {turns:,} turns: ncpp compensates {MAX_TURNS:,} at most (its pieces, 8 a turn, are held at once)",
            Location(ctx.file, line, word="P"),
        )
    geometry = _ArcGeometry(arcs)
    offsets, scales, tools, line_of = arcs.offsets, arcs.scales, arcs.tools, arcs.lines
    pending = _whole(_initial_pieces(geometry, ctx.directional), geometry)
    done = _Fitted(geometry.a0, np.where(geometry.sweep >= 0, 1.0, -1.0))
    for _ in range(MAX_ROUNDS):
        if len(pending.arc) == 0:
            break
        length = np.abs(pending.sweep) * geometry.radius[pending.arc] * scales[pending.arc]
        counts = np.select([length < 2.0, length < 10.0], [3, 5], SAMPLES)  # see SAMPLES
        split = np.zeros(len(pending.arc), dtype=bool)
        for m, rows in _slices(counts):
            some = _Pieces(pending.arc[rows], pending.a0[rows], pending.sweep[rows])
            split[rows] = _round(
                some,
                length[rows],
                np.linspace(0.0, 1.0, m),
                geometry,
                offsets,
                scales,
                tools,
                line_of,
                ctx,
                done,
            )
        half = pending.sweep[split] / 2
        pending = _Pieces(
            np.repeat(pending.arc[split], 2),
            np.column_stack([pending.a0[split], pending.a0[split] + half]).ravel(),
            np.repeat(half, 2),
        )
    return done


def _slices(counts: NDArray) -> Iterator[tuple[int, NDArray]]:
    """The pieces to sample `m` times, for each `m` in `counts`, ROUND_PIECES at a time: a round's
    samples and their temporaries (a few kB a piece) are held for so many pieces at most, however
    many turns an arc makes."""
    for m in np.unique(counts).tolist():
        rows = np.flatnonzero(counts == m)
        for start in range(0, len(rows), ROUND_PIECES):
            yield m, rows[start : start + ROUND_PIECES]


def _round(
    pending: _Pieces,
    length: NDArray,
    t: NDArray,
    geometry,
    offsets,
    scales,
    tools,
    line_of,
    ctx,
    done: _Fitted,
) -> NDArray:
    """Compensate and fit pieces sampled at `t`; append the finished ones to
    `done` and return (p,) which to halve."""
    angles = pending.a0[:, None] + t[None, :] * pending.sweep[:, None]
    nominal = geometry.points(pending.arc, angles)
    middle = (pending.a0 + pending.sweep / 2)[:, None]
    ahead = geometry.points(pending.arc, np.hstack([middle + 1e-6 * np.sign(pending.sweep)[:, None], middle]))
    direction = np.sign(ahead[:, :1] - ahead[:, 1:])  # of the tangent in the middle
    # the normal axis's direction is the one the machine holds when it gets here, as
    # `Motion` guesses it: apply_error_map knows it and shifts the piece where it differs
    np.put_along_axis(
        direction, geometry.axes[pending.arc, None, 2:], geometry.normal[pending.arc, None, None], axis=2
    )
    direction = np.broadcast_to(direction, nominal.shape)
    scale = scales[pending.arc]
    # under cutter compensation the correction is the one where the tool centre is, off the contour
    shift = geometry.centre_shifts(pending.arc, angles)
    at = nominal if shift is None else nominal + shift
    q = compensate(
        at,
        offsets[pending.arc],
        scale,
        line_of[pending.arc],
        ctx,
        direction,
        rows_of(tools, pending.arc),
    )
    if shift is not None:
        q -= shift
    centre, deviation = _fit(q, geometry.axes[pending.arc], t, ctx.tolerance / scale)
    ok = deviation <= ctx.tolerance / scale
    ripple = getattr(ctx.model, "ripple", None)
    if ripple is not None and ripple.any():  # the samples alias an error that repeats between them: halve on
        # (not under cutter compensation, as lines there are not split: each piece is a move the control offsets)
        free = np.ones(len(ok), dtype=bool) if shift is None else geometry.free(pending.arc)
        ok &= ~(free & _rippled(nominal, length, geometry.axes[pending.arc], scale, ripple, ctx.tolerance))
    if ctx.directional:  # ends on the output grid (after the fit: a short piece's chord fixes the bisector)
        step = grid(ctx, scale)
        q[:, 0], q[:, -1] = quantize(q[:, 0], step), quantize(q[:, -1], step)
        window = np.maximum(step, REVERSAL_WINDOW / scale)
        one_way = _one_way(
            q,
            centre,
            geometry.axes[pending.arc],
            direction[:, 0],
            np.sign(pending.sweep),
            window,
            REVERSAL_HEIGHT / scale,
        )
    else:
        one_way = np.ones(len(ok), dtype=bool)
    # a sliver (a quadrant cut next to an arc's end) is a line: on the output grid its
    # chord fixes no centre, and equal ends would be read as a full circle; so is a
    # piece that reverses an axis inside but bulges less than a quarter of the tolerance
    chord = norm3(q[:, -1] - q[:, 0]) * scale
    flat = chord**2 / (8 * np.maximum(geometry.radius[pending.arc] * scale, 1e-12)) <= ctx.tolerance / 4
    whole = geometry.whole(pending.arc)
    straight = ((length < SLIVER) | (~one_way & flat)) & ~whole
    ok = (ok & one_way & ~straight) | whole
    give_up = ~ok & ~straight & (length < MIN_PIECE)
    lines = np.flatnonzero(straight | give_up)
    if lines.size and ctx.directional:
        # lines are compensated for the mean direction: apply_error_map moves them to the real one
        arc = pending.arc[lines]
        q[lines] = _mean_compensated(
            at[lines], offsets[arc], scale[lines], line_of[arc], ctx, rows_of(tools, arc)
        ) - (0.0 if shift is None else shift[lines])
    for rows, pts in (
        (np.flatnonzero(straight), lambda r: q[r][:, [0, -1]]),
        (np.flatnonzero(give_up), lambda r: q[r]),
    ):
        if rows.size:
            done.lines.append((pending.arc[rows], pending.a0[rows], pts(rows)))
    fitted = np.flatnonzero(ok)
    if fitted.size:
        done.arcs.append(
            (pending.arc[fitted], pending.a0[fitted], q[fitted, 0], q[fitted, -1], centre[fitted])
        )
    return ~ok & ~give_up & ~straight


def _rippled(
    nominal: NDArray, length: NDArray, axes: NDArray, scale: NDArray, ripple: NDArray, tolerance: float
) -> NDArray:
    """(p,) the pieces (of `length` mm, program points `nominal` (p,m,3)) that the errors repeating
    along an axis (`Machine.ripple`) could bow from the fit by more than the tolerance allows: a
    piece spans at most its length of its plane's axes, its rise of the normal one."""
    span = np.repeat(length[:, None], 3, axis=1)
    rows, normal = np.arange(len(span)), axes[:, 2]
    span[rows, normal] = np.abs(nominal[rows, -1, normal] - nominal[rows, 0, normal]) * scale
    return SAFETY * ripple_bow(span, ripple) > tolerance


def _one_way(
    q: NDArray,
    centre: NDArray,
    axes: NDArray,
    direction: NDArray,
    sign: NDArray,
    window: NDArray,
    height: NDArray,
) -> NDArray:
    """(p,) whether each compensated piece (ends `q` on the output grid, `centre`) moves
    every plane axis one way only, in the `direction` (p,3) it was compensated for
    (`sign` (p,): +1 counter-clockwise).

    Quadrant cuts are made on the nominal arc; compensation moves the centre, so a
    piece next to a cut can pass the axis's extreme just inside its end and reverse
    the axis there, where no step can follow.  An extreme within `window` (p,)
    (program units of path) of an end, or from which the axis goes back by less
    than `height` (p,), is rounding or a rotation of the compensated frame, not a reversal."""
    (cu, cv, _), (u0, v0, _), (u1, v1, _) = (
        in_plane(centre, axes),
        in_plane(q[:, 0], axes),
        in_plane(q[:, -1], axes),
    )
    want_u, want_v, _ = in_plane(direction, axes)
    a0 = np.arctan2(v0 - cv, u0 - cu)
    a1 = np.arctan2(v1 - cv, u1 - cu)
    span = np.mod(sign * (a1 - a0), 2 * np.pi)  # angle travelled, whatever the wrap
    r0, r1 = np.hypot(u0 - cu, v0 - cv), np.hypot(u1 - cu, v1 - cv)
    radius = np.maximum(r0, 1e-12)
    # controllers blend the radius from start to end: that moves each extreme
    # by (dr/dangle)/r, a lot on a short piece whose ends were rounded
    with np.errstate(divide="ignore", invalid="ignore"):
        blend = np.where(span > 0, (r1 - r0) / (span * radius), 0.0)
    quarter = np.pi / 2
    ahead = quarter - np.mod(sign * a0, quarter)  # angle to the first extreme ahead, (0, π/2]
    margin = window / radius
    at = ahead[:, None] + quarter * np.arange(-1, 2)[None, :] + blend[:, None]
    from_end = np.minimum(at, span[:, None] - at)  # angle between the extreme and the nearer end
    # the axis goes back by r·(1 - cos) from the extreme to that end
    back = radius[:, None] * from_end**2 / 2 > height[:, None]
    inside = any3((at > margin[:, None]) & (at < (span - margin)[:, None]) & back)
    mid = a0 + sign * span / 2
    agrees = (np.sign(sign * -np.sin(mid)) == want_u) & (
        np.sign(sign * np.cos(mid)) == want_v
    )  # the tangent's signs
    return ~inside & agrees & (span < np.pi) & (np.abs(blend) < quarter / 2)


def _mean_compensated(nominal, offsets, scales, line_of, ctx, tools) -> NDArray:
    """Compensated samples (p,m,3) for the mean direction.  Not on the output
    grid: apply_error_map moves them for the real direction, then rounds once."""
    return compensate(nominal, offsets, scales, line_of, ctx, np.zeros_like(nominal), tools)


def _fit(q: NDArray, axes: NDArray, t: NDArray, tolerance: NDArray) -> tuple[NDArray, NDArray]:
    """Centre (p,3 program) on the bisector of each piece's end points, and the
    largest deviation (p,) of the compensated samples from the fitted helix
    (tolerance (p,) in program units)."""
    u, v, w = in_plane(q, axes)
    u0, v0, u1, v1 = u[:, 0], v[:, 0], u[:, -1], v[:, -1]
    mu, mv = (u0 + u1) / 2, (v0 + v1) / 2
    nu, nv = -(v1 - v0), u1 - u0  # the chord turned a quarter
    length = np.sqrt(nu * nu + nv * nv)
    nu, nv = nu / length, nv / length
    # |q_k - c|^2 - |q_0 - c|^2 is linear in the centre's position s along the bisector.
    du, dv = u - u0[:, None], v - v0[:, None]
    a = (u * u + v * v) - (u0 * u0 + v0 * v0)[:, None] - 2 * (du * mu[:, None] + dv * mv[:, None])
    b = 2 * (du * nu[:, None] + dv * nv[:, None])
    s = (a * b).sum(-1) / np.maximum((b * b).sum(-1), 1e-300)
    cu, cv = mu + s * nu, mv + s * nv
    radial = _radial(u, v, cu, cv)
    # Where least squares leaves much of the tolerance unused, its centre stands;
    # elsewhere move it to the smallest largest deviation (which is what is judged).
    tight = np.flatnonzero(row_max(np.abs(radial)) > tolerance / 2)
    if tight.size:
        uv = np.stack([u[tight], v[tight]], axis=-1)
        q0, c = uv[:, 0], np.column_stack([cu[tight], cv[tight]])
        normal = np.column_stack([nu[tight], nv[tight]])
        s[tight] += _minimax_step(uv, q0, c, normal)
        cu[tight], cv[tight] = mu[tight] + s[tight] * nu[tight], mv[tight] + s[tight] * nv[tight]
        radial[tight] = _radial(u[tight], v[tight], cu[tight], cv[tight])
    ramp = w[:, :1] + t[None, :] * (w[:, -1:] - w[:, :1])
    deviation = row_max(np.hypot(radial, w - ramp))
    return from_plane(cu, cv, w[:, 0], axes), deviation


def _radial(u: NDArray, v: NDArray, cu: NDArray, cv: NDArray) -> NDArray:
    """(p,m) distance of the samples (u, v) from each centre (cu, cv) less the first sample's."""
    ru, rv = u[:, 0] - cu, v[:, 0] - cv
    eu, ev = u - cu[:, None], v - cv[:, None]
    return np.sqrt(eu * eu + ev * ev) - np.sqrt(ru * ru + rv * rv)[:, None]


def _minimax_step(uv: NDArray, q0: NDArray, c: NDArray, normal: NDArray) -> NDArray:
    """Move along the bisector that minimises the largest radial deviation.

    The radial deviations r_k are linear in the move δ near the least-squares
    centre (r_k + g_k·δ); the minimax δ of a 1-D linear family lies where two
    of them are equal or opposite, so try every pair."""
    to_k = uv - c[:, None, :]
    to_0 = (q0 - c)[:, None, :]
    dist_k = np.linalg.norm(to_k, axis=-1)
    dist_0 = np.linalg.norm(to_0, axis=-1)
    r = dist_k - dist_0
    g = -(to_k * normal[:, None, :]).sum(-1) / dist_k + (to_0 * normal[:, None, :]).sum(-1) / dist_0
    ri, rj, gi, gj = r[:, :, None], r[:, None, :], g[:, :, None], g[:, None, :]
    with np.errstate(divide="ignore", invalid="ignore"):
        candidates = np.concatenate(
            [
                (-(ri + rj) / (gi + gj)).reshape(len(r), -1),
                (-(ri - rj) / (gi - gj)).reshape(len(r), -1),
                np.zeros((len(r), 1)),
            ],
            axis=1,
        )
    candidates = np.where(np.isfinite(candidates), candidates, 0.0)
    worst = row_max(np.abs(r[:, None, :] + g[:, None, :] * candidates[:, :, None]))
    return candidates[np.arange(len(r)), worst.argmin(axis=1)]


def _line_pieces(arc: Arc, q: list[list[float]]) -> list[Event]:
    pts = cast(list[tuple[float, float, float]], [tuple(p) for p in q])  # (q's points are 3-vectors)
    return [
        Line(a, b, False, arc.feed, arc.block, arc.context, arc.extra, True, centre_shift=arc.centre_shift)
        for a, b in zip(pts, pts[1:])
    ]


def _assemble(arcs: list[Arc], fitted: _Fitted, normals: list[int]) -> list[list[Event]]:
    """The events of each arc's pieces in the order of travel."""
    found = fitted.arcs + fitted.lines  # each (arc, a0, ...) per piece: fitted arcs first, then runs of lines
    if not found:
        return [[] for _ in arcs]
    of = np.concatenate([f[0] for f in found])
    # by arc, then by progress along its sweep whatever its sign (stable: ties keep the order found)
    progress = (np.concatenate([f[1] for f in found]) - fitted.a0[of]) * fitted.sign[of]
    order = np.lexsort((progress, of)).tolist()
    of_list = of.tolist()
    ends = [tuples(np.concatenate([f[k] for f in fitted.arcs])) if fitted.arcs else [] for k in (2, 3, 4)]
    runs = [q for _, _, pts in fitted.lines for q in pts.tolist()]  # the points of each run of lines
    fitted_count = len(ends[0])
    out: list[list[Event]] = [[] for _ in arcs]
    for j in order:
        k = of_list[j]
        arc = arcs[k]
        if j < fitted_count:
            out[k].append(
                Arc(
                    ends[0][j],
                    ends[1][j],
                    ends[2][j],
                    1 if arc.turn > 0 else -1,
                    arc.feed,
                    arc.block,
                    arc.context,
                    arc.extra,
                    True,
                    "",
                    normals[k],
                    centre_shift=arc.centre_shift,
                )
            )
        else:
            out[k] += _line_pieces(arc, runs[j - fitted_count])
    return out
