"""Corner rounding and chamfers between two lines (Fanuc `,R`/`,C`, Klartext `RND`/`CHF`).

`round_corner` is pure geometry on events: both interpreters decide the
scope (arcs, rapids) and turn a `CornerError` into an error at their own
location.
"""

from __future__ import annotations

import math
from dataclasses import replace

from ncpp.motion.segments import PLANE_AXES, Arc, Event, Line, Point
from ncpp.program.blocks import Block

TINY = 1e-12


class CornerError(ValueError):
    """A corner that cannot be made (out of plane, zero-length move, too large)."""


def round_corner(
    first: Line, second: Line, kind: str, size: float, block: Block | None = None, feed: float | None = None
) -> list[Event]:
    """[first shortened, fillet arc (kind 'R') or chamfer line (kind 'C'), second from the tangent point].

    `size` is the fillet radius or the chamfer's leg along each line; the
    corner piece belongs to `block` (default: the first line's) and runs at
    `feed` (default: the first line's).  Lines straight on (or back) give no
    corner: [first, second] unchanged.
    """
    i, j, k = PLANE_AXES[first.context.plane]
    if abs(first.end[k] - first.start[k]) > TINY or abs(second.end[k] - second.start[k]) > TINY:
        raise CornerError("corner rounding/chamfer needs both moves in the active plane")
    u = (first.end[i] - first.start[i], first.end[j] - first.start[j])
    v = (second.end[i] - second.start[i], second.end[j] - second.start[j])
    lu, lv = math.hypot(*u), math.hypot(*v)
    if lu < TINY or lv < TINY:
        raise CornerError("corner rounding/chamfer next to a zero-length move")
    u, v = (u[0] / lu, u[1] / lu), (v[0] / lv, v[1] / lv)
    cross, dot = u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1]
    if abs(cross) < 1e-9:  # straight on (or back): no corner to round
        return [first, second]
    turn = math.atan2(abs(cross), dot)  # direction change, 0..pi
    distance = size if kind == "C" else size * math.tan(turn / 2)
    if distance > lu + TINY or distance > lv + TINY:
        raise CornerError(
            f"corner {'chamfer' if kind == 'C' else 'radius'} {size:g} does not fit between the moves"
        )
    corner = first.end
    start = _in_plane(corner, i, j, corner[i] - distance * u[0], corner[j] - distance * u[1])
    end = _in_plane(corner, i, j, corner[i] + distance * v[0], corner[j] + distance * v[1])
    piece_block = first.block if block is None else block
    piece_feed = first.feed if feed is None else feed
    if kind == "C":
        piece: Event = replace(first, start=start, end=end, block=piece_block, feed=piece_feed)
    else:
        side = 1.0 if cross > 0 else -1.0  # the centre lies on the inside of the turn
        centre = _in_plane(start, i, j, start[i] - side * size * u[1], start[j] + side * size * u[0])
        turn = 1 if cross > 0 else -1
        piece = Arc(start, end, centre, turn, piece_feed, piece_block, first.context, first.extra)
    return [replace(first, end=start), piece, replace(second, start=end)]


def _in_plane(p: Point, i: int, j: int, a: float, b: float) -> Point:
    """`p` with its coordinates i and j (the plane's) set to a and b."""
    q = list(p)
    q[i], q[j] = a, b
    return (q[0], q[1], q[2])
