"""Motion segments: what the interpreter makes of blocks, and what passes transform.

The interpreter turns each block into zero or more events:

* `Line`  — a straight move (rapid traverse or feed), like rs274's
  STRAIGHT_TRAVERSE / STRAIGHT_FEED;
* `Arc`   — a circular or helical feed move, like rs274's ARC_FEED;
* `Pass`  — a block with no motion (comments, M/S/T words, set-up codes,
  constructs outside the interpreter's scope), written back verbatim.

Every segment points at its source `Block` and carries the modal context a
writer needs to turn it back into NC text in the program's own style.
Coordinates are program (work) coordinates in program units, as rs274
reports them (under a rotation of the coordinate system, turned as the control turns
them: `Context.rotation`); `Context.to_machine` converts to machine axis positions in mm,
where the error model lives.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import final

from ncpp.program.blocks import Block

Point = tuple[float, float, float]
# Axes a programmable mirror image reflects (Fanuc's G51.1): (axis 0-2, the coordinate it reflects about)
Mirror = tuple[tuple[int, float], ...]
# Why a segment is `fixed`: passes leave it as programmed
CYCLE = "canned cycle"  # a hole is drilled where the program puts it
# a canned cycle compensated hole by hole: apply_error_map corrects its X Y Z R words (`Hole`), and no
# other pass splits or moves its moves
HOLE = "compensated canned cycle"
FLOW = "loop or subroutine"  # one text runs many times (or out of the text's order)
# a called drilling cycle's moves along the tool axis, in X Y where the block's move leaves the tool
DRILLED = "drilling cycle"
# the holes of a pattern the control computes (Klartext PATTERN DEF, Sinumerik HOLES1 ...) and its moves
# between them, at the pattern's own positions
PATTERN = "hole pattern"
COMP = "cutter compensation"  # the control offsets the path by the tool's radius: the tool is not on it
# Fanuc, Haas: a move of axis words before the program names any of G00-G03, in the motion mode the
# control holds at its start (a parameter's or setting's: `FanucInterpreter`), written as programmed so
# that no G00/G01 word of ncpp's sets that mode for the blocks after it
HELD = "motion mode the control holds at the start"
HOME = "G28/G30 return"  # the control homes the axes it names (machine coordinates); the others stay where they stand
# Klartext M91 and M140 MB, Sinumerik SUPA, G53 and G153: positions of the control's own
MACHINE = "machine-coordinate move"
# Klartext: moves from where the control left the tool on an axis ncpp is not told the position of
# (after `M140 MB MAX`, a pattern's last hole), up to the block that names the axis again
UNPLACED = "move from a position ncpp is not told"
# A rigid tap's two moves (`Line.tap`; LinuxCNC's G33.1): the tap, which passes correct like any feed
# move but never split (the control runs it as one motion synchronised with the spindle), and its
# return to where the tap started, which the control makes on its own (no block writes it)
TAP_IN, TAP_OUT = 1, 2
# Axis letters of `Line.end` / `Arc.end` beyond XYZ, in rs274's order.
EXTRA_AXES = ("A", "B", "C", "U", "V", "W")

PLANES = {17: "XY", 18: "XZ", 19: "YZ"}
# (first, second, normal) axis indices of each plane, as rs274 orders ARC_FEED arguments:
# G17: X Y (Z), G18: Z X (Y), G19: Y Z (X).
PLANE_AXES = {17: (0, 1, 2), 18: (2, 0, 1), 19: (1, 2, 0)}


def plane_letters(plane: int) -> str:
    """The letters of a plane's first and second axes, in `PLANE_AXES`' order: "XY", "ZX", "YZ"."""
    a, b, _ = PLANE_AXES[plane]
    return "XYZ"[a] + "XYZ"[b]


@dataclass(frozen=True, slots=True)
class Context:
    """Modal state a segment was made in, as far as writing it back needs."""

    plane: int = 17  # 17, 18, 19
    absolute: bool = True  # G90 / G91
    arc_absolute: bool = False  # G90.1 / G91.1 (IJK absolute)
    inch: bool = False  # G20 / G21
    offset: Point = (
        0.0,
        0.0,
        0.0,
    )  # machine minus program position (work offset, G92, tool length), program units
    tool: Point = (
        0.0,
        0.0,
        0.0,
    )  # the tool length offset (in `offset`): the tool tip is this far from the gauge point
    inverse_time: bool = False  # G93: a feed move's F is 1 / its time in minutes
    system: int = 1  # the work coordinate system in effect, 1..9: G54..G59.3 (one program zero: 1)
    tool_id: str = ""  # the tool in the spindle as the program names it ("3", '"MILL"'; "": none)
    # the program set the system's zero (G10): whether it is known (None: it did not, the control's holds)
    zero_set: bool | None = None
    # the control turns the program's X Y about Z (LinuxCNC's G10 L2 R), or the axes of another plane
    # (Fanuc's G68 in G18, G19: `rotation_plane`): (degrees counter-clockwise, the centre's first and second
    # coordinates in that plane, program units); segments are in the turned frame, the program's words are
    # not (`turned`)
    rotation: tuple[float, float, float] | None = None
    # the plane `rotation` turns (`PLANE_AXES`: G18 turns Z toward X, G19 Y toward Z)
    rotation_plane: int = 17
    # the axes the control mirrors (Fanuc's G51.1), before it turns them: segments are in the mirrored frame
    mirror: Mirror = ()

    @property
    def framed(self) -> bool:
        """Whether the control moves the program's points elsewhere in the work frame (`turned`)."""
        return self.rotation is not None or bool(self.mirror)

    @property
    def reverses(self) -> bool:
        """Whether the mirror reflects one axis of the plane alone: the control runs G2 as G3 and G3 as G2."""
        a, b, _ = PLANE_AXES[self.plane]
        return sum(axis in (a, b) for axis, _ in self.mirror) % 2 == 1

    @property
    def tool_mm(self) -> Point:
        s = self.unit_mm
        return (self.tool[0] * s, self.tool[1] * s, self.tool[2] * s)

    @property
    def unit_mm(self) -> float:
        return 25.4 if self.inch else 1.0

    def to_machine(self, p: Point) -> Point:
        """Machine axis position in mm of a program point."""
        s = self.unit_mm
        return ((p[0] + self.offset[0]) * s, (p[1] + self.offset[1]) * s, (p[2] + self.offset[2]) * s)

    def to_program(self, m: Point) -> Point:
        s = self.unit_mm
        return (m[0] / s - self.offset[0], m[1] / s - self.offset[1], m[2] / s - self.offset[2])

    def turned(self, p: Point, sign: float = 1.0) -> Point:
        """A point the program writes as the control moves to it under `rotation` (the frame of the
        segments, a translation of the machine's); `sign` -1: the program's point of a turned one.
        A mirror image reflects the program's point first, then the rotation turns it (SINUMERIK
        802D sl/840D ISO Milling programming manual, 3.2 "Programmable mirror image": "Processing proceeds
        from program mirror image to scaling and coordinate rotation")."""
        if self.mirror:
            q = list(p)
            if sign > 0:
                mirror_axes(q, self.mirror)
            if self.rotation is not None:
                turn_in_plane(q, self.rotation, self.rotation_plane, sign)
            if sign < 0:
                mirror_axes(q, self.mirror)
            return (q[0], q[1], q[2])
        if self.rotation is None:
            return p
        if self.rotation_plane == 17:
            x, y = turn_xy(p[0], p[1], self.rotation, sign)
            return (x, y, p[2])
        q = list(p)
        turn_in_plane(q, self.rotation, self.rotation_plane, sign)
        return (q[0], q[1], q[2])


def stores_a_cycle(move: Line | Arc) -> bool:
    """Whether a move is a canned cycle block's that stores the cycle and moves nothing (a Fanuc `L0`
    or `K0` block: `Interpreter._stored_cycle`): no move left as programmed, no move at all."""
    return move.fixed == CYCLE and move.start == move.end


def mirror_axes(p: list[float], mirror: Mirror) -> None:
    """Reflect point `p` (x, y, z, ...) in place about each of `mirror`'s coordinates (its own inverse)."""
    for axis, centre in mirror:
        p[axis] = 2.0 * centre - p[axis]


def turn_in_plane(
    p: list[float], rotation: tuple[float, float, float], plane: int, sign: float = 1.0
) -> None:
    """Turn point `p` (x, y, z, ...) in place by `rotation` about its centre in `plane`: from the plane's
    first axis toward its second (`PLANE_AXES`, as an arc of G3 turns there); `sign` -1: back."""
    a, b, _ = PLANE_AXES[plane]
    p[a], p[b] = turn_xy(p[a], p[b], rotation, sign)


def turn_xy(
    x: float, y: float, rotation: tuple[float, float, float], sign: float = 1.0
) -> tuple[float, float]:
    """(x, y) turned by `rotation` (degrees, centre x, centre y) about its centre; `sign` -1: back."""
    angle, cx, cy = rotation
    c, s = math.cos(math.radians(angle)), sign * math.sin(math.radians(angle))
    dx, dy = x - cx, y - cy
    return cx + c * dx - s * dy, cy + s * dx + c * dy


@dataclass(frozen=True, slots=True)
class Hole:
    """One hole of a canned cycle (`fixed` HOLE), in its plane's coordinates as rs274ngc names
    them (`PLANE_AXES`: `aa` `bb` in the plane, X Y in G17; the levels along its normal, the
    drilling axis): what the control drills it from, program units, absolute.  apply_error_map
    writes its moves again from the corrected words (`command`), as the control will run them
    (`cycles.drilled`); the writer writes each hole of a block's repeats (L) as a block of its own."""

    motion: float  # the cycle's G code (81.0, 83.0, ...)
    aa: float
    bb: float
    bottom: float  # along the normal (Z in G17)
    r: float  # the R plane
    peck: float  # G73 G83's Q (0: none)
    rapid_delta: float  # how far above the last peck G73 G83 rapid back in
    retract_to_r: bool  # G99 (True) or G98
    series_start: bool  # the first cycle of a series: G98 retracts to the level it starts from
    repeat: int = 0  # which of its block's repeats (L) it is, from 0
    repeats: int = 1  # how many the block has
    # with its correction: the aa bb, bottom and R written, absolute (None: as programmed), and the
    # level its series starts from as written (in G91 R counts from there)
    command: tuple[float, float, float, float] | None = None
    series_level: float = 0.0
    plane: int = 17  # 17, 18, 19
    # G87 (back boring): the offset in the plane the tool passes the bore at (I J in G17), and the
    # level it feeds back up to (K in G17), the cut's end; its command, absolute (None: as programmed)
    offset: tuple[float, float] = (0.0, 0.0)
    top: float | None = None
    top_command: float | None = None
    # Fanuc's G87 (`cycles.fanuc_back_bore`): shifted by `offset` at the level the series started at, down
    # to R below the part (`bottom` and `r` both), back over the hole, the cut up to Z (`top`)
    fanuc_back: bool = False

    @property
    def cut(self) -> float:
        """The level the hole's position in the plane is corrected at: where its cut ends (the
        bottom; G87: the top it feeds back up to)."""
        return self.bottom if self.top is None else self.top

    def point(self, level: float) -> Point:
        """The X Y Z of the hole at `level` along the plane's normal."""
        return plane_point(self.plane, self.aa, self.bb, level)


def plane_point(plane: int, aa: float, bb: float, cc: float) -> Point:
    """The X Y Z of a point given in a plane's coordinates (`PLANE_AXES`: `cc` along its normal)."""
    a, b, n = PLANE_AXES[plane]
    out = [0.0, 0.0, 0.0]
    out[a], out[b], out[n] = aa, bb, cc
    return (out[0], out[1], out[2])


# Events are not frozen: a pipeline makes several per output line, and a frozen
# dataclass sets each field through object.__setattr__ (several times slower to build).
# Treat them as values all the same: a pass that changes one makes a new one.
# Line and Arc are final: code tells them apart by `type(e) is Line` (faster than isinstance).
@final
@dataclass(slots=True)
class Line:
    start: Point
    end: Point
    rapid: bool
    feed: float
    block: Block
    context: Context = field(default_factory=Context)
    extra: tuple[float, ...] = ()  # end positions of A B C U V W, when the program uses them
    changed: bool = False  # set by a pass that moved the end point
    fixed: str = (
        ""  # why passes leave the move as programmed (CYCLE, FLOW, COMP, HOME), "" if they may change it
    )
    # A fixed move's X Y Z the control puts at their programmed end; the others run their programmed
    # increment from where the control stands (None: all of them in G90, none in G91)
    placed: tuple[bool, bool, bool] | None = None
    extra_start: tuple[
        float, ...
    ] = ()  # start positions of A B C U V W (as `extra`), when the program uses them
    # a compensated canned cycle's hole (`fixed` HOLE), the same for its block's moves
    hole: Hole | None = None
    # under cutter compensation ncpp follows (`Interpreter._in_comp`): where the tool centre stands off
    # the programmed start and end (program units, in the plane; zero where the radius is unknown), the
    # control offsetting the contour by the radius; the start None: the entry move, which the control
    # makes whole.  None: the tool centre is on the programmed path.  replace_arcs' pieces carry their arc's
    centre_shift: tuple[Point | None, Point] | None = None
    tap: int = 0  # TAP_IN, TAP_OUT: a rigid tap's move (0: none)

    def length(self) -> float:
        return math.dist(self.start, self.end)


@final
@dataclass(slots=True)
class Arc:
    """A circular (or helical) arc in `context.plane`.

    `turn` follows rs274's ARC_FEED rotation: +1 counter-clockwise (G3),
    -1 clockwise (G2); |turn| > 1 adds full turns.  `center` has the
    normal-axis coordinate of the start point.
    """

    start: Point
    end: Point
    center: Point
    turn: int
    feed: float
    block: Block
    context: Context = field(default_factory=Context)
    extra: tuple[float, ...] = ()
    changed: bool = False
    fixed: str = ""  # as `Line.fixed`
    # a piece replace_arcs made: the direction its plane's normal axis was compensated for
    # (+1, -1: the one that axis last moved in, which the machine holds it in; 0: the mean)
    normal: int = 0
    extra_start: tuple[float, ...] = ()  # as `Line.extra_start`
    centre_shift: tuple[Point | None, Point] | None = None  # as `Line.centre_shift`

    @property
    def clockwise(self) -> bool:
        return self.turn < 0

    def radius(self) -> float:
        i, j, _ = PLANE_AXES[self.context.plane]
        return math.hypot(self.start[i] - self.center[i], self.start[j] - self.center[j])

    def sweep(self) -> float:
        """Signed swept angle in radians (positive counter-clockwise)."""
        i, j, _ = PLANE_AXES[self.context.plane]
        a0 = math.atan2(self.start[j] - self.center[j], self.start[i] - self.center[i])
        a1 = math.atan2(self.end[j] - self.center[j], self.end[i] - self.center[i])
        full = 2 * math.pi
        if self.turn > 0:
            d = (a1 - a0) % full
            d = d if d > 1e-12 else full
            return d + full * (self.turn - 1)
        d = (a0 - a1) % full
        d = d if d > 1e-12 else full
        return -(d + full * (-self.turn - 1))


@dataclass(frozen=True, slots=True)
class Setting:
    """What a G92 or G10 L10/L11/L20 block sets from where the control stands: the offset that gives the
    current point the block's coordinates.  The control stands at the compensated point, off
    `position` by `shift`; written with their values moved by it, the block sets the offset the
    program means (apply_error_map fills `shift`, the writer writes it)."""

    values: tuple[tuple[int, float], ...]  # (axis 0-2, the coordinate the block gives it), program units
    context: Context  # the frame the block is read in
    position: Point  # the programmed point the tool stands at, in that frame
    shift: Point | None = None  # where the control stands minus `position` (None: not known, or none)
    leaves: bool = False  # the block ends interpretation: what runs after it is not followed


@dataclass(slots=True)
class Pass:
    """A block that makes no motion; written back as it was (a `Setting`'s values moved by its shift)."""

    block: Block
    skipped: bool = False  # the program does not run it (an untaken branch, a subroutine's definition)
    # a control line's (an o-word; Sinumerik's loop end, jump or subprogram call, which runs other
    # blocks' moves after its text): the modal motion (G0-G3, a cycle; Sinumerik's CIP, CT) where it runs
    motion: float | str | None = None
    setting: Setting | None = None  # a G92 or G10 L10/L11/L20 block's
    # --expand-cycles: `cycle` the G code of a canned cycle's block whose moves are written as G0/G1 blocks
    # (the first of its events), `dwell` how long it dwells between two of them (G82 G89's P, in the
    # control's unit) and `dwell_word` the P of the G4 that dwells as long on that control
    cycle: float | None = None
    dwell: float | None = None
    dwell_word: str | None = None
    # a block that applies the length of the tool in the spindle from the told tool table (G43):
    # (the tool's number, its Z offset in mm; Sinumerik's M6 or D: the edge D, its length 1 in mm),
    # which the tool guard checks (`ncpp/guard.py`)
    length_told: tuple[int, float] | None = None
    # a block that selects a work coordinate system whose zero is still the one ncpp was told (its
    # number, 1..9 or ADDITIONAL + n), which the placement guard checks before the block
    zero_told: int | None = None
    # the tool parameters (#5401-#5413) the block reads, as ncpp answered them from the told table:
    # (the tool in the spindle, the parameter, its value in the table's units or degrees), which the
    # tool guard checks before the block
    tool_read: tuple[tuple[int, int, float], ...] | None = None
    # a block that sets an offset from where the control stands (G92; LinuxCNC's G10 L20, a system's zero)
    # or restores the saved G92 offset (G92.3): (0 for the G92 offset, else the system 1-9 whose zero it
    # sets; (axis 0-2, the offset after the block in mm) for the axes it sets, X Y Z for G92.3), which
    # the placement guard checks after the block
    offset_told: tuple[int, tuple[tuple[int, float], ...]] | None = None
    # with `offset_told`, of a G92 or a G10 L20 of the system in effect that sets X Y Z (a touch-off): that
    # system (1-9), and where the program's zero stands after the block, its zero plus the G92 offset
    # applied, in machine mm
    zero_placed: tuple[int, tuple[float, float, float]] | None = None


Segment = Line | Arc
Event = Line | Arc | Pass


def mark_off_path(moves: list, compensating: bool, off_path: bool) -> bool:
    """Under tool radius compensation (G41/G42, RL/RR) the control offsets the path by the
    radius: mark a block's `moves` made with it on, or the first after it is off (which ends
    on its programmed point), `fixed` (COMP).  Whether the tool is off the path after them."""
    if not moves or not (compensating or off_path):
        return off_path
    for move in moves:
        move.fixed = COMP
    return compensating


__all__ = [
    "COMP",
    "CYCLE",
    "HOLE",
    "Hole",
    "plane_point",
    "FLOW",
    "DRILLED",
    "PATTERN",
    "HELD",
    "HOME",
    "MACHINE",
    "UNPLACED",
    "mark_off_path",
    "Arc",
    "Context",
    "Event",
    "Line",
    "Pass",
    "Point",
    "Mirror",
    "mirror_axes",
    "stores_a_cycle",
    "Segment",
    "Setting",
    "PLANES",
    "PLANE_AXES",
    "EXTRA_AXES",
    "replace",
]
