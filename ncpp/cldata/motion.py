"""CL records -> motion events (`Line`, `Arc`, `Pass`), the same events the NC
interpreter makes, so that the compensation passes and writers serve both.

APT semantics used here:
* `RAPID` makes the next motion a rapid traverse only (it is not modal).
* `CIRCLE/ x,y,z, i,j,k, r [, ...]` (Creo: 7 values; NX: 11, the extra
  four are tolerance and tool data; SolidWorks CAM: 6, no radius, the tool
  being on the circle already) announces that the following `GOTO`s run
  on the circle with centre (x,y,z) around axis (i,j,k), turning by the right
  hand rule about that axis (Creo, "CL Output for Circular Interpolation"), or,
  in NX's 11-value form, clockwise about it: NX CLSF files turn every arc by at
  most a half turn that way, by the right-hand rule by more.  Consecutive `GOTO`s
  that stay on the circle and go on in its direction are one arc (CAM systems
  split arcs at quadrants); the first `GOTO` off it, or back against it, is a
  line again.  Axis must be ±X, ±Y or ±Z (planes G19, G18, G17).
* `MULTAX` + `GOTO/ x,y,z,i,j,k`: a tool vector.  A 3-axis machine can follow
  it only while it stays constant; a changing vector is refused.
* `GOHOME` returns to the `FROM` point (rapid); `GOHOME/Z` moves Z only;
  `GOHOME/x,y,z` (NX) names the home point itself.
* Motion this module does not model (`NURBS/` splines, `GODLTA/`, ...) is refused:
  passed through as a comment, its move would be missing from the program.
* Under `CYCLE/DRILL` (and the other cycles of `ncpp.cldata.cycles`) a `GOTO` is a
  hole's top: its moves are the canned cycle's, marked `fixed` (compensation leaves
  them as programmed, as the NC interpreter's); `CYCLE/OFF` ends the cycle.
* Between `CUTCOM/LEFT|RIGHT` and `CUTCOM/OFF` the control offsets the path by the
  tool radius: the moves are marked `fixed` too.
* SolidWorks CAM's `CSYS/` other than the identity (a setup turned or moved: its tool vector
  and GOTO points are the part's, aamorim1913/AptPostProcessor `parts-2022/shimemcunha.apt`) is
  refused: the points would be posted untransformed.

Each event's block is a synthetic `Block` holding the record text (no
items), so a writer can show it as a comment and errors can name its line.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Sequence

from ncpp.cldata.cycles import Driller, HoleBlock, parse_cycle
from ncpp.cldata.reader import Record
from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import COMP, CYCLE, PLANE_AXES, Arc, Context, Event, Line, Pass, Point, replace
from ncpp.program.blocks import Block

ON_CIRCLE_TOL = 1e-3  # mm (or inch): GOTO within this of the circle lies on it
NX_CIRCLE_VALUES = 11  # NX: centre, axis, radius, tolerance, and three of tool data
VECTOR_TOL = 1e-6  # tool vector components: "constant"
AXIS_TOL = 1e-6


def units_inch(record: Record) -> bool:
    """UNITS/INCHES (or INCH) or UNITS/MM; any other unit is refused: posted as mm, it
    would cut the part at the wrong size."""
    unit = record.words[0] if record.words else ""
    if unit.startswith("INCH"):
        return True
    if unit in ("MM", "MILLIMETERS", "MILLIMETRES"):
        return False
    raise NcppError(f"UNITS/{unit or '?'}: expected MM or INCHES", record.where)


def _identity_frame(values: Sequence[float]) -> bool:
    """Whether SolidWorks CAM's `CSYS/` 3x4 matrix (rotation rows, each with its translation) leaves
    the GOTO points where they are."""
    identity = (1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    return len(values) == len(identity) and all(abs(v - w) <= AXIS_TOL for v, w in zip(values, identity))


def _block(record: Record) -> Block:
    return Block(raw=record.text, eol="\n", items=(), line=record.line)


def _plane(axis: Sequence[float], record: Record) -> tuple[int, int]:
    """(G17/18/19, rotation sign) of a CIRCLE axis vector."""
    norm = math.sqrt(sum(a * a for a in axis))
    if norm == 0:
        raise NcppError("CIRCLE axis vector is zero", record.where)
    unit = [a / norm for a in axis]
    for plane, index in ((17, 2), (18, 1), (19, 0)):
        if abs(abs(unit[index]) - 1.0) < AXIS_TOL:
            return plane, (1 if unit[index] > 0 else -1)
    raise NcppError(
        f"CIRCLE axis ({axis[0]:g}, {axis[1]:g}, {axis[2]:g}) is not along X, Y or Z; "
        "only arcs in the XY, XZ and YZ planes can be posted",
        record.where,
    )


class _Circle:
    """A CIRCLE record waiting for the GOTOs that run on it."""

    def __init__(self, record: Record, start: Point):
        values = record.numbers
        if record.words:  # NX's TIMES, n (turns of a helix), ...: the arc would be guessed
            raise NcppError(f"CIRCLE with {', '.join(record.words)}: ncpp posts a CIRCLE of numbers only "
                            "(centre, axis, radius, ...)", record.where)  # fmt: skip
        if len(values) < 6:
            raise NcppError(
                f"CIRCLE needs centre and axis (6 values) and the radius, got {len(values)}", record.where
            )
        self.record = record
        self.plane, self.sign = _plane(values[3:6], record)
        if len(values) == NX_CIRCLE_VALUES:
            self.sign = -self.sign  # NX turns clockwise about the axis it writes
        self.i, self.j, self.n = PLANE_AXES[self.plane]
        c = list(_position(record, values))
        c[self.n] = start[self.n]  # Arc.center carries the start's normal coordinate
        self.center: Point = (c[0], c[1], c[2])
        self.start = start
        r0 = self._in_plane_radius(start)
        self.radius = values[6] if len(values) > 6 else r0  # without a radius: the tool is on the circle
        if abs(r0 - self.radius) > ON_CIRCLE_TOL:
            raise NcppError(
                f"the tool ({start[0]:g}, {start[1]:g}, {start[2]:g}) is {r0:.4f} from the CIRCLE centre, "
                f"not on its radius {self.radius:.4f}",
                record.where,
            )
        self.points: list[Point] = []
        self.sweep = 0.0

    def _in_plane_radius(self, p: Point) -> float:
        return math.hypot(p[self.i] - self.center[self.i], p[self.j] - self.center[self.j])

    def _angle(self, p: Point) -> float:
        return math.atan2(p[self.j] - self.center[self.j], p[self.i] - self.center[self.i])

    def takes(self, p: Point) -> bool:
        """Does p continue the arc?  The first GOTO always ends it (it may be a helix)."""
        if not self.points:
            return True
        last = self.points[-1]
        flat = (
            abs(p[self.n] - last[self.n]) <= ON_CIRCLE_TOL
            and abs(last[self.n] - self.start[self.n]) <= ON_CIRCLE_TOL
        )
        on_circle = abs(self._in_plane_radius(p) - self.radius) <= ON_CIRCLE_TOL
        return flat and on_circle and self._step(last, p) <= math.pi  # (a step back is a line)

    def _step(self, a: Point, b: Point) -> float:
        """The angle from a to b turning the circle's way, in [0, 2 pi)."""
        return (self.sign * (self._angle(b) - self._angle(a))) % (2 * math.pi)

    def add(self, p: Point, record: Record) -> None:
        if not self.points and abs(self._in_plane_radius(p) - self.radius) > ON_CIRCLE_TOL:
            raise NcppError(
                f"the GOTO after CIRCLE is {self._in_plane_radius(p):.4f} from the centre, not on radius {self.radius:.4f}",
                record.where,
            )
        prev = self.points[-1] if self.points else self.start
        step = self._step(prev, p)
        if step <= 1e-12 and not self.points:
            step = 2 * math.pi  # the first GOTO back where the arc starts: a full turn
        self.sweep += step
        self.points.append(p)

    def arc(self, feed: float, context: Context, fixed: str = "") -> Arc:
        turns = 1 + int((self.sweep - 1e-9) // (2 * math.pi))
        return Arc(
            start=self.start,
            end=self.points[-1],
            center=self.center,
            turn=self.sign * turns,
            feed=feed,
            block=_block(self.record),
            context=replace(context, plane=self.plane),
            fixed=fixed,
        )


# The largest number an NC word holds (Fanuc and LinuxCNC: up to 8 digits before the point)
MAX_WORD = 99_999_999.0


def feed_rate(rec: Record) -> float:
    """FEDRAT/f: a feed above 0 (a control reads a negative F word otherwise; 0 stops no move)."""
    f = rec.numbers[0]
    if not 0 < f <= MAX_WORD:
        raise NcppError(
            f"{rec.major}: expected a feed rate above 0 and at most {MAX_WORD:,.0f}, got {f:g}", rec.where
        )
    return f


def _position(rec: Record, values: Sequence[float]) -> Point:
    """The record's x, y, z: numbers an NC word can hold (GOTO / 1e308 would be 309 digits)."""
    x, y, z = values[:3]
    if not max(abs(x), abs(y), abs(z)) <= MAX_WORD:
        raise NcppError(
            f"{rec.major}: a coordinate beyond ±{MAX_WORD:,.0f}, what an NC word holds: {x:g}, {y:g}, {z:g}",
            rec.where,
        )
    return (x, y, z)


def _unit(vector: tuple[float, ...]) -> tuple[float, ...]:
    """The tool vector's direction (CL data need not give a unit vector); zero stays zero."""
    length = math.sqrt(sum(v * v for v in vector))
    return tuple(v / length for v in vector) if length > 0 else tuple(vector)


def _check_along_z(unit: tuple[float, ...], rec: Record) -> None:
    """A 3-axis machine holds its tool along +Z: CL data for a tool along another `unit`
    vector (a horizontal spindle, a tilted head) puts the tool's length elsewhere."""
    if not all(abs(v - z) <= AXIS_TOL for v, z in zip(unit, (0.0, 0.0, 1.0))):
        raise NcppError(
            f"the tool vector ({', '.join(f'{v:g}' for v in unit)}) is not along +Z: "
            "the post drives a 3-axis machine whose tool points along Z (0, 0, 1)",
            rec.where,
        )


# Majors that move the tool along a path other than GOTO lines and CIRCLE arcs: NX CLSF's
# NURBS/ (with KNOT/ and CNTRL/ records), APT's incremental and direction motion words
UNMODELLED_MOTION = frozenset("NURBS GODLTA GOFWD GOBACK GOLFT GORGT GOUP GODOWN MOVARC".split())


def _home_target(rec: Record, home: Point | None, pos: Point) -> Point:
    """Where GOHOME goes: NX's `GOHOME/x,y,z[,i,j,k]` names the point; otherwise the FROM point,
    for the axes named (`GOHOME/Z` moves Z only) or all three."""
    if len(rec.numbers) >= 3:
        return _position(rec, rec.numbers)
    assert home is not None
    named = [a for a in "XYZ" if a in rec.words] or list("XYZ")
    x, y, z = (home[k] if a in named else pos[k] for k, a in enumerate("XYZ"))
    return (x, y, z)


def cutter_side(rec: Record) -> str:
    """CUTCOM/LEFT or RIGHT (the side the tool runs on), "" for CUTCOM/OFF; other forms are refused."""
    sides = [w for w in rec.words if w in ("LEFT", "RIGHT", "OFF")]
    if len(sides) != 1:
        raise NcppError("CUTCOM: expected LEFT, RIGHT or OFF", rec.where)
    return "" if sides[0] == "OFF" else sides[0]


def motion(
    records: Iterable[Record], warnings: Warnings | None = None, zero: Point = (0.0, 0.0, 0.0)
) -> Iterator[Event]:
    """Line / Arc / Pass events of a CL record stream; `zero`: the machine position (mm)
    of the CL data's origin, the work offset the control will hold."""
    pos: Point | None = None
    home: Point | None = None
    feed = 0.0
    rapid_next = False
    multax = False
    tool_vector: tuple[float, ...] | None = None  # its unit vector
    vector_line = 0
    context = Context(offset=zero)
    circle: _Circle | None = None
    driller: Driller | None = None
    rpm: float | None = None
    fixed = ""  # COMP under CUTCOM/LEFT|RIGHT and for the move leaving it (as the NC interpreter's)
    leaving = False  # CUTCOM/OFF: the next move is the last fixed one

    def flush() -> Iterator[Event]:
        nonlocal circle
        if circle is not None:
            if not circle.points:
                raise NcppError("CIRCLE without a GOTO on it", circle.record.where)
            yield circle.arc(feed, context, fixed)
            circle = None

    for rec in records:
        major = rec.major
        if major == "GOTO":
            values = rec.numbers
            if len(values) not in (3, 6):
                raise NcppError(
                    f"GOTO needs 3 coordinates (or 6 with a tool vector), got {len(values)}", rec.where
                )
            if len(values) == 6 or multax:
                vector = _unit(values[3:6]) if len(values) == 6 else None
                if vector is not None:
                    if tool_vector is None:
                        _check_along_z(vector, rec)
                        tool_vector, vector_line = vector, rec.line
                    elif max(abs(a - b) for a, b in zip(vector, tool_vector)) > VECTOR_TOL:
                        raise NcppError(
                            f"the tool vector changes from ({', '.join(f'{v:g}' for v in tool_vector)}) "
                            f"(line {vector_line}) to ({', '.join(f'{v:g}' for v in vector)}): "
                            "5-axis motion cannot be posted for a 3-axis machine",
                            rec.where,
                        )
            end: Point = _position(rec, values)
            if driller is not None:
                if pos is None:
                    raise NcppError("a CYCLE hole before any position (FROM or GOTO)", rec.where)
                hole, moves = driller.hole(end, pos, feed, rpm)
                block = HoleBlock(raw=rec.text, eol="\n", items=(), line=rec.line, hole=hole)
                for x, y, z, rapid in moves:
                    yield Line(pos, (x, y, z), rapid, hole.feed, block, context, fixed=CYCLE)
                    pos = (x, y, z)
                rapid_next = False
                continue
            if circle is not None and circle.takes(end):
                circle.add(end, rec)
                pos = end
                continue
            yield from flush()
            start = pos if pos is not None else end
            yield Line(start, end, rapid_next, feed, _block(rec), context, fixed=fixed)
            rapid_next = False
            if leaving:
                fixed, leaving = "", False
            pos = end
            continue
        yield from flush()
        if major == "CIRCLE":
            if driller is not None:
                raise NcppError("CIRCLE under a CYCLE: only its holes (GOTO) until CYCLE/OFF", rec.where)
            if pos is None:
                raise NcppError("CIRCLE before any position (FROM or GOTO)", rec.where)
            circle = _Circle(rec, pos)
            yield Pass(_block(rec))  # the arc event follows with its GOTOs
            continue
        if major == "FROM":
            values = rec.numbers
            if len(values) < 3:
                raise NcppError("FROM needs x, y, z", rec.where)
            pos = home = _position(rec, values)
        elif major in UNMODELLED_MOTION:
            raise NcppError(f"{major}/ moves the tool along a path ncpp does not post (it posts GOTO lines "
                            "and CIRCLE arcs): passed through, the move would be missing", rec.where)  # fmt: skip
        elif major == "GOHOME" and pos is not None and (home is not None or len(rec.numbers) >= 3):
            target = _home_target(rec, home, pos)
            yield Line(pos, target, True, feed, _block(rec), context, fixed=fixed)
            pos, rapid_next = target, False
            if driller is not None:  # the generator ends the canned cycle for the move: a new series
                driller = Driller(driller.cycle, pos[2], context.inch)
            continue
        elif major == "GOHOME":  # passed through, the move home would be missing
            raise NcppError("GOHOME without a FROM point or a position before it: where home is is not "
                            "known (NX's GOHOME/x,y,z names it)", rec.where)  # fmt: skip
        elif major == "RAPID":
            rapid_next = True
        elif major == "FEDRAT" and rec.numbers:
            feed = feed_rate(rec)
        elif major == "UNITS":
            inch = units_inch(rec)
            offset: Point = (zero[0] / 25.4, zero[1] / 25.4, zero[2] / 25.4) if inch else zero
            context = replace(context, inch=inch, offset=offset)  # program units
        elif major == "CYCLE" and rec.words[:1] == ("INIT",):
            if warnings is not None:  # SolidWorks CAM's mark before each cycle record: no motion of its own
                warnings.warn("CYCLE/INIT has no machine function: nothing is written for it", rec.where)
        elif major == "CYCLE":
            cycle = parse_cycle(rec)
            if cycle is not None and pos is None:
                raise NcppError(f"CYCLE/{cycle.kind} before any position (FROM or GOTO)", rec.where)
            if cycle is not None and fixed == COMP and not leaving:  # RS274/NGC and FANUC refuse it too
                raise NcppError(
                    f"CYCLE/{cycle.kind} under CUTCOM/LEFT or RIGHT: turn it OFF first", rec.where
                )
            driller = Driller(cycle, pos[2], context.inch) if cycle is not None and pos is not None else None
        elif major == "SPINDL" and rec.numbers:
            rpm = rec.numbers[0]
        elif major == "CUTCOM":
            side = cutter_side(rec)
            leaving = not side and fixed == COMP
            fixed = COMP if side or leaving else ""
        elif major == "MULTAX":
            multax = not (rec.words and rec.words[0] == "OFF")
        elif major == "TLAXIS" and len(rec.numbers) >= 3:
            vector = _unit(rec.numbers[:3])
            if tool_vector is not None and max(abs(a - b) for a, b in zip(vector, tool_vector)) > VECTOR_TOL:
                raise NcppError(
                    "TLAXIS changes the tool vector: 5-axis motion cannot be posted for a 3-axis machine",
                    rec.where,
                )
            _check_along_z(vector, rec)
            tool_vector, vector_line = vector, rec.line
        elif major == "CSYS" and not _identity_frame(rec.numbers):
            raise NcppError("CSYS/ places the GOTO points in a coordinate system of its own (a setup turned or "
                            "moved): ncpp posts them as written and does not transform them", rec.where)  # fmt: skip
        elif rec.vendor and warnings is not None:
            warnings.warn(f"{major}/ is not understood; passed through as a comment", rec.where)
        yield Pass(_block(rec))
    yield from flush()
