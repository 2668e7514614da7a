"""Where the tool centre stands under cutter (tool radius) compensation, in every dialect.

ISO's G41/G42, Klartext's RL/RR and Sinumerik's G41/G42 make the control offset the
programmed contour by the tool radius, to the left or the right of the direction of travel.
The control joins the offset moves at their corners (a transition arc about the corner at an
outside corner, the crossing of the offset paths at an inside one: TNC 640 user's manual,
"Radius compensation: Machining corners"; 840D sl Programming Manual Fundamentals, "Corner
behavior: G450, G451"; LinuxCNC's interpreter likewise), so at a move's end the tool centre
stands square to the move's own direction there, by the radius, in the working plane (G17, G18,
and in Klartext and Sinumerik G19 too: LinuxCNC refuses compensation there).  ncpp evaluates the
machine's error where the tool centre stands (`Line.centre_shift`); `ToolCentre` follows it move
by move, for the ISO interpreter and for `ModalInterpreter` alike.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from ncpp.motion.segments import PLANE_AXES, Arc, Line, Point, mark_off_path

ON_PATH: Point = (0.0, 0.0, 0.0)


def centre_offset(move: Line | Arc, side: float, standing: Point, at_start: bool = False) -> Point:
    """The tool centre minus the programmed point at the end of `move` (its start: `at_start`,
    square to it there) under compensation:
    `side` the radius, positive to the left of the move's direction there (G41, RL), negative
    to the right (0: not compensating, or the radius is unknown: on the path).  Left as seen
    from the plane's normal (+Z in G17, +Y in G18, +X in G19): in the plane's own (u, v) axes,
    X Y, Z X or Y Z, as LinuxCNC's manual (G41, G42) and rs274ngc's ARC_FEED have them, as the
    TNC's working plane has them for the tool axis Z, Y or X (its principal and minor axis: TNC
    640 user's manual, "Designation of the axes on milling machines"; left "based on the
    direction of tool movement along the workpiece contour", "Radius compensation") and as the
    840D sl's G17 G18 G19 have their abscissa and ordinate (Programming Manual Fundamentals,
    "Selection of the working plane"; G41 left of the contour in the direction of travel).  A
    move with no motion in the plane keeps the tool centre where it stands (`standing`)."""
    if not side:
        return ON_PATH
    a, b, _ = PLANE_AXES[move.context.plane]
    u0, v0, u1, v1 = move.start[a], move.start[b], move.end[a], move.end[b]
    shift = [0.0, 0.0, 0.0]
    if type(move) is Arc:  # left of the tangent: towards the centre counter-clockwise
        cu, cv = move.center[a], move.center[b]
        u1, v1 = (u0, v0) if at_start else (u1, v1)
        length = math.hypot(u1 - cu, v1 - cv)
        side = -side if move.turn > 0 else side
        shift[a], shift[b] = side * (u1 - cu) / length, side * (v1 - cv) / length
    elif (length := math.hypot(u1 - u0, v1 - v0)) > 0.0:
        shift[a], shift[b] = -side * (v1 - v0) / length, side * (u1 - u0) / length
    else:
        return standing
    return (shift[0], shift[1], shift[2])


def followed(moves: list[Line | Arc]) -> bool:
    """Whether compensation follows a block's moves under cutter compensation: in a principal plane
    (G17, G18, G19; in G90 or G91, absolute or incremental words: the moves' points are absolute
    here, and the writers write an increment from the corrected end before it), and none of them
    left as programmed for another reason (a loop's, a cycle's)."""
    return all(not m.fixed and m.context.plane in PLANE_AXES for m in moves)


@dataclass
class ToolCentre:
    """Where the tool centre stands off the programmed path, block after block.

    `approach`: where the entry move ends.  None: square to its own direction, as the other
    moves (LinuxCNC, the TNC).  "NORM", Sinumerik's initial setting: square to the contour's
    tangent at its first point, the next element's start ("The tool is oriented perpendicular
    to the contour point": 840D sl Programming Manual Fundamentals, "Contour approach and
    retraction (NORM, KONT, KONTC, KONTT)"), wherever the approach comes from.  "KONT": so too
    where the tool starts in front of the contour, on the side compensation puts it; from behind
    it "travels around the starting point" as at an outside corner (G450 or G451), so the entry
    ends square to its own direction ("KONT only differs from NORM when the tool start position
    is behind the contour": 840D sl Function Manual Basic Functions W1, "Approach and retraction
    behavior").  The retraction (G40) starts square to the last element in every setting, as
    each move ends.  The entry move's end waits (`waiting`) for the next move in the plane."""

    off_path: bool = False  # from the first move under compensation to the first after it is off
    at: Point = ON_PATH  # the tool centre minus the programmed point where the last move ended
    # whether the output stands at a corrected point in the plane (not where a move left as
    # programmed put the tool)
    corrected: bool = True
    approach: str | None = None
    # the entry move, and the moves after it along the plane's normal only, whose tool centre
    # (`centre_shift`) waits for the next move in the plane (`approach`)
    waiting: list[Line | Arc] = field(default_factory=list)

    def follow(self, moves: list[Line | Arc], side: float | None, also: bool = True) -> None:
        """A block's `moves` under compensation on `side` (`centre_offset`; None: it is off, the
        first move after it brings the tool back to its programmed end) or the first after it:
        each gets its `centre_shift`, where compensation follows them (`followed`, and `also`:
        the dialect's own condition); else they are marked `fixed` (COMP), left as programmed.
        The entry move's start is None: the tool centre starts on the programmed point, and the
        control makes the move whole."""
        if side is None and not self.off_path:
            return
        corrected = self.corrected or not self.off_path  # (the entry move starts from a compensated move)
        # an arc from where a move left as programmed ended starts there: it is left as programmed too
        # (compensated, it would start at its corrected start, a step away, which the control would offset);
        # so is a line that moves no axis of the plane (its corrected end would be such a step, made alone)
        follows = (
            also
            and followed(moves)
            and (corrected or (type(moves[0]) is not Arc and _moves_in_plane(moves[0])))
        )
        entry = follows and side is not None and not self.off_path
        if follows and side is not None and self.waiting:
            self._approached(moves, side)
        else:  # (not followed, or off: the entry keeps the tool centre square to its own direction)
            self.waiting = []
        shifts = [self._shift(move, side) for move in moves]
        if follows:
            for move, shift in zip(moves, shifts):
                move.centre_shift = shift
            self.off_path = side is not None
            self.corrected = corrected or any(_moves_in_plane(m) for m in moves)
            # (an entry along the normal alone: "If no geometry axis is programmed for the current
            # plane in the block with the tool radius compensation selection, no selection takes
            # place", 840D sl Function Manual W1, "Tool radius compensation 2D": not waited for)
            if entry and side is not None and self.approach is not None and _moves_in_plane(moves[0]):
                self.waiting = [moves[0]]
                self._approached(moves[1:], side, shifted=True)
        else:  # (a loop's or a cycle's moves too: that the tool is off the path matters more)
            self.off_path = mark_off_path(moves, side is not None, self.off_path)
            self.corrected = False

    def _approached(self, moves: list[Line | Arc], side: float, shifted: bool = False) -> None:
        """The entry move waiting (`waiting`) ends square to the first of `moves` in the plane at
        its start (`approach`), and the moves along the normal before it stand there too: theirs
        (`shifted`) or those `_shift` gives from `at`; with none in the plane they wait too."""
        first = next((k for k, move in enumerate(moves) if _moves_in_plane(move)), None)
        if first is None:
            self.waiting += moves
            return
        entry, standing = self.waiting[0], self.waiting[1:] + (moves[:first] if shifted else [])
        self.waiting = []
        at = centre_offset(moves[first], side, ON_PATH, at_start=True)
        if self.approach == "KONT" and _behind(entry, at):
            return
        entry.centre_shift = (None, at)
        for move in standing:
            move.centre_shift = (at, at)
        if shifted:
            given = moves[first].centre_shift
            assert given is not None  # (by `follow`)
            moves[first].centre_shift = (at, given[1])
        else:
            self.at = at

    def _shift(self, move: Line | Arc, side: float | None) -> tuple[Point | None, Point]:
        """The move's (start, end) tool centre minus programmed point; the start is the move
        before's end (the exit move after compensation ends on its programmed point)."""
        start = self.at if self.off_path else None
        self.at = centre_offset(move, side or 0.0, self.at)
        return start, self.at

    def scale(self, factor: float) -> None:
        """The program units changed."""
        self.at = (self.at[0] * factor, self.at[1] * factor, self.at[2] * factor)

    def reset(self) -> None:
        """Compensation is off and the tool on the path (a program end)."""
        self.off_path, self.at, self.corrected, self.waiting = False, ON_PATH, True, []


def _behind(entry: Line | Arc, at: Point) -> bool:
    """Whether the entry move starts behind the contour: on the other side of its first point than
    the tool centre compensation puts there (`at`)."""
    return sum((s - e) * o for s, e, o in zip(entry.start, entry.end, at)) < 0


def _moves_in_plane(move: Line | Arc) -> bool:
    """Whether the move moves an axis of its plane (a line along the normal alone does not)."""
    a, b, _ = PLANE_AXES[move.context.plane]
    return move.start[a] != move.end[a] or move.start[b] != move.end[b]
