"""The path the tool centre takes under cutter compensation, as the control joins the offset moves.

The interpreter gives each move it follows under compensation where the tool centre stands off
its programmed start and end (`Line.centre_shift`, `ncpp.motion.cutter`): the start where the
move before left it, the end square to the move's own direction there.  Between two moves the
control joins the offset paths: at an outside corner by an arc about the programmed corner, at
an inside one by cutting both back to where they cross (LinuxCNC's interpreter, and the TNC's
and the 840D's default G450: TNC 640 user's manual, "Radius compensation: Machining corners";
840D sl Programming Manual Fundamentals, "Corner behavior: G450, G451").  `CentrePath` makes
that path of a stream of moves, a move at a time: what the verifier compares, so that a written
program whose contour lies near the input's but turns a short move round (and with it the tool
centre by up to twice the radius) is told apart.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, replace

from ncpp.motion.segments import PLANE_AXES, Arc, Event, Line, Point

Flat = tuple[float, float]  # a point or a direction in the plane's own axes (u, v)
# program units: offsets closer than this meet without a corner (the rounding of a written number)
SMOOTH = 1e-7
# radians: within this of straight on the control makes no corner, and within it of a half turn tells an
# outside corner from an inside one by the arc turned back along (rs274ngc's TOLERANCE_CONCAVE_CORNER)
TURNED = 0.05


@dataclass(frozen=True)
class Corner:
    """An outside corner's arc about the programmed corner, from `start` to `end`."""

    start: Point
    end: Point
    centre: Point
    turn: int  # +1 counter-clockwise in the plane's (u, v), -1 clockwise


@dataclass(frozen=True)
class OnCentre:
    """A move's tool-centre start and end, the corner before it (None: the offsets meet there or
    are cut back to their crossing), and where the move before now ends in the plane (None: where it
    did; `cut_back_moves`); `standing`: the move runs along the plane's normal alone, the tool standing
    where the move before left it, whose corner with the next move in the plane it leaves open."""

    start: Point
    end: Point
    corner: Corner | None = None
    cut_back: Point | None = None
    standing: bool = False


@dataclass(frozen=True)
class _Offset:
    """A move's tool-centre path in its plane: a line through `point` along `leaving`, or
    (`radius` set) a circle about `point`; `length` how far it runs, `leaving` its direction at
    its end."""

    point: Flat
    leaving: Flat
    radius: float | None = None
    length: float = 0.0


class CentrePath:
    """The tool-centre path of the moves given it one after another (`along`): `last` is the
    offset of the move given last, which the next may cut back at an inside corner."""

    def __init__(self) -> None:
        self.last: tuple[_Offset, int] | None = None  # the last move's offset and its plane

    def along(self, move: Line | Arc, before_is_last: bool) -> OnCentre:
        """Where the tool centre runs for `move` (its `centre_shift` set); `before_is_last`: the
        move given last is the one just before it (else an inside corner is not cut back)."""
        shifts = move.centre_shift
        assert shifts is not None
        at_start, at_end = shifts
        plane = move.context.plane
        a, b, normal = PLANE_AXES[plane]
        end = _plus(move.end, at_end)
        last, self.last = self.last, None
        # (an offset off the plane: the move before ran in another plane, which the control does not join)
        if at_start is None or not _in_plane(move, a, b) or abs(at_start[normal]) > SMOOTH:
            start = move.start if at_start is None else _plus(move.start, at_start)
            if at_start is None and type(move) is Line and _in_plane(move, a, b):  # (an entry line)
                self.last = (_offset(move, end, a, b), plane)
            if at_start is None or _in_plane(move, a, b) or abs(at_start[normal]) > SMOOTH:
                return OnCentre(start, end)
            # (rs274ngc holds such moves with the one before, and moves them all to an inside corner's
            # crossing)
            self.last = last if before_is_last else None
            return OnCentre(start, end, standing=True)
        own = _own_start_shift(move, at_end, a, b)
        exits = math.hypot(at_end[a], at_end[b]) <= SMOOTH  # (after G40: it ends on its programmed point)
        start = _plus(move.start, at_start if exits else own)
        self.last = (_offset(move, end, a, b), plane)
        gap = (own[a] - at_start[a], own[b] - at_start[b])
        if exits or math.hypot(*gap) <= SMOOTH:
            return OnCentre(start, end)
        before = _plus(move.start, at_start)
        tangent = _tangent(move, a, b)
        away = _turned_away((at_start[a], at_start[b]), (own[a], own[b]), tangent)
        if abs(away) <= TURNED:  # (near straight on, no corner: the move starts where the tool stands)
            return OnCentre(before, end)
        previous = last[0] if before_is_last and last is not None and last[1] == plane else None
        if _outside(away, (at_start[a], at_start[b]), (own[a], own[b]), move, previous, a, b):
            # (round the corner, away from the tool)
            turn = -1 if _on_the_left(tangent, (own[a], own[b])) else 1
            return OnCentre(start, end, Corner(before, start, move.start, turn))
        if previous is None:
            return OnCentre(start, end)
        crossing = _crossing(previous, self.last[0], (before[a], before[b]), (start[a], start[b]), tangent)
        if crossing is None:  # (they do not cross within the move before: the control reports a gouge)
            return OnCentre(start, end)
        met = list(start)
        met[a], met[b] = crossing
        return OnCentre((met[0], met[1], met[2]), end, cut_back=(met[0], met[1], met[2]))


def on_centre(events: Iterable[Event]) -> Iterator[Event]:
    """The events with each move that compensation follows under cutter compensation (its
    `centre_shift` set) where the tool centre runs, as rs274 prints it: from where the tool stands to
    its tool-centre end, an outside corner's arc before it, the moves before cut back to an inside
    corner (held, with the events after them, until the next move in the plane tells)."""
    path = CentrePath()
    # the last move on the path in the plane, the moves standing after it, the events between
    held: list[Event] = []
    for event in events:
        if type(event) is not Line and type(event) is not Arc:
            if held:
                held.append(event)
            else:
                yield event
            continue
        on = path.along(event, bool(held)) if event.centre_shift is not None else None
        if on is not None and on.standing and held:
            held.append(replace(event, start=on.start, end=on.end))
            continue
        if on is not None and on.cut_back is not None:
            held = cut_back_moves(held, on.cut_back, event.context.plane)
        yield from held
        held = []
        if on is None:
            yield event
            continue
        if on.corner is not None:
            corner = on.corner
            yield Arc(corner.start, corner.end, corner.centre, corner.turn, event.feed, event.block,
                      event.context, event.extra)  # fmt: skip
        held = [replace(event, start=on.start, end=on.end)]
    yield from held


def cut_back_moves(moves: list[Event], to: Point, plane: int) -> list[Event]:
    """`moves` (the last on the path in the plane first, then those standing after it, and other
    events) moved to an inside corner's crossing `to` in the plane: the first's end, the others'
    start and end; along the plane's normal each keeps its own."""
    a, b, _ = PLANE_AXES[plane]

    def there(p: Point) -> Point:
        q = list(p)
        q[a], q[b] = to[a], to[b]
        return (q[0], q[1], q[2])

    out: list[Event] = []
    for k, event in enumerate(moves):
        if type(event) is Line or type(event) is Arc:
            start = event.start if k == 0 else there(event.start)  # (the first: only its end)
            event = replace(event, start=start, end=there(event.end))
        out.append(event)
    return out


def turns_back_inside(arc: Arc, before: Point, own: Point) -> bool:
    """Whether the path turns right back onto `arc` at an inside corner (a cusp, the tool outside the
    arc: `_outside`), where the control cuts the move before back to a crossing far along the arc
    (`before`: where the move before left the tool centre off the arc's start, `own`: the arc's own
    offset there, on the other side of the contour)."""
    a, b, _ = PLANE_AXES[arc.context.plane]
    came, mine = (before[a], before[b]), (own[a], own[b])
    away = _turned_away(came, mine, _tangent(arc, a, b))
    return abs(away - math.pi) <= TURNED and not _outside(away, came, mine, arc, None, a, b)


def _turned_away(before: Flat, own: Flat, tangent: Flat) -> float:
    """The angle the path turns away from the tool's side at the corner before a move (radians,
    -90 to 270 degrees, as rs274ngc's convert_straight_comp2 and convert_arc_comp2 measure it):
    `before` the offset the move before left, `own` the move's own offset at its start,
    `tangent` its direction there."""
    left = _on_the_left(tangent, own)
    came = (before[1], -before[0]) if left else (-before[1], before[0])  # the move before's direction
    turned = math.atan2(
        came[0] * tangent[1] - came[1] * tangent[0], came[0] * tangent[0] + came[1] * tangent[1]
    )
    away = -turned if left else turned
    return away + 2 * math.pi if away < -math.pi / 2 else away


def _outside(away: float, before: Flat, own: Flat, move: Line | Arc, previous: _Offset | None, a: int,
             b: int) -> bool:  # fmt: skip
    """Whether the corner before `move` is an outside one, as rs274ngc tells it from the angle the
    path turns `away` from the tool's side (more than TURNED: `_turned_away`): an inside one where
    it turns towards the tool, or away by more than a half turn and TURNED; within TURNED of a half
    turn (a cusp) an inside one where the tool runs outside the arc the path turns back along (the
    move's, or for a line the one before), else an outside one."""
    if away < -TURNED or away > math.pi + TURNED:
        return False
    if away > math.pi - TURNED:
        if type(move) is Arc:  # (the tool inside it: it bends towards its centre)
            return own[0] * (move.center[a] - move.start[a]) + own[1] * (move.center[b] - move.start[b]) > 0.0
        if previous is not None and previous.radius is not None:
            corner = (move.start[a], move.start[b])
            return (
                before[0] * (previous.point[0] - corner[0]) + before[1] * (previous.point[1] - corner[1])
                > 0.0
            )
    return True


def _plus(p: Point, q: Point) -> Point:
    return (p[0] + q[0], p[1] + q[1], p[2] + q[2])


def _in_plane(move: Line | Arc, a: int, b: int) -> bool:
    """Whether the move moves in the plane: an arc does (a full circle too), a line along its normal not."""
    return type(move) is Arc or move.start[a] != move.end[a] or move.start[b] != move.end[b]


def _own_start_shift(move: Line | Arc, at_end: Point, a: int, b: int) -> Point:
    """The tool centre minus the programmed point at the move's start, square to the move there:
    a line's is its end's; an arc's is radial, by its end's signed distance off the arc."""
    if type(move) is not Arc:
        return at_end
    c = move.center
    eu, ev = move.end[a] - c[a], move.end[b] - c[b]
    su, sv = move.start[a] - c[a], move.start[b] - c[b]
    towards = (at_end[a] * eu + at_end[b] * ev) / math.hypot(eu, ev)
    radial = towards / math.hypot(su, sv)
    shift = [0.0, 0.0, 0.0]
    shift[a], shift[b] = su * radial, sv * radial
    return (shift[0], shift[1], shift[2])


def _tangent(move: Line | Arc, a: int, b: int, at_end: bool = False) -> Flat:
    """The move's unit direction in the plane at its start (at its end: `at_end`)."""
    if type(move) is Arc:
        point = move.end if at_end else move.start
        u, v = point[a] - move.center[a], point[b] - move.center[b]
        r = math.hypot(u, v) * (1.0 if move.turn > 0 else -1.0)
        return (-v / r, u / r)
    u, v = move.end[a] - move.start[a], move.end[b] - move.start[b]
    n = math.hypot(u, v)
    return (u / n, v / n)


def _on_the_left(tangent: Flat, offset: Flat) -> bool:
    """Whether the tool centre stands left of the move (its `offset` from the programmed point)."""
    return tangent[0] * offset[1] - tangent[1] * offset[0] > 0.0


def _offset(move: Line | Arc, end: Point, a: int, b: int) -> _Offset:
    """The move's tool-centre path in the plane, through its tool-centre `end`: a line along the
    move's own direction (also an entry's, which the control cuts back so), or its arc's circle."""
    if type(move) is Arc:
        centre = (move.center[a], move.center[b])
        radius = math.hypot(end[a] - centre[0], end[b] - centre[1])
        return _Offset(centre, _tangent(move, a, b, at_end=True), radius, radius * _swept(move, a, b))
    length = math.hypot(move.end[a] - move.start[a], move.end[b] - move.start[b])
    return _Offset((end[a], end[b]), _tangent(move, a, b), None, length)


def _swept(move: Arc, a: int, b: int) -> float:
    """The angle an arc turns through (radians, positive)."""
    c = move.center
    begin = math.atan2(move.start[b] - c[b], move.start[a] - c[a])
    finish = math.atan2(move.end[b] - c[b], move.end[a] - c[a])
    part = ((finish - begin) if move.turn > 0 else (begin - finish)) % (2 * math.pi)
    return part + 2 * math.pi * (abs(move.turn) - 1)


def _crossing(first: _Offset, second: _Offset, ends: Flat, starts: Flat, onwards: Flat) -> Flat | None:
    """Where two moves' offsets cross at an inside corner (`ends`: the first's tool-centre end,
    `starts`: the second's start, `onwards`: its direction there): the crossing nearest the
    corner back along the first, within its length, and on along the second, and about where the
    offsets' tangents there cross (arcs nearly tangent to one another may cross only far off, or not
    at all).  Past the second's end too: rs274ngc checks the move it cuts back, not the next, which
    then runs back from the crossing to its end (a line back along itself, an arc nearly round)."""
    crossings = [
        p for p in _meet(first, second)
        if _dot(p, ends, first.leaving) <= SMOOTH and _dot(p, starts, onwards) >= -SMOOTH
    ]  # fmt: skip
    near = ((ends[0] + starts[0]) / 2, (ends[1] + starts[1]) / 2)
    best = min(crossings, key=lambda p: math.dist(p, near), default=None)
    if best is None or math.dist(best, ends) > first.length:
        return None
    tangents = _meet(_Offset(ends, first.leaving), _Offset(starts, onwards))
    if tangents:  # (none: the moves turn right back, and the arcs' crossing is the corner's)
        reach = 2 * max(math.dist(tangents[0], ends), math.dist(tangents[0], starts)) + SMOOTH
        if max(math.dist(best, ends), math.dist(best, starts)) > reach:
            return None
    return best


def _dot(point: Flat, origin: Flat, direction: Flat) -> float:
    """How far `point` lies from `origin` along `direction`."""
    return (point[0] - origin[0]) * direction[0] + (point[1] - origin[1]) * direction[1]


def _meet(first: _Offset, second: _Offset) -> list[Flat]:
    """The points where two offsets (lines or circles) cross."""
    if first.radius is None and second.radius is None:
        (p, d), (q, e) = (first.point, first.leaving), (second.point, second.leaving)
        det = d[0] * e[1] - d[1] * e[0]
        if abs(det) <= 1e-12:
            return []
        t = ((q[0] - p[0]) * e[1] - (q[1] - p[1]) * e[0]) / det
        return [(p[0] + t * d[0], p[1] + t * d[1])]
    if first.radius is None or second.radius is None:
        line, circle = (first, second) if first.radius is None else (second, first)
        return _line_meets_circle(line.point, line.leaving, circle.point, circle.radius or 0.0)
    return _circles_meet(first.point, first.radius, second.point, second.radius)


def _line_meets_circle(p: Flat, d: Flat, c: Flat, r: float) -> list[Flat]:
    fu, fv = p[0] - c[0], p[1] - c[1]
    half_b = fu * d[0] + fv * d[1]
    disc = half_b * half_b - (fu * fu + fv * fv - r * r)
    if disc < 0.0:
        return []
    root = math.sqrt(disc)
    return [(p[0] + t * d[0], p[1] + t * d[1]) for t in (-half_b - root, -half_b + root)]


def _circles_meet(c0: Flat, r0: float, c1: Flat, r1: float) -> list[Flat]:
    apart = math.dist(c0, c1)
    if apart <= 1e-12 or apart > r0 + r1 or apart < abs(r0 - r1):
        return []
    along = (r0 * r0 - r1 * r1 + apart * apart) / (2 * apart)
    height = math.sqrt(max(r0 * r0 - along * along, 0.0))
    du, dv = (c1[0] - c0[0]) / apart, (c1[1] - c0[1]) / apart
    mu, mv = c0[0] + along * du, c0[1] + along * dv
    return [(mu - height * dv, mv + height * du), (mu + height * dv, mv - height * du)]
