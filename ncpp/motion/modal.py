"""What the Heidenhain and Sinumerik interpreters share.

`ModalInterpreter` holds the position, plane, units and feed, runs the event
stream (one warning and pass-through from the first out-of-scope construct
on, as the ISO interpreter does) and builds `Line` / `Arc` events; the
dialect subclasses only read their blocks.  `evaluate` computes the
expression trees both dialect builders produce (angles in degrees).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import NoReturn

from ncpp.errors import Location, NcppError, Warnings, resolve_warnings
from ncpp.motion.cutter import ToolCentre
from ncpp.motion.endless import exact
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.once import OnceRuns
from ncpp.motion.segments import DRILLED, PLANE_AXES, Arc, Context, Event, Line, Pass, Point, Setting
from ncpp.program.blocks import Block, Item

MM_PER_INCH = 25.4
RADIUS_TOLERANCE = (
    0.01  # mm: start and end radius of a centre-format arc may differ this much (controller default)
)
PLANE_OF_TOOL_AXIS = {"Z": 17, "Y": 18, "X": 19}
ROTARY = "ABC"  # the rotary axes whose words the dialects follow, in `Line.extra`'s order
MAX_HOLES = 10_000  # holes of one pattern a control computes: beyond, the counts are a mistake, not a part


class OutOfScope(Exception):
    """A construct after which the interpreter no longer knows the position.  `setting`: the offset a
    block that leaves the scope sets from where the control stands, which the writer gives a step back
    to the programmed point before it (the control stands at the corrected point)."""

    def __init__(self, reason: str, col: int | None = None, setting: Setting | None = None):
        super().__init__(reason)
        self.reason = reason
        self.col = col
        self.setting = setting


def placed_interpreting(dialect: type[ModalInterpreter]) -> Callable[..., Iterator[Event]]:
    """The `interpret` function of a one-zero dialect (Klartext, Sinumerik): its interpreter
    starts at the program zero in effect and warns where a tool length applies that nothing
    tells, when the program is placed."""

    def interpret(
        blocks: Iterable[Block],
        *,
        file: str = "<stdin>",
        warnings: Warnings | None = None,
        strict: bool = False,
        offsets: WorkOffsets | None = None,
        expand: bool = False,
        once_runs: OnceRuns | None = None,
    ) -> Iterator[Event]:
        """Motion events of a program's blocks, lazily (see the dialect module's docstring);
        `expand`: its subprograms and loops are to be written out (a dialect that can: Klartext);
        `once_runs`: given, a subprogram that runs once is followed as its run and told there, to
        be written where its text stands (a dialect that can: Klartext, `HeidenhainInterpreter`)."""
        from ncpp.motion.tools import UntoldLengths

        zero = offsets.program_zero() if offsets is not None else (0.0, 0.0, 0.0)
        interpreter = dialect(file, zero, offsets.tools if offsets is not None else None)  # type: ignore[call-arg]
        warnings = resolve_warnings(warnings, strict)
        told = offsets is None or offsets.tools is not None
        interpreter.untold_lengths = UntoldLengths(not told, warnings)  # type: ignore[attr-defined]
        interpreter.subroutine_path = offsets.subroutine_path if offsets is not None else ()
        interpreter.expand = expand
        if once_runs is not None:
            interpreter.once_runs = once_runs  # type: ignore[attr-defined]
        return interpreter.run(blocks, warnings)

    return interpret


class ModalInterpreter:
    """Position and modal state of one program run (program units throughout)."""

    # Attributes that are no state a loop's check compares (`loop_state`): fixed for the run, only
    # written or warned from, caches and counts of blocks run, the flow (its own)
    not_loop_state = frozenset(("_context", "subroutine_path", "expand", "untold_lengths", "expansion",
                                "tools", "called_blocks", "_files", "flow", "main_path",
                                "program_file", "once_runs"))  # fmt: skip

    def __init__(self, file: str = "<stdin>", zero: tuple[float, float, float] = (0.0, 0.0, 0.0)):
        self.file = file  # the file of the blocks running (a called one's, while it runs)
        self.program_file = file
        self.pos: list[float] = [0.0, 0.0, 0.0]
        self.plane = 17
        self.inch = False
        self.feed = 0.0
        self.offset: list[float] = [
            0.0,
            0.0,
            0.0,
        ]  # machine minus program position (frames, tool length), program units
        self.tool: list[float] = [
            0.0,
            0.0,
            0.0,
        ]  # the tool length offset in effect (in `offset`), program units
        self.zero: list[float] = list(
            zero
        )  # the program zero the control holds (preset, settable frame), program units
        self.tangent: tuple[float, float, float] | None = None  # direction at the end of the last move
        self.done = False
        self.left = False  # the program left the interpreter's scope (`done` too)
        self.radius_comp = False  # tool radius compensation on (G41/G42, RL/RR)
        # the radius it offsets by, positive to the left, negative to the right (0: the radius is
        # unknown); None: off, or a tool of radius 0, which stays on the path
        self.comp_side: float | None = None
        self.centre = ToolCentre()  # where the tool centre stands off the programmed path
        self.again = False  # the block runs again, or away from its text (its moves are left as programmed)
        self.tool_id = ""  # the tool in the spindle as the program names it (Context.tool_id)
        self._context: Context | None = None
        self.subroutine_path: tuple[Path, ...] = ()  # the folders of the program files it calls
        self.expand = False  # --expand: subprograms and loops written out (the dialect's own)
        # A B C where the program turned them; 0 before a word names them, as rs274ngc assumes of an
        # axis not yet positioned (the ISO reading).  Moves carry them (`Line.extra`) once a word did.
        self.rotary = [0.0, 0.0, 0.0]
        self.uses_rotary = False
        # The coordinate system turned in the working plane XY about the program zero (Klartext Cycle 10,
        # Sinumerik ROT / AROT): `Context.rotation`, moves in the turned frame (`line`, `arc`); None: unturned
        self.rotation: tuple[float, float, float] | None = None
        # The instruction that last turned or moved the frame under a rotation, until a move gives X and Y
        # absolutely (`settle_rotation`); None: settled
        self.unsettled: str | None = None

    def loop_state(self) -> tuple:
        """The state a loop that comes back to it repeats for ever with (`endless.py`), but the
        flow's: every attribute but those of `not_loop_state`, as `exact` values."""
        return tuple(exact(value) for name, value in vars(self).items() if name not in self.not_loop_state)

    def loop_quick(self) -> object:
        """A cheap part of `loop_state` (a copy, compared first): the position."""
        return self.pos[:]

    # -- the event stream -------------------------------------------------------------
    def run(self, blocks: Iterable[Block], warnings: Warnings) -> Iterator[Event]:
        for block in blocks:
            if self.done or not block.items:
                yield Pass(block)
                continue
            try:
                events = self.block(block)
            except OutOfScope as stop:
                self.leave_scope(warnings, stop.reason, block, stop.col)
                yield Pass(block)
                continue
            yield from events or (Pass(block),)

    def approached(self, events: Iterable[Event]) -> Iterator[Event]:
        """`events` with those from a compensated entry move on held while its tool centre waits for
        the next move in the plane (`ToolCentre.approach`): a move is passed on once it is told."""
        held: list[Event] = []
        for event in events:
            if held or self.centre.waiting:
                held.append(event)
                if not self.centre.waiting:
                    yield from held
                    held = []
            else:
                yield event
        yield from held

    def leave_scope(
        self, warnings: Warnings, reason: str, block: Block, col: int | None, owner: Block | None = None
    ) -> None:
        """A construct outside the scope: the state is unknown from here on (an error with strict).
        `owner`: the line that ran the block (a loop's end, a backward jump, a call), from which the
        rest passes.  In a called file, the warning stands at the calling line of the program (where
        the program passes through from) and names the place in that file."""
        self.done = self.left = True
        self.centre.waiting = []  # (an entry move waiting keeps its tool centre square to it)
        where = "this line" if owner is None else f"line {owner.line}, which runs it,"
        place = Location(self.file, *block.place(col))
        if self.file != self.program_file and owner is not None:
            reason, place = f"{reason} (at {place})", Location(self.program_file, owner.line, None)
        warnings.warn(
            f"{reason} is outside the motion interpreter's scope; from {where} on the "
            "program passes through uninterpreted (its modal state is unknown)",
            place,
        )

    def block(self, block: Block) -> list[Event]:
        raise NotImplementedError

    def radius_compensation(self, events: list[Event], turn: int | None, also: bool = True) -> list[Event]:
        """A block's events, `turn`ing tool radius compensation on to the left (+1: G41, RL) or
        the right (-1: G42, RR), off (0: G40, R0) or neither (None).  The control offsets the
        path by the tool radius (`tool_radius`): the moves from the first with it on to the
        first after it is off (which ends on its programmed point) stay the programmed contour,
        as the control's positions do, and carry where the tool centre stands (`ToolCentre`), in
        any working plane, their words absolute or incremental (the writers write an increment
        from the corrected end before it).  Left as programmed (COMP) where ncpp does not follow
        them: in a block that runs again (`again`), where the dialect's `also` is False, an entry or
        exit move that is an arc (the TNC refuses RL/RR in an arc block: TNC 640 user's manual,
        "Radius compensation"; the Sinumerik approaches and leaves the contour on a line with
        NORM: 840D sl Programming Manual Fundamentals, "Contour approach and retraction"), and a
        block that changes sides under it."""
        if turn is None and not self.radius_comp and not self.centre.off_path:
            return events
        if turn is not None:
            also = also and not (turn and self.radius_comp and self._turned(turn))
            self.radius_comp = bool(turn)
            radius = self.tool_radius() if turn else 0.0
            self.comp_side = None if radius == 0.0 else turn * (radius or 0.0)
        moves: list[Line | Arc] = [e for e in events if type(e) is Line or type(e) is Arc]
        if not moves or (self.radius_comp and self.comp_side is None):  # (radius 0: on the path)
            return events
        side = self.comp_side if self.radius_comp else None
        ends = side is None or not self.centre.off_path  # (the exit, or the entry move)
        self.centre.follow(moves, side, also and not self.again and not (ends and type(moves[0]) is Arc))
        return events

    def _turned(self, turn: int) -> bool:
        """Whether compensation on turns to the other side from the one in effect."""
        return self.comp_side is not None and (self.comp_side > 0) != (turn > 0)

    def tool_radius(self) -> float | None:
        """The radius of the tool in effect, program units, which radius compensation offsets
        by (None: not known); each dialect says where it comes from."""
        raise NotImplementedError

    # -- modal state --------------------------------------------------------------------
    def context(self, plane: int | None = None, absolute: bool = True) -> Context:
        plane = plane or self.plane
        if self._context is None or self._context.plane != plane or self._context.absolute != absolute:
            offset = as_point([z + o for z, o in zip(self.zero, self.offset)])
            tool = as_point(self.tool)
            self._context = Context(plane, absolute, False, self.inch, offset, tool, tool_id=self.tool_id,
                                    rotation=self.rotation)  # fmt: skip
        return self._context

    def set_units(self, inch: bool) -> None:
        """Switch units; the position is kept in the new program units."""
        if inch != self.inch:
            scale = 1 / MM_PER_INCH if inch else MM_PER_INCH
            self.pos = [v * scale for v in self.pos]
            self.offset = [v * scale for v in self.offset]
            self.tool = [v * scale for v in self.tool]
            self.zero = [v * scale for v in self.zero]
            self.comp_side = None if self.comp_side is None else self.comp_side * scale
            self.centre.scale(scale)
            self.inch = inch
            self._context = None

    def set_offset(self, offset: list[float]) -> None:
        """A frame moved the program origin: the same machine point gets new program coordinates."""
        self.set_frame(offset, self.rotation)

    def set_frame(self, offset: list[float], rotation: tuple[float, float, float] | None) -> None:
        """A frame moved or turned the program origin (`rotation` about the program zero): the machine stays
        where it is, its point (machine = turned program point + offset) gets new program coordinates, and
        the direction of the last move (for a tangential arc) turns with the frame."""
        before = self.context()
        held = [p + old - new for p, old, new in zip(before.turned(as_point(self.pos)), self.offset, offset)]
        # (a rotation about the zero turns a direction as it turns a point)
        tangent = None if self.tangent is None else before.turned(self.tangent)
        self.offset, self.rotation, self._context = list(offset), rotation, None
        after = self.context()
        self.pos = list(after.turned(as_point(held), -1.0))
        self.tangent = None if tangent is None else after.turned(tangent, -1.0)
        self._context = None  # (a tool length set with the offset is in the next context)

    def settle_rotation(self, absolute_xy: bool, named: Item | None) -> None:
        """A block after a rotation turned or moved the frame (`unsettled`): one that gives X and Y absolutely
        puts the tool where the turned frame says; before it, one that names X or Y otherwise (`named`, its
        first such word) is not followed: the control turns the working plane's axes once both are
        programmed (TNC 640 Cycle Programming manual, "ROTATION (Cycle 10)": "move both axes of the working
        plane to activate rotation for all axes"), and where the other axis of a one-axis move goes is not
        said."""
        if self.unsettled is None:
            return
        if absolute_xy:
            self.unsettled = None
        elif named is not None:
            why = f"after {self.unsettled} (before a move gives both absolutely)"
            raise OutOfScope(f"a move of X or Y alone, or incremental, {why}", named.start + 1)

    def set_tool(self, tool: list[float]) -> None:
        """A tool length offset (program units) takes effect: the machine's controlled point
        moves by it, so the same machine point gets new program coordinates."""
        self.set_offset([o - old + new for o, old, new in zip(self.offset, self.tool, tool)])
        self.tool = list(tool)

    def lookup(self, name: str) -> float:
        """The value of a program parameter (Q, R, DEF variable); each dialect says how."""
        raise NotImplementedError

    def value(self, expr: tuple, block: Block, item) -> float:
        """An expression's value; an unknown parameter ends interpretation (out of scope)."""
        try:
            value = evaluate(expr, self.lookup)
        except OutOfScope as stop:
            stop.col = item.start + 1
            raise
        except OverflowError:  # exp, ** past the largest float
            value = math.inf
        except ValueError as err:
            self.fail(str(err), block, item)
        if not math.isfinite(value):  # (a sum or product past the largest float too)
            self.fail("number out of range", block, item)
        return value

    def fail(self, message: str, block: Block, item=None) -> NoReturn:
        raise NcppError(
            message, Location(self.file, block.line, item.start + 1 if item is not None else None)
        )

    # -- events ---------------------------------------------------------------------------
    def drilled(
        self, block: Block, steps: Iterable[tuple[float, float | None, float]], axis: int = 2
    ) -> list[Event]:
        """A called drilling cycle's moves along the tool `axis`, each step (level, feed: None for
        a rapid, dwell s after it): left as programmed (DRILLED), placed along the axis only (the
        control runs them from where the positioning before left it); the programmed feed is kept."""
        programmed = self.feed
        events: list[Event] = []
        for level, feed, dwell in steps:
            end = list(self.pos)
            end[axis] = level
            self.feed = programmed if feed is None else feed
            line = self.line(block, end, feed is None)
            line.fixed, line.placed = DRILLED, (axis == 0, axis == 1, axis == 2)
            events.append(line)
            if dwell > 0:
                events.append(Pass(block, dwell=dwell))
        self.feed = programmed
        return events

    def rotary_end(self, given: Iterable[tuple[int, float, bool]]) -> list[float]:
        """Where a block's rotary words turn A B C to: (axis 0-2, value, incremental) each."""
        self.uses_rotary = True
        end = list(self.rotary)
        for k, value, incremental in given:
            end[k] = self.rotary[k] + value if incremental else value
        return end

    def _rotary_move(self, rotary: list[float] | None) -> tuple[tuple[float, ...], tuple[float, ...]]:
        """A move's (end, start) of A B C, turning them to `rotary` (None: they stand); none
        before a word named them."""
        if not self.uses_rotary:
            return (), ()
        start = tuple(self.rotary)
        if rotary is not None:
            self.rotary = list(rotary)
        return tuple(self.rotary), start

    def line(
        self,
        block: Block,
        end: list[float],
        rapid: bool,
        absolute: bool = True,
        rotary: list[float] | None = None,
    ) -> Line:
        """A line from the position to `end`, turning A B C to `rotary` (None: they stand)."""
        start = as_point(self.pos)
        d = [e - s for e, s in zip(end, start)]
        length = math.sqrt(sum(v * v for v in d))
        if length > 0:
            self.tangent = (d[0] / length, d[1] / length, d[2] / length)
        self.pos = list(end)
        extra, extra_start = self._rotary_move(rotary)
        context = self.context(absolute=absolute)  # (under a rotation, the points turned: `Context.turned`)
        end_point = context.turned(as_point(end))
        return Line(
            context.turned(start), end_point, rapid, self.feed, block, context, extra, extra_start=extra_start
        )

    def arc(
        self,
        block: Block,
        end: list[float],
        centre: list[float],
        turn: int,
        plane: int | None = None,
        absolute: bool = True,
    ) -> Arc:
        """An arc from the position to `end` about `centre` (its plane coordinates count)."""
        plane = plane or self.plane
        a, b, n = PLANE_AXES[plane]
        start = as_point(self.pos)
        c = list(centre)
        c[n] = start[n]
        extra, extra_start = self._rotary_move(None)  # (a dialect leaves an arc that turns them out of scope)
        context = self.context(plane, absolute)  # (under a rotation, in G17: the points turned, an arc still)
        turned = context.turned
        points = turned(start), turned(as_point(end)), turned(as_point(c))
        event = Arc(*points, turn, self.feed, block, context, extra, extra_start=extra_start)
        # tangent at the end: perpendicular to the radius, turning with the arc, plus the helix rise
        ra, rb = end[a] - c[a], end[b] - c[b]
        sign = 1.0 if turn > 0 else -1.0
        t = [0.0, 0.0, 0.0]
        t[a], t[b] = -sign * rb, sign * ra
        sweep = abs(event.sweep())
        t[n] = (end[n] - start[n]) / sweep if sweep > 0 else 0.0
        norm = math.sqrt(sum(v * v for v in t)) or 1.0
        self.tangent = (t[0] / norm, t[1] / norm, t[2] / norm)
        self.pos = list(end)
        return event

    def check_radii(
        self, block: Block, item, end: list[float], centre: list[float], plane: int | None = None
    ) -> None:
        a, b, _ = PLANE_AXES[plane or self.plane]
        r1 = math.hypot(self.pos[a] - centre[a], self.pos[b] - centre[b])
        r2 = math.hypot(end[a] - centre[a], end[b] - centre[b])
        tolerance = RADIUS_TOLERANCE / (MM_PER_INCH if self.inch else 1.0)
        if r1 < tolerance or r2 < tolerance:
            self.fail("zero-radius arc", block, item)
        if abs(r1 - r2) > max(tolerance, 1e-3 * max(r1, r2)):
            self.fail(
                f"radius to the end of the arc ({r2:.4f}) differs from the radius to its start ({r1:.4f})",
                block,
                item,
            )

    def centre_from_radius(
        self, block: Block, item, end: list[float], radius: float, clockwise: bool
    ) -> list[float]:
        """The centre of an arc of signed radius (negative: more than a half circle), as G2/G3 R."""
        a, b, _ = PLANE_AXES[self.plane]
        x0, y0, x1, y1 = self.pos[a], self.pos[b], end[a], end[b]
        if x0 == x1 and y0 == y1:
            self.fail("the start point of the arc is its end point", block, item)
        r = abs(radius)
        mx, my = (x0 + x1) / 2, (y0 + y1) / 2
        half = math.hypot(x1 - mx, y1 - my)
        tolerance = RADIUS_TOLERANCE / (MM_PER_INCH if self.inch else 1.0)
        if half - r > tolerance:
            self.fail("arc radius too small to reach the end point", block, item)
        half = min(half, r)
        direction = math.atan2(y1 - y0, x1 - x0)
        theta = direction - math.pi / 2 if clockwise == (radius > 0) else direction + math.pi / 2
        offset = math.sqrt(max(r * r - half * half, 0.0))
        centre = list(self.pos)
        centre[a], centre[b] = mx + offset * math.cos(theta), my + offset * math.sin(theta)
        return centre

    def tangential(self, block: Block, end: list[float], absolute: bool = True) -> Line | Arc:
        """The arc from the position to `end` tangent to the last move (a line when they are in line)."""
        a, b, _ = PLANE_AXES[self.plane]
        if self.tangent is None:
            raise OutOfScope("a tangential arc with no previous move", None)
        ta, tb = self.tangent[a], self.tangent[b]
        norm = math.hypot(ta, tb)
        if norm < 1e-12:
            raise OutOfScope("a tangential arc after a move along the tool axis", None)
        ta, tb = ta / norm, tb / norm
        da, db = end[a] - self.pos[a], end[b] - self.pos[b]
        across = -tb * da + ta * db  # component of the chord along the left normal
        if abs(across) < 1e-9 * max(1.0, math.hypot(da, db)):
            return self.line(block, end, False, absolute)
        s = (da * da + db * db) / (2 * across)  # signed distance of the centre along the left normal
        centre = list(self.pos)
        centre[a], centre[b] = self.pos[a] - tb * s, self.pos[b] + ta * s
        return self.arc(block, end, centre, 1 if s > 0 else -1, absolute=absolute)


def as_point(values: Sequence[float]) -> Point:
    """An x, y, z list (the interpreter's working positions) as the point an event holds."""
    return (values[0], values[1], values[2])


def plane_of(points: Sequence[Sequence[float]]) -> int | None:
    """The principal plane (17, 18, 19) containing all points, if any (a shared normal coordinate)."""
    for plane, (_, _, n) in PLANE_AXES.items():
        if max(p[n] for p in points) - min(p[n] for p in points) < 1e-9:
            return plane
    return None


def circle_through(
    p0: Sequence[float], p1: Sequence[float], p2: Sequence[float], plane: int
) -> tuple[list[float], int] | None:
    """Centre and turn (+1 counter-clockwise) of the arc from p0 through p1 to p2 in `plane`."""
    a, b, _ = PLANE_AXES[plane]
    ax, ay, bx, by, cx, cy = p0[a], p0[b], p1[a], p1[b], p2[a], p2[b]
    d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
    if abs(d) < 1e-12:
        return None
    ux = (
        (ax * ax + ay * ay) * (by - cy) + (bx * bx + by * by) * (cy - ay) + (cx * cx + cy * cy) * (ay - by)
    ) / d
    uy = (
        (ax * ax + ay * ay) * (cx - bx) + (bx * bx + by * by) * (ax - cx) + (cx * cx + cy * cy) * (bx - ax)
    ) / d
    centre = list(p0)
    centre[a], centre[b] = ux, uy
    # the turn that passes the intermediate point: the sign of the triangle's orientation
    turn = 1 if (bx - ax) * (cy - ay) - (by - ay) * (cx - ax) > 0 else -1
    return centre, turn


# ---- expressions --------------------------------------------------------------------------


def _div(a: float, b: float) -> float:
    return float(math.trunc(a / b))


def _power(a: float, b: float) -> float:
    """`a ^ b` as a real number: a negative base to a fractional power has none."""
    if a < 0.0 and b != math.floor(b):
        raise ValueError("negative number to a non-integer power")
    return math.pow(a, b)


_BINARY: dict[str, Callable[[float, float], float]] = {
    "+": lambda a, b: a + b, "-": lambda a, b: a - b, "*": lambda a, b: a * b, "/": lambda a, b: a / b,
    "**": _power, "DIV": _div, "MOD": math.fmod,
    "==": lambda a, b: float(a == b), "<>": lambda a, b: float(a != b), "<": lambda a, b: float(a < b),
    ">": lambda a, b: float(a > b), "<=": lambda a, b: float(a <= b), ">=": lambda a, b: float(a >= b),
    "AND": lambda a, b: float(bool(a) and bool(b)), "OR": lambda a, b: float(bool(a) or bool(b)),
    "XOR": lambda a, b: float(bool(a) != bool(b)),
    "B_AND": lambda a, b: float(int(a) & int(b)), "B_OR": lambda a, b: float(int(a) | int(b)),
    "B_XOR": lambda a, b: float(int(a) ^ int(b)),
}  # fmt: skip
_DEG = math.pi / 180
_FUNCTIONS: dict[str, Callable[..., float]] = {
    "SIN": lambda x: math.sin(x * _DEG), "COS": lambda x: math.cos(x * _DEG), "TAN": lambda x: math.tan(x * _DEG),
    "ASIN": lambda x: math.asin(x) / _DEG, "ACOS": lambda x: math.acos(x) / _DEG, "ATAN": lambda x: math.atan(x) / _DEG,
    "ATAN2": lambda y, x: math.atan2(y, x) / _DEG, "SQRT": math.sqrt, "POT": lambda x: x * x, "SQ": lambda x: x * x,
    "ABS": abs, "TRUNC": lambda x: float(math.trunc(x)), "INT": lambda x: float(math.trunc(x)),
    "FRAC": lambda x: x - math.trunc(x), "ROUND": lambda x: float(math.floor(x + 0.5)), "LN": math.log,
    "LOG": math.log10, "EXP": math.exp, "NEG": lambda x: -x, "SGN": lambda x: float((x > 0) - (x < 0)),
    "MINVAL": min, "MAXVAL": max,
}  # fmt: skip
# Functions of other than one argument (Siemens, Programming Manual Job Planning: ATAN2(y, x),
# MINVAL(a, b), MAXVAL(a, b))
_ARITY = {"ATAN2": 2, "MINVAL": 2, "MAXVAL": 2}


def evaluate(expr: tuple, lookup: Callable[[str], float]) -> float:
    """The value of an expression tree (`("num", v)`, `("param", name)`, `("bin", op, a, b)` ...).

    `lookup(name)` gives a variable's value or raises OutOfScope; anything
    this evaluator does not know (arrays, strings, system functions) is out
    of scope, a division by zero an NcppError-worthy ValueError.
    """
    kind = expr[0]
    if kind == "num":
        return expr[1]
    if kind == "param":
        return lookup(expr[1])
    if kind == "neg":
        return -evaluate(expr[1], lookup)
    if kind == "not":
        return float(not evaluate(expr[1], lookup))
    if kind == "bin":
        op = _BINARY.get(expr[1])
        if op is None:
            raise OutOfScope(f"the operator {expr[1]}")
        try:
            return op(evaluate(expr[2], lookup), evaluate(expr[3], lookup))
        except ZeroDivisionError:
            raise ValueError("division by zero") from None
    if kind == "call":
        function = _FUNCTIONS.get(expr[1])
        if function is None:
            raise OutOfScope(f"the function {expr[1]}")
        wanted, given = _ARITY.get(expr[1], 1), len(expr) - 2
        if given != wanted:
            raise ValueError(f"{expr[1]} takes {wanted} argument{'s' * (wanted > 1)}, not {given}")
        try:
            return float(function(*(evaluate(arg, lookup) for arg in expr[2:])))
        except ValueError:  # math's domain error
            raise ValueError(f"{expr[1]} of a value outside its domain") from None
    raise OutOfScope(f"the expression {kind!r}")
