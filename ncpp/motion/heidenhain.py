"""Heidenhain Klartext blocks -> motion events (`Line`, `Arc`, `Pass`), like `ncpp.motion.interpret`.

Scope: `BEGIN PGM ... MM|INCH`, `TOOL CALL n|"NAME" Z DL..` (the tool axis gives the
working plane; the tool's length L + DL from the tool table, TOOL.T, or from the
program's `TOOL DEF n L..`, plus the call's DL, along that axis), `L` with X/Y/Z (absolute) and IX/IY/IZ (incremental) per word
and the rotary axes A/B/C and IA/IB/IC (`ROTARY_WORDS`), `R0`,
`F`, `FMAX` (rapid, this block only), `FAUTO`, `CC` (the pole; its plane from
the axes written), `C ... DR±` about the pole, `CR ... R± DR±` (R+: less than a
half circle), `CT` (tangential arc), `LP`/`CP` polar with PR/IPR/PA/IPA (a
helix with IZ, several turns with |IPA| > 360), Q parameters with arithmetic,
labels, subprograms (`CALL LBL n` ... `LBL 0`), program-section repeats (`CALL LBL n REP k`)
and the jumps FN 9-12 (`heidenhain_flow`: a block that runs again is left as programmed,
FLOW, a subprogram that runs once is compensated where its text stands, `_flowing`, and so is a
jump's loop of one pass, `_run_flow`; with --expand each run is written out, `heidenhain_expand`), `CALL PGM` of a program file on the subroutine path (`_call_program`: its moves are left
as programmed, FLOW, and the caller's after it compensated), `CYCL DEF` of machining cycles
(they only define), the drilling cycles 200, 201, 203, 205, 207 and 240 called by M99, `CYCL CALL`
or `CYCL CALL POS` (`heidenhain_cycles`: their moves along the tool axis are left as
programmed, DRILLED) or `CYCL CALL PAT` at the holes of a `PATTERN DEF` (all its moves left as
programmed, PATTERN; but single positions at FMAX, whose moves in the plane are compensated,
`Positions`), the datum shift of CYCL DEF 7 and the rotation of CYCL DEF 10 with the tool
axis Z (`_rotation_cycle`: the moves in the turned frame, `Context.rotation`), M2/M30
and `END PGM` (end), and `RND R..` / `CHF ..` between two feed lines in the
working plane (the fillet arc or chamfer line is the RND/CHF block's event; a
feed line waits for the next move to know whether its corner is cut).
Radius compensation RL/RR is followed to R0: the moves from the first with RL/RR
to the R0 block's are the programmed contour, the tool centre off it by the radius
(the called tool's R + DR from TOOL.T or TOOL DEF's R, plus TOOL CALL's DR); they carry
where the tool centre stands (`centre_shift`, `ModalInterpreter.radius_compensation`) in
the working plane of the tool axis (TOOL CALL .. Z: X Y, .. Y: Z X, .. X: Y Z, left and right
as seen from the positive tool axis), with X/Y/Z or IX/IY/IZ words, else (RL/RR or R0 in an arc
block, RND/CHF next to the entry or exit move, a block that turns it to the other side, a block
that runs again) they are marked `fixed`.  A TOOL CALL
under RL/RR is out of scope.  Paraxial R+/R-,
RND/CHF next to an arc or a rapid, FK free contours,
APPR/DEP, `CALL PGM` of a file not found, calls of other cycles, point tables, M89, FN 14 and
later FN
functions and cycles that move the datum make the position unknown: one warning (an error with
`strict`) and the rest passes through.

A `CC` block yields a `Pole` event (a `Pass` that carries the pole) so that a
writer can keep the program's pole where compensated arcs need their own.
"""

from __future__ import annotations

import math
import operator
import re
from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path

from ncpp.errors import Location, NcppError, Warnings
from ncpp.motion.called import Files, count_called, searched
from ncpp.motion.corners import CornerError, round_corner
from ncpp.motion.cutter import centre_offset
from ncpp.motion.endless import never_changes
from ncpp.motion.expand import refused
from ncpp.motion.heidenhain_cycles import (
    DEFINITION_ACTIVE,
    REQUIRED,
    RETRACT_FEED,
    SHAPES,
    Drilling,
    Hole,
    Step,
    cycle_number,
    parameters_needed,
    pattern_holes,
)
from ncpp.motion.heidenhain_cycles import steps as cycle_steps
from ncpp.motion.heidenhain_expand import KlartextExpansion, is_control, is_label
from ncpp.motion.heidenhain_flow import (
    CALLED,
    FIXED,
    JUMPS,
    ONCE,
    SKIP,
    TEXT,
    KlartextFlow,
    jump_parts,
    label_key,
)
from ncpp.motion.modal import (
    MM_PER_INCH,
    PLANE_OF_TOOL_AXIS,
    ModalInterpreter,
    OutOfScope,
    as_point,
    placed_interpreting,
)
from ncpp.motion.once import FirstPass, OnceRuns, held_to_the_end
from ncpp.motion.segments import (
    COMP,
    FLOW,
    MACHINE,
    PATTERN,
    PLANE_AXES,
    UNPLACED,
    Arc,
    Event,
    Line,
    Pass,
    Point,
)
from ncpp.motion.tools import ToolTable, UntoldLengths
from ncpp.passes.rotary import turns
from ncpp.program.blocks import Block, Comment, ExprWord, Statement, Word

AXES = "XYZ"
# A B C, absolute (`A+90`) or incremental (`IA+10`) (TNC 640 Klartext manual, "Path functions": a straight
# line L with rotary axis words); a turn is followed in an L or LP block, and where the control does not
# take its own way: M126 turns a rotary axis the shortest way ("Shortest-path traverse of rotary axes: M126",
# without it the axis turns by the difference of the positions, as ncpp follows them), and M94 reduces the
# display of its position below 360 degrees ("Reducing display of a rotary axis to a value less than 360°")
ROTARY_WORDS = {"A": (0, False), "B": (1, False), "C": (2, False), "IA": (0, True), "IB": (1, True),
                "IC": (2, True)}  # fmt: skip
SHORTEST_WAY, LONGER_WAY, REDUCED_DISPLAY = 126.0, 127.0, 94.0
# Programs CALL PGM runs nest this deep (TNC 640 Klartext manual, "Nesting": "Maximum nesting
# depth for calling NC main programs")
MAX_PROGRAM_NESTING = 19
# Coordinate transformations this interpreter does not follow, by what each does (TNC 640 Cycle
# Programming manual, "MIRRORING (Cycle 8)", "SCALING (Cycle 11)", "WORKING PLANE (Cycle 19)",
# "AXIS-SPECIFIC SCALING (Cycle 26)"); 7, a shift, and 10, a rotation, are followed
TRANSFORMATION_CYCLES = {"8": "a mirror image", "11": "a scaling", "19": "a tilted working plane",
                         "26": "an axis-specific scaling"}  # fmt: skip
# CYCL DEF 7 DATUM SHIFT (TNC 640 Cycle Programming manual, "DATUM SHIFT (Cycle 7)"): `7.0` heads it, each
# of `7.1 X..` `7.2 Y..` `7.3 Z..` shifts one axis's datum, an absolute value from the preset, an incremental
# one (`IY-11.75`) from the datum in effect; a datum table's line (`7.1 #5`) is not read
SHIFT_CYCLE = "7"
# CYCL DEF 10 ROTATION (TNC 640 Cycle Programming manual, "ROTATION (Cycle 10)"): `10.1 ROT+30` turns the
# coordinate system in the working plane about the active datum, counter-clockwise from the reference axis
# (X in the XY plane), `IROT` adds to the angle in effect, `ROT+0` resets it; the head `10.0` alone moves
# nothing (`_rotation_cycle`)
ROTATION_CYCLE = "10"
# The words that place a move in the working plane XY (`settle_rotation` after Cycle 10)
PLANE_WORDS = ("X", "Y", "IX", "IY", "PR", "PA", "IPR", "IPA")
# CYCL DEF 247 DATUM SETTING activates the preset Q339 of the preset table (TNC 640 Klartext manual,
# "Cycle 247 DATUM SETTING"): the program zero ncpp is told is that preset's; another preset later
# is a zero ncpp is not told
PRESET_CYCLE = "247"
END_M = frozenset((2.0, 30.0))
# The parameter the control sets to the active tool radius at each TOOL CALL: R (tool table or
# TOOL DEF) + DR (tool table) + DR (TOOL CALL) (TNC 320 User's Manual, "Preassigned Q parameters")
ACTIVE_TOOL_RADIUS = "q108"
SIDES = {"RL": 1, "RR": -1, "R0": 0}  # radius compensation's side of the contour (0: off)
HARMLESS_KEYWORDS = frozenset(("STOP",))
# Resets of what this interpreter never follows (a tilted plane, TCPM: it stops at any that sets
# one), which move no axis: `PLANE RESET STAY` keeps the rotary axes where they are (TNC 640
# Klartext manual, "PLANE RESET"), `FUNCTION RESET TCPM` ends tool-centre-point control
HARMLESS_RESETS = frozenset((("PLANE", "RESET", "STAY"), ("FUNCTION", "RESET", "TCPM")))
# `PLANE SPATIAL SPA+0 SPB+0 SPC+0 STAY`, which CAM posts write for a part machined untilted: spatial
# angles of 0 leave the working plane as it is and STAY positions no rotary axis (TNC 640 Klartext
# manual, "PLANE SPATIAL", "Automatic positioning: STAY"); the control stores the rotary axes'
# positions for the plane in Q120-Q122 (A, B, C), which ncpp does not know
SPATIAL_ANGLES = ("SPA", "SPB", "SPC")
UNTILTED_PLANE_WORDS = frozenset(("STAY", "SEQ+", "SEQ-", "TABLE", "COORD", "ROT"))
PLANE_AXIS_POSITIONS = ("q120", "q121", "q122")


# FN 0-8 and 13: Q parameter arithmetic (TNC 640 Klartext manual, "Basic arithmetic" and "Angle
# functions": `FN 0: Q5 = +10`, `FN 1: Q1 = -Q2 + -5`, `FN 4: Q25 = +Q1 DIV +Q7`, `FN 5:
# Q20 = SQRT Q4`, `FN 6: Q20 = SIN-Q5` in degrees, `FN 8: Q10 = +5 LEN +4`, `FN 13: Q20 =
# +25 ANG-Q1`, the angle whose opposite and adjacent sides (or sine and cosine) the two are,
# 0 to 360 degrees).  The jumps FN 9-12 are `heidenhain_flow`'s.
FN_ARITHMETIC = {0: "", 1: "+", 2: "-", 3: "*", 4: "DIV", 5: "SQRT", 6: "SIN", 7: "COS", 8: "LEN", 13: "ANG"}
FN_BINARY = {1: operator.add, 2: operator.sub, 3: operator.mul, 4: operator.truediv, 8: math.hypot,
             13: lambda a, b: math.degrees(math.atan2(a, b)) % 360.0}  # fmt: skip
_FN_OPERAND = r"([+-]?)[ \t]*(Q[LR]?\d+|\d+(?:[.,]\d*)?|[.,]\d+)"
_FN_TARGET = re.compile(r"[ \t]*(Q[LR]?\d+)[ \t]*=[ \t]*(.*?)[ \t]*$", re.I)


def _fn_operand(text: str) -> tuple:
    sign, value = re.fullmatch(_FN_OPERAND, text.strip(), re.I).groups()  # type: ignore[union-attr]
    expr = ("param", value.lower()) if value[0] in "Qq" else ("num", float(value.replace(",", ".")))
    return ("neg", expr) if sign == "-" else expr


@dataclass(slots=True)
class Pole(Pass):
    """A `CC` block: the pole (circle centre) it sets, in `plane`."""

    center: Point = (0.0, 0.0, 0.0)
    plane: int = 17
    again: bool = False  # the block runs again or away from its text: its text stays as it is


@dataclass(slots=True)
class Corner(Pass):
    """An `RND` (kind 'R', size the radius) or `CHF` (kind 'C', size the leg) block, until the next move."""

    kind: str = "R"
    size: float = 0.0
    feed: float | None = None  # `RND R5 F200`: the feed of the fillet only
    col: int | None = None


@dataclass(slots=True)
class Positions(Pass):
    """The first event of a `CYCL CALL PAT` whose holes are a `PATTERN DEF`'s single positions, all
    numbers (`pattern`, that block): the moves to the holes are compensated, and the writer writes
    the PATTERN DEF again before the call, each POS's X and Y where the move to it ends."""

    pattern: Block | None = None


def _offset_corner(made: list[Event], side: float | None) -> bool:
    """An RND/CHF corner between two lines under RL/RR (on `side`: `centre_offset`), both
    followed: the control rounds the contour, then offsets it, so the fillet or chamfer gets
    where the tool centre stands along it as any move does, and the second line starts where it
    ends.  The first line keeps its own: shortened, its direction is the same.  False where that
    is not so (the first line the entry move, the second the exit move, either left as
    programmed)."""
    first, last = made[0], made[-1]
    if not isinstance(first, Line) or not isinstance(last, Line) or first.fixed or last.fixed:
        return False
    if first.centre_shift is None or last.centre_shift is None or first.centre_shift[0] is None:
        return False
    at = first.centre_shift[1]
    if side is None or math.dist(last.centre_shift[1], centre_offset(last, side, at)) > 1e-9 * (
        1 + abs(side)
    ):
        return False  # (the exit move)
    for piece in made[1:]:
        if isinstance(piece, (Line, Arc)):
            end = centre_offset(piece, side, at)
            piece.centre_shift, at = (at, end), end
    return True


def _in_flow(events: list[Event], owner: Block | None) -> list[Event]:
    """A block's events where it runs again: its moves are left as programmed (FLOW) and, run
    out of the text's order, belong to `owner`, as do its pole and corner (the writer's state);
    its other events are the text, written where it stands."""
    out: list[Event] = []
    for event in events:
        if type(event) is Line or type(event) is Arc:
            event.fixed = event.fixed or FLOW
        elif type(event) is Pole:
            event.again = True
        elif owner is not None and type(event) is not Pole and type(event) is not Corner:
            continue
        if owner is not None:
            event.block = owner
        out.append(event)
    return out


def _as_programmed(event: Event, owner: Block | None) -> Event | None:
    """An event of a text that runs again (a CALLED run's, `once.held_to_the_end`; a loop's first pass,
    `FirstPass`): as a FIXED run's (`owner`: the call; None: in its place)."""
    kept = _in_flow([event], owner)
    return kept[0] if kept else None


def _written_positions(item: Statement) -> bool:
    """Whether a `PATTERN DEF` gives its holes one by one, each `POSn` with X and Y as numbers (TNC 640
    cycle programming manual, "Pattern definition PATTERN DEF", "Defining individual machining
    positions"): where each hole is, the block says in words a corrected value can stand in."""
    return bool(item.node) and all(
        name == "POS" and all(expr[0] == "num" for _, expr in words) for name, _, words in item.node
    )


def _skippable(block: Block) -> bool:
    """Whether the block has the block skip `/` (the control runs it or not, as the operator sets)."""
    return any(type(i) is Statement and i.kind == "block_delete" for i in block.items)


def _untilted_plane(node: tuple) -> bool:
    """Whether a keyword statement is `PLANE SPATIAL` by angles of 0 with STAY (`SPATIAL_ANGLES`)."""
    if node[:2] != ("PLANE", "SPATIAL") or "STAY" not in node:
        return False
    angles = {word[:3]: word[3:].replace(",", ".") for word in node[2:] if word[:3] in SPATIAL_ANGLES}
    others = [word for word in node[2:] if word[:3] not in SPATIAL_ANGLES]
    if set(angles) != set(SPATIAL_ANGLES) or not UNTILTED_PLANE_WORDS.issuperset(others):
        return False
    return all(re.fullmatch(r"[+-]?(0+(\.0*)?|\.0+)", angle) for angle in angles.values())


def _plane_of_axes(axes: set[int], default: int) -> int:
    for plane, (a, b, _) in PLANE_AXES.items():
        if axes == {a, b}:
            return plane
    return default


class HeidenhainInterpreter(ModalInterpreter):
    def __init__(
        self,
        file: str = "<stdin>",
        zero: tuple[float, float, float] = (0.0, 0.0, 0.0),
        tools: ToolTable | None = None,
    ):
        super().__init__(file, zero)
        self.tools = tools  # the control's tool table (TOOL.T), if told
        self.defined: dict[
            float, float
        ] = {}  # tool lengths the program defines (TOOL DEF n L..), program units
        self.tool_number: float | None = (
            0.0  # the tool TOOL CALL put in the spindle (None: one named, no table)
        )
        self.tool_axis = 2  # the axis its length is along (TOOL CALL's axis)
        self.call_dl = 0.0  # the last TOOL CALL's DL (an oversize), program units
        self.call_dr = 0.0  # and its DR, added to the tool's radius
        self.tool_called = False  # a TOOL CALL named a tool (before it, the spindle's tool is not told)
        self.defined_radii: dict[float, float] = {}  # tool radii the program defines (TOOL DEF n R..)
        self.untold_lengths = UntoldLengths()  # warns at a TOOL CALL whose tool length nothing tells
        self.q: dict[str, float] = {}
        self.pole: list[float] | None = None
        self.pole_rotation: tuple[float, float, float] | None = None  # the rotation in effect where CC set it
        self.pole_plane = 17
        self.auto_feed = 0.0
        self.last_move: Line | Arc | None = None
        self.corner_waits = False  # an RND/CHF block came after the last move
        self.unknown_axes: set[int] = set()  # axes whose position ncpp is not told (after M140 MB MAX)
        self.preset: float | None = None  # the preset CYCL DEF 247 activated (the program zero told)
        self.shift = [0.0, 0.0, 0.0]  # the datum CYCL DEF 7 shifted X Y Z by, from the preset
        self.ended = False  # the program ended (M2, M30, END PGM), not left the scope
        self.flow: KlartextFlow | None = None  # the order the blocks run in (labels, calls, jumps)
        self.cycle: Drilling | str | None = None  # the cycle M99 / CYCL CALL runs (str: one not followed)
        self.spindle = 0.0  # the speed TOOL CALL S set (rev/min): a tapping cycle's feed follows it
        self.pattern: tuple[str, list[Hole]] | str | None = None  # PATTERN DEF's holes (str: not followed)
        self.positions: Block | None = None  # the PATTERN DEF, where its holes are POS words of numbers only
        self.programs: list[Path] = []  # the programs CALL PGM runs, outermost first
        self.main_path: Path | None = Path(file).resolve() if file != "<stdin>" else None
        self.called: Path | None = None  # the program the block just run calls
        self.returned = False  # the called program's END PGM ran
        self.called_blocks = 0  # blocks run in called programs so far
        self._files: Files | None = None  # the called programs' files, once a call needs them
        self.expansion: KlartextExpansion | None = None  # --expand: what it writes (`heidenhain_expand`)
        self.shortest_way = False  # M126: rotary axes turn the shortest way (ROTARY_WORDS)
        # the subprograms whose one run is written where their text stands (`_flowing`; None: none)
        self.once_runs: OnceRuns | None = None

    def run(self, blocks: Iterable[Block], warnings: Warnings) -> Iterator[Event]:
        """Events as `ModalInterpreter.run`; a feed line waits (with the events after it)
        for the next move, which an RND/CHF block in between makes round or cut."""
        held: list[Event] = []  # the last feed line and the events after it
        corner: Corner | None = None
        for event in self._flowing(blocks, warnings):
            if isinstance(event, Pass):
                if type(event) is Corner:
                    corner = event
                if held:
                    held.append(event)
                else:
                    yield event
                continue
            if corner is not None:
                made = self._cut(held, corner, event, warnings)
                if made is None:  # out of scope: the line, the corner and this move pass through
                    yield from (e if type(e) is Pass else Pass(e.block) for e in held)
                    yield Pass(event.block)
                    held, corner = [], None
                    continue
                first, last = made[0], made[-1]
                assert not isinstance(first, Pass) and not isinstance(last, Pass)  # round_corner's lines
                held[0], event = first, last
                if (first.centre_shift is not None or last.centre_shift is not None) and not _offset_corner(
                    made, self.comp_side if self.radius_comp else None
                ):
                    # (the entry or exit move, a side unknown: left as programmed, as ISO's corners are)
                    for cut in made:
                        if not isinstance(cut, Pass):
                            cut.fixed, cut.centre_shift = COMP, None
                piece = made[1] if len(made) == 3 else Pass(corner.block)
                kept = next((f for f in (first.fixed, last.fixed) if f in (COMP, FLOW)), None)
                if kept is not None and not isinstance(piece, Pass):  # (the contour's, or runs again)
                    piece.fixed = kept
                held = [piece if e is corner else e for e in held]
                corner = None
            yield from held
            held = []
            if type(event) is Line and not event.rapid:
                held.append(event)
            else:
                yield event
        if corner is not None:
            raise NcppError(
                f"{'RND' if corner.kind == 'R' else 'CHF'} has no following move",
                Location(self.file, corner.block.line, corner.col),
            )
        yield from held

    def _cut(
        self, held: list[Event], corner: Corner, second: Line | Arc, warnings: Warnings
    ) -> list[Event] | None:
        """[first line shortened, fillet or chamfer, second line] or None when out of scope."""
        where = Location(self.file, corner.block.line, corner.col)
        first = held[0]
        assert isinstance(first, Line)  # `run` holds back a feed line and what follows it
        what = None if isinstance(second, Line) and not second.rapid else "an arc or a rapid move"
        if what is None and (turns(first) or turns(second)):  # (its fillet or chamfer would not turn a share)
            what = "a move that turns a rotary axis"
        if what is not None or not isinstance(second, Line):
            self._refuse_leaving(f"RND/CHF next to {what}", corner.block, corner.col)
            self.done = True
            warnings.warn(f"RND/CHF next to {what} is outside the motion interpreter's scope; "
                          "from this line on the program passes through uninterpreted", where)  # fmt: skip
            return None
        try:
            return round_corner(first, second, corner.kind, corner.size, corner.block, corner.feed)
        except CornerError as err:
            raise NcppError(str(err), where) from None

    def lookup(self, name: str) -> float:
        if name in self.q:
            return self.q[name]
        if name == ACTIVE_TOOL_RADIUS:
            radius = self.tool_radius()
            if radius is None:
                raise OutOfScope("the parameter Q108 (the active tool radius, which ncpp is not told: "
                                 "give --tool-table TOOL.T, or TOOL DEF with R)")  # fmt: skip
            return radius
        raise OutOfScope(f"the parameter {name.upper()} (not set in the program)")

    # -- one block ------------------------------------------------------------------------
    def block(self, block: Block) -> list[Event]:
        function: str | None = None
        function_item = None
        words: dict[str, tuple[float, object]] = {}
        rapid = False
        rotation: str | None = None
        comp: str | None = None  # RL, RR or R0
        end = False
        machine_datum = False  # M91: the block's coordinates are the machine datum's
        retract: float | str | None = None  # M140 MB: a retract along the tool axis after the move
        call: tuple[str, int] | None = None  # M99 or CYCL CALL and its column: the cycle runs after the move
        at_position = False  # CYCL CALL POS: the block's X Y Z are where the cycle runs
        at_pattern = False  # CYCL CALL PAT: the cycle runs at the holes of the PATTERN DEF
        defined: str | None = None  # CYCL DEF of a drilling cycle: its number
        rotary_words: list[tuple[Word | ExprWord, float]] = []
        for item in block.items:
            if type(item) is Comment:
                continue
            if type(item) is Word or type(item) is ExprWord:
                letter = item.letter
                value = item.value if type(item) is Word else self.value(item.expr, block, item)
                if letter == "N":
                    continue
                if letter == "M":
                    if value == 99.0:
                        call = ("M99", item.start + 1)
                        continue
                    if value == 89.0:  # (whether it calls after every block is a machine parameter)
                        raise OutOfScope("M89 (a modal cycle call or a free M function: the machine "
                                         "tool builder decides)", item.start + 1)  # fmt: skip
                    if value == 128.0:
                        raise OutOfScope("M128 (tool-centre-point control)", item.start + 1)
                    if value == 92.0:  # (its datum is a machine parameter ncpp is not told)
                        raise OutOfScope("M92 (a position the machine tool builder sets)", item.start + 1)
                    if value == REDUCED_DISPLAY and (self.uses_rotary or rotary_words):
                        raise OutOfScope("M94 (it reduces a rotary axis's position below 360 degrees)",
                                         item.start + 1)  # fmt: skip
                    if value in (SHORTEST_WAY, LONGER_WAY):
                        self.shortest_way = value == SHORTEST_WAY
                    machine_datum = machine_datum or value == 91.0
                    if value in END_M and self.programs:
                        raise OutOfScope(f"M{value:g} in a program CALL PGM runs (its END PGM returns)",
                                         item.start + 1)  # fmt: skip
                    end = end or value in END_M
                    continue
                if letter in ROTARY_WORDS:
                    rotary_words.append((item, value))
                    continue
                words[letter] = (value, item)
                continue
            what, node = item.kind, item.node
            if what == "block_delete":  # (the block runs, block skip off: as ISO's `/`)
                continue
            if what == "path":
                function, function_item = node[0], item
            elif what == "program_begin":
                self.set_units(node[1] == "INCH")
            elif what == "program_end":
                if self.flow is not None and self.flow.frames:  # (where the control goes is not told)
                    raise OutOfScope("END PGM in a subprogram (no LBL 0 before it)", item.start + 1)
                if self.programs:  # a called program's END PGM returns to the caller
                    self.returned = True
                else:
                    end = True
            elif what == "call_program":
                self.called = self._call_program(block, item)
            elif what == "tool_call":
                if node[1] not in (None, "Z") and self.rotation is not None:
                    raise OutOfScope(f"TOOL CALL with the tool axis {node[1]} under a rotation (CYCL DEF 10)",
                                     item.start + 1)  # fmt: skip
                if node[1] is not None:
                    self.plane = PLANE_OF_TOOL_AXIS[node[1]]
                    self.tool_axis = AXES.index(node[1])
                    self._context = None
                return self._tool_call(block, item)
            elif what == "radius_comp":
                comp = node[0]
                if comp != "R0" and self.rotation is not None:
                    raise OutOfScope(
                        f"radius compensation {comp} under a rotation of CYCL DEF 10", item.start + 1
                    )
            elif what == "feed":
                rapid = node[0] == "FMAX"
                if node[0] == "FAUTO":
                    self.feed = self.auto_feed
            elif what == "rotation":
                rotation = node[0]
            elif what == "retract":
                retract = node[0]
            elif what == "assignment":
                if node[1][0] == "feed":
                    self._feed_parameter(node, item)
                elif node[1][0] != "str":
                    self.q[node[0][1]] = self.value(node[1], block, item)
            elif what == "cycle_def":
                number = cycle_number(node[0])
                if number == PRESET_CYCLE:
                    self._preset(block, item)
                    return []
                if number == SHIFT_CYCLE:
                    self._datum_shift(block, item)
                    return []
                if number == ROTATION_CYCLE:
                    self._rotation_cycle(block, item)
                    return []
                if number in TRANSFORMATION_CYCLES:
                    what = TRANSFORMATION_CYCLES[number]
                    raise OutOfScope(f"CYCL DEF {node[0]} ({what} of the coordinate system)", item.start + 1)
                if number not in REQUIRED:  # (a cycle ncpp does not follow: a call of it leaves the scope)
                    self.cycle = self.cycle if number in DEFINITION_ACTIVE else f"CYCL DEF {number}"
                    self._forget_assigned(block)
                    return []
                defined = number  # (its Q parameters follow as assignments)
            elif what == "cycle_call":
                call = ("CYCL CALL" if node[0] is None else f"CYCL CALL {node[0]}", item.start + 1)
                at_position, at_pattern = node[0] == "POS", node[0] == "PAT"
            elif what == "pattern_def":
                self.pattern = self._pattern(block, item)
                self.positions = block if _written_positions(item) and not _skippable(block) else None
                return []
            elif (
                what == "keyword"
                and node
                and (node[0] in HARMLESS_KEYWORDS or tuple(node) in HARMLESS_RESETS)
            ):
                continue
            elif what == "keyword" and _untilted_plane(node):
                for name in PLANE_AXIS_POSITIONS:
                    self.q.pop(name, None)
            elif what == "fn" and node[0] in FN_ARITHMETIC:
                self._fn(block, item)
            elif what == "tool_def":
                return self._tool_def(block, item)
            elif what == "blk_form":
                return []  # its words describe the blank, not a move
            elif what == "label":
                if node[0] == 0 and self.flow is not None:
                    self.flow.end_subprogram()
            elif what == "call_label" and self.flow is not None:
                self._call_label(block, item)
            elif what == "fn" and node[0] in JUMPS and self.flow is not None:
                self._jump(block, item)
            else:
                reason = {"call_label": "CALL LBL", "cycle_call": "CYCL CALL",
                          "contour_label": "a label list `/n` away from CYCL DEF 14.1",
                          "fn": f"FN {node[0]}", "keyword": " ".join(map(str, node)),
                          "touch_probe": f"TCH PROBE {node[0]} (a touch probe cycle: it probes, and may set"
                                         " the datum or the tool's data)"}.get(what, what)  # fmt: skip
                raise OutOfScope(reason, item.start + 1)
        rotary = None
        if rotary_words:
            on_line = function in ("L", "LP") and not machine_datum and call is None
            rotary = self._rotary(rotary_words, on_line, machine_datum)
        if defined is not None:
            self._define_cycle(defined, block)
            return []
        if function in ("RND", "CHF"):
            return [self._corner(block, function_item, words)]
        if self.unsettled is not None and (function is not None or at_position):
            self._settle(function, function_item, words)
        if (at_position or at_pattern) and call is not None:
            if function is not None or machine_datum or retract is not None or comp not in (None, "R0"):
                raise OutOfScope(f"{call[0]} with a path function, M91, M140 or RL/RR in its block", call[1])
            if (
                self.radius_comp or self.centre.off_path
            ):  # (no move after R0 brought the tool back to its point)
                raise OutOfScope(
                    f"{call[0]} with the tool off the contour by radius compensation RL/RR", call[1]
                )
            if at_pattern:
                return self._call_pattern(block, words, rapid, call[1])
            positioned = self._call_at_position(block, words, rapid, call[1])
            if self.unknown_axes:  # (the move in the plane goes from where ncpp is not told)
                self._from_unknown(positioned[:1], words)
            return positioned
        if "F" in words and function is not None:
            self.feed = words["F"][0]
        if machine_datum and function is not None:
            events: list[Event] = [self._machine_move(block, function, function_item, words, rapid)]
        else:
            events = (
                self._path(block, function, function_item, words, rapid, rotation, rotary) if function else []
            )
        if self.unknown_axes:
            self._from_unknown(events, words)
        if retract is not None:
            if call is not None:
                raise OutOfScope(f"M140 and the cycle call {call[0]} in one block", call[1])
            events.append(self._retract(block, retract))
        if comp is not None or self.radius_comp or self.centre.off_path:
            events = self.radius_compensation(events, None if comp is None else SIDES[comp])
        if call is not None:
            events = events + self._call_cycle(block, *call)
        if events and isinstance(events[-1], (Line, Arc)):
            self.last_move, self.corner_waits = events[-1], False
        if end:
            self.done = self.ended = True
        return events

    def _rotation_cycle(self, block: Block, item: Statement) -> None:
        """A line of CYCL DEF 10 (`ROTATION_CYCLE`): the coordinate system turns about the datum in the
        working plane XY (`ModalInterpreter.set_frame`: the tool stays where it stands, the moves after it are
        in the turned frame until a block gives X and Y, `_settle`).  Not followed: another working plane
        (a turn about X or Y), a rotation under radius compensation RL/RR (the control cancels it: the
        manual's "Please note")."""
        words = [i for i in block.items if (type(i) is Word or type(i) is ExprWord) and i.letter != "N"]
        if not words and item.node[0] in ("10", "10.0"):
            return  # (the cycle's head: its angle follows)
        if len(words) != 1 or words[0].letter not in ("ROT", "IROT"):
            raise OutOfScope(f"CYCL DEF {item.node[0]} (a rotation ncpp does not read)", item.start + 1)
        before = self.rotation[0] if self.rotation is not None else 0.0
        angle = self._word_value(words[0], block) + (before if words[0].letter == "IROT" else 0.0)
        if angle == before:
            return
        why = ("with the tool axis " + AXES[self.tool_axis] if self.tool_axis != 2
               else "under radius compensation RL/RR" if self.radius_comp else None)  # fmt: skip
        if why is not None:
            raise OutOfScope(f"CYCL DEF 10 ROTATION {why}", item.start + 1)
        self.set_frame(self.offset, (angle, 0.0, 0.0) if angle else None)
        self.unsettled = "CYCL DEF 10"

    def _settle(self, function: str | None, item, words: dict) -> None:
        """`settle_rotation` for a block after Cycle 10: an absolute X and Y settle it (a CC's only set the
        pole); a circle from where the tool stands (no word in the plane) is placed as one axis alone is."""
        both = "X" in words and "Y" in words
        named = next((words[k][1] for k in PLANE_WORDS if k in words), None)
        if function in ("C", "CP", "CT", "CR") and named is None:
            named = item
        if function == "CC":
            both, named = False, None if both else named
        self.settle_rotation(both, named)

    def _define_cycle(self, number: str, block: Block) -> None:
        """CYCL DEF of a drilling cycle, its Q parameters just assigned: the cycle M99 and CYCL
        CALL run from now on (`ncpp.motion.heidenhain_cycles`)."""
        missing = [name.upper() for name in REQUIRED[number] if name not in self.q]
        if missing:
            self.cycle = f"CYCL DEF {number} without {', '.join(missing)}"
            return
        needed = parameters_needed(number)
        self.cycle = Drilling(number, {name: self.q[name] for name in needed if name in self.q}, block.line)

    def _feed_parameter(self, node: tuple, item: Statement) -> None:
        """`Q208= MAX`: the cycle retracts at rapid (TNC 640 Cycle Programming manual, cycles 200-205:
        "Q208 Feed rate for retraction ... alternatively FMAX"); `Q206= AUTO`: the feed of the TOOL CALL,
        as `FAUTO` on a move ("Q206 Feed rate for plunging ... alternatively FAUTO"), followed where the
        TOOL CALL gives one.  Any other parameter so given is a feed ncpp does not follow."""
        name, (_, word) = node[0][1], node[1]
        if name == RETRACT_FEED and word == "MAX":
            self.q[name] = math.inf
        elif word == "AUTO" and self.auto_feed > 0.0:
            self.q[name] = self.auto_feed
        else:
            raise OutOfScope(f"{name.upper()}={word} (a feed ncpp does not follow)", item.start + 1)

    def _forget_assigned(self, block: Block) -> None:
        """The Q parameters a CYCL DEF ncpp does not read sets are unknown from here on."""
        for item in block.items:
            if type(item) is Statement and item.kind == "assignment":
                self.q.pop(item.node[0][1], None)

    def _call_cycle(self, block: Block, how: str, col: int) -> list[Event]:
        """M99 (after the block's move) or CYCL CALL: the drilling cycle's moves where the tool
        stands, in the tool axis.  Left as programmed (DRILLED): the control runs them from
        where it stands, which is the compensated end of the positioning before."""
        run = self._cycle_run(how, col)
        here = self.pos[self.tool_axis]  # (a step to where the tool stands is none: the cycle starts there)
        steps = [
            (s.level, None if s.rapid else s.feed, 0.0) for s in run if s.level != here or s is not run[0]
        ]
        return self.drilled(block, steps, self.tool_axis)

    def _cycle_run(self, how: str, col: int, shift: float = 0.0) -> list[Step]:
        """The steps of one run of the cycle defined (its levels `shift`ed along the tool axis),
        or out of scope where ncpp cannot call it here."""
        cycle = self.cycle
        if not isinstance(cycle, Drilling):
            raise OutOfScope(f"the cycle call {how} ({cycle or 'no cycle defined'})", col)
        if self.tool_axis != 2:
            raise OutOfScope(f"the cycle call {how} with the tool axis {AXES[self.tool_axis]}", col)
        if self.radius_comp:
            raise OutOfScope(f"the cycle call {how} with radius compensation RL/RR", col)
        if self.tool_axis in self.unknown_axes:
            raise OutOfScope(f"the cycle call {how} where the tool axis is unknown (after M140 MB MAX)", col)
        changed = [name.upper() for name, value in cycle.q.items() if self.q.get(name) != value]
        if changed:
            raise OutOfScope(f"the cycle call {how}: {changed[0]} changed since CYCL DEF {cycle.number}", col)
        try:
            run = cycle_steps(cycle, self.spindle)
        except OutOfScope as out:
            out.col = col
            raise
        return [Step(s.level + shift, s.rapid, s.feed) for s in run]

    def _call_at_position(self, block: Block, words: dict, rapid: bool, col: int) -> list[Event]:
        """`CYCL CALL POS X.. Y.. Z.. FMAX|F..`: the cycle runs at the block's position.  TNC 640
        Klartext manual, "Calling a cycle with CYCL CALL POS": all three axes are programmed; from
        above the workpiece surface Q203 the control moves first in the working plane, then in
        the tool axis (below it, first to a clearance height: out of scope); the tool-axis
        coordinate is an additional datum shift of the cycle; the feed is for this approach only;
        the move is without radius compensation.  The move in the plane positions the tool
        (compensated, the block's X and Y); the one in the tool axis and the cycle's are left as
        programmed (DRILLED), as the block's Z stays what the cycle's levels count from."""
        if any(axis not in words for axis in AXES):
            raise OutOfScope("CYCL CALL POS without absolute X, Y and Z (the control needs all three)", col)
        if not rapid and "F" not in words:
            raise OutOfScope("CYCL CALL POS without F or FMAX (its feed is the last CYCL CALL POS's)", col)
        shift = words[AXES[self.tool_axis]][0]
        run = self._cycle_run("CYCL CALL POS", col, shift)
        assert isinstance(self.cycle, Drilling)  # (`_cycle_run` checked it)
        surface = self.cycle["q203"] + shift
        if not self.pos[self.tool_axis] > surface:
            raise OutOfScope(f"CYCL CALL POS from below the workpiece surface Q203 ({surface:g} with the "
                             "call's datum shift): the control goes to a clearance height first", col)  # fmt: skip
        programmed, approach = self.feed, None if rapid else words["F"][0]
        self.feed = programmed if approach is None else approach
        end = list(self.pos)
        for n, axis in enumerate(AXES):
            if n != self.tool_axis:
                end[n] = words[axis][0]
        plane = self.line(block, end, rapid)
        self.feed = programmed
        steps = [(shift, approach, 0.0)] if shift != self.pos[self.tool_axis] else []
        steps += [(s.level, None if s.rapid else s.feed, 0.0) for s in run]
        return [plane, *self.drilled(block, steps, self.tool_axis)]

    def _pattern(self, block: Block, item) -> tuple[str, list[Hole]] | str:
        """`PATTERN DEF`: its holes (`heidenhain_cycles.pattern_holes`) and the last shape's name,
        or why ncpp does not follow them (a `CYCL CALL PAT` then leaves the scope)."""
        holes: list[Hole] = []
        try:
            for name, _, words in item.node:
                values = {letter: self.value(expr, block, item) for letter, expr in words}
                if name not in SHAPES or len(values) != len(words):
                    return f"PATTERN DEF {name}{' with a word twice' if name in SHAPES else ''}"
                holes += pattern_holes(name, values)
        except OutOfScope as out:
            return out.reason
        return (item.node[-1][0] if item.node else "", holes) if holes else "PATTERN DEF without a hole"

    def _call_pattern(self, block: Block, words: dict, rapid: bool, col: int) -> list[Event]:
        """`CYCL CALL PAT FMAX|F..`: the cycle runs at each hole of the PATTERN DEF, the tool
        moving between them at the 2nd set-up clearance (TNC 640 cycle programming manual,
        "Pattern definition PATTERN DEF" and "Calling a cycle with CYCL CALL PAT"; each
        shape's Z is added to Q203).  The control computes the holes and its own moves
        between them, which a rewritten program could not correct: all the call's moves
        are left as programmed (PATTERN) and the holes are where the pattern puts them;
        compensation resumes after the call.  Single positions (POS1-POS9, numbers) at FMAX
        are the exception (`_compensated_pattern`): the block says where each hole is.  Only
        from above the 2nd set-up clearance and with one surface for all holes (the moves
        between two surfaces are the control's); after a PAT or FRAME grid, whose order the
        manual does not give, X and Y are not known until a block names them."""
        pattern = self.pattern
        if not isinstance(pattern, tuple):
            raise OutOfScope(f"the cycle call CYCL CALL PAT ({pattern or 'no PATTERN DEF'})", col)
        if not rapid and "F" not in words:
            raise OutOfScope("CYCL CALL PAT without F or FMAX (its feed between the holes)", col)
        shape, holes = pattern
        if len({z for _, _, z in holes}) > 1:
            raise OutOfScope("CYCL CALL PAT with holes at different surfaces Z", col)
        surface = holes[0][2]
        run = self._cycle_run("CYCL CALL PAT", col, surface)
        assert isinstance(self.cycle, Drilling)  # (`_cycle_run` checked it)
        top = surface + self.cycle["q203"] + max(self.cycle["q200"], self.cycle["q204"])
        if self.pos[self.tool_axis] < top:
            raise OutOfScope(f"CYCL CALL PAT from below the 2nd set-up clearance {top:g} (the control's "
                             "move up to it is not followed)", col)  # fmt: skip
        if self._compensated_pattern(rapid, block):
            # (the moves to the holes compensated as a CYCL CALL POS's, the cycle's left as programmed)
            return [Positions(block, pattern=self.positions), *self._at_holes(block, holes, run, None)]
        events = self._at_holes(block, holes, run, None if rapid else words["F"][0])
        for event in events:
            if type(event) is Line:
                event.fixed, event.placed = PATTERN, (True, True, True)
        if shape in ("PAT", "FRAME"):
            self.unknown_axes |= {0, 1}
        else:  # (the last hole is where the tool stands)
            self.unknown_axes -= {0, 1}
        return events

    def _compensated_pattern(self, rapid: bool, call: Block) -> bool:
        """Whether the holes of the PATTERN DEF are compensated one by one: single positions, all
        numbers, which the control reaches at FMAX (a rapid is never written in pieces, which
        the control's moves between the holes could not be), from where ncpp knows the tool
        stands in the plane, without a rotation of CYCL DEF 10; neither the PATTERN DEF nor the
        `call` skippable (the PATTERN DEFs written around the call run whatever the skip says)."""
        known = not self.unknown_axes & {0, 1} and self.rotation is None
        return self.positions is not None and rapid and known and not _skippable(call)

    def _at_holes(
        self, block: Block, holes: list[Hole], run: list[Step], approach: float | None
    ) -> list[Event]:
        """The tool to each hole in the plane at the height it stands (at `approach`, None: FMAX),
        then the cycle's `run` there along the tool axis (DRILLED)."""
        programmed = self.feed
        events: list[Event] = []
        for x, y, _ in holes:
            end = list(self.pos)
            end[0], end[1] = x, y
            self.feed = programmed if approach is None else approach
            events.append(self.line(block, end, approach is None))
            self.feed = programmed
            here = self.pos[self.tool_axis]
            steps = [
                (s.level, None if s.rapid else s.feed, 0.0) for s in run if s.level != here or s is not run[0]
            ]
            events += self.drilled(block, steps, self.tool_axis)
        return events

    def _tool_def(self, block: Block, statement) -> list[Event]:
        """`TOOL DEF n L.. R..`: the program defines tool n's length and radius (without L: it only
        prepares the tool)."""
        number = self._tool_number(statement.node[0], block, statement)
        for item in block.items:
            if (type(item) is Word or type(item) is ExprWord) and number is not None:
                if item.letter == "L":
                    self.defined[number] = self._word_value(item, block)
                elif item.letter == "R":
                    self.defined_radii[number] = self._word_value(item, block)
        return []

    def _tool_call(self, block: Block, statement) -> list[Event]:
        """`TOOL CALL n|"NAME" [axis] [DL..]`: tool n's length L + DL (table) + DL (call) along
        the tool axis; without a tool, the tool stays and so does its DL unless the call gives one."""
        if self.radius_comp:  # (which radius the control then offsets by, and how it gets there, is its own)
            raise OutOfScope("TOOL CALL with radius compensation RL/RR", statement.start + 1)
        dl = dr = None
        for item in block.items:
            if type(item) is Word and item.letter == "F":
                self.auto_feed = item.value
            elif (type(item) is Word or type(item) is ExprWord) and item.letter == "S":
                self.spindle = self._word_value(item, block)
            elif (type(item) is Word or type(item) is ExprWord) and item.letter == "DL":
                dl = self._word_value(item, block)
            elif (type(item) is Word or type(item) is ExprWord) and item.letter == "DR":
                dr = self._word_value(item, block)
        called = statement.node[0]
        if called is not None:
            self.tool_number = self._tool_number(called, block, statement)
            self.tool_id = f'"{called}"' if type(called) is str else f"{self.tool_number:g}"
            self.call_dl = self.call_dr = 0.0
            self.tool_called = True
        if dl is not None:
            self.call_dl = dl
        if dr is not None:
            self.call_dr = dr
        self.q.pop(ACTIVE_TOOL_RADIUS, None)  # (the control sets it anew)
        tool = [0.0, 0.0, 0.0]
        tool[self.tool_axis] = self._length(self.tool_number, block, statement) + self.call_dl
        self.set_tool(tool)
        return []

    def _tool_number(self, called, block: Block, statement) -> float | None:
        """The number of a tool called or defined by number, Q parameter or name (a tool
        table's names; None: a name and no table to look it up in)."""
        if type(called) is tuple:  # ("param", q)
            return float(self.value(called, block, statement))
        if type(called) is not str:
            return float(called)
        if self.tools is None:
            return None
        number = self.tools.names.get(called)
        if number is None:
            self.fail(f'tool "{called}" is not in {self.tools.source}', block, statement)
        return number

    def _length(self, number: float | None, block: Block, statement) -> float:
        """Tool `number`'s length L + DL, program units: defined by the program, else the table's."""
        if number == 0:
            return 0.0
        if number in self.defined:
            return self.defined[number]
        if self.tools is None or number is None:
            self.untold_lengths("TOOL CALL", "TOOL.T", Location(self.file, block.line, statement.start + 1))
            return 0.0
        lengths = self.tools.edges.get((number, 1))
        if lengths is None:
            self.fail(
                f"tool {number:g} is not defined: neither in {self.tools.source} nor by TOOL DEF",
                block,
                statement,
            )
        return lengths[0] / (MM_PER_INCH if self.inch else 1.0)

    def tool_radius(self) -> float | None:
        """The called tool's radius R + DR, program units: defined by the program (TOOL DEF n
        R..), else the table's (TOOL.T), plus the call's DR (None: neither tells it, or no TOOL
        CALL did: the tool in the spindle is the control's)."""
        number = self.tool_number
        if not self.tool_called:
            return None
        if number == 0:
            return 0.0
        if number is not None and number in self.defined_radii:
            return self.defined_radii[number] + self.call_dr
        if self.tools is None or number is None or number in self.defined:
            return None  # (a tool the program defines without R: its radius is not the table's)
        radius = self.tools.radii.get((number, 1))
        return None if radius is None else radius / (MM_PER_INCH if self.inch else 1.0) + self.call_dr

    def _word_value(self, item, block: Block) -> float:
        return item.value if type(item) is Word else self.value(item.expr, block, item)

    # -- control flow (`heidenhain_flow`) ------------------------------------------------------
    def loop_quick(self) -> object:
        """The position and the Q parameters (copies), compared first of a loop's state."""
        return self.pos[:], dict(self.q)

    def _flowing(self, blocks: Iterable[Block], warnings: Warnings) -> Iterator[Event]:
        """Events as `ModalInterpreter.run`, block by block in the order they run: the moves of
        a block that runs again are left as programmed (FLOW) and, where it runs out of the
        text's order, belong to the line that runs it (a call, a jump back), written once; with
        --expand (`expand`) each run of it is written where it runs (`heidenhain_expand`).  The
        run of a subprogram that may be its only one (CALLED, `heidenhain_flow`) is followed as a
        run in place and held to the program's end (`once.held_to_the_end`, `once_runs`): run
        once, it is written where its text stands; else its moves are left as programmed."""
        self.expansion = KlartextExpansion(self.q, self.file) if self.expand else None
        runs = self.once_runs if self.expansion is None else None
        flow = KlartextFlow(self.file, blocks, once=runs)
        events = self._run_flow(flow, warnings, None)
        if runs is None:
            return events  # type: ignore[return-value]  # (no run is CALLED)
        return held_to_the_end(events, runs, lambda: (self.done, self.ended), lambda: flow.called_again,
                               lambda event, call: _as_programmed(event, call))  # fmt: skip

    def _run_flow(
        self, flow: KlartextFlow, warnings: Warnings, caller: Block | None
    ) -> Iterator[Event | tuple[tuple[str, Block], Event]]:
        """`_flowing` over the program (`caller` None) or over a program the line `caller` calls
        by CALL PGM: its blocks all run out of the text's order, their moves the caller's, and
        its text is no part of the output.  A CALLED run's events come as ((its subprogram, its
        call), event); those of a jump's loop's first pass in its place (ONCE) wait until the flow
        tells whether its text runs again (`ncpp.motion.once.FirstPass`)."""
        self.flow = flow
        flow.watch(self.loop_quick, self.loop_state)

        def stop(reason: str, owner: Block) -> None:  # (where the flow itself cannot go on)
            self._refuse_leaving(reason, owner, None)
            self.leave_scope(warnings, reason, owner, None, caller)

        once: FirstPass | None = None  # a loop's first pass in its place, while the flow has not told
        calling_inch = self.inch  # (a called program's units must be its caller's with --expand)
        for block, kind, owner in flow.steps(lambda: self.done or self.returned, stop):
            if caller is not None:
                if kind is SKIP or kind is TEXT:
                    continue
                kind, owner = FIXED, caller
                self.called_blocks = count_called(self.called_blocks, self.program_file, caller)
            if kind is ONCE and (self.expansion is not None or (once is not None and once.full())):
                kind = FIXED  # (--expand writes each run out; a longer first pass stays as programmed)
            if once is not None and (self.done or flow.in_straight_code() or once.full()):
                yield from self._told(once, flow, again=(self.done and not self.ended) or once.full())
                once = None
            if kind is ONCE and once is None:
                once = FirstPass(lambda event: _as_programmed(event, None))
            elif once is not None and kind is FIXED and owner is not None and once.rerun(block):
                yield from self._told(once, flow, again=True)  # (all of it runs again: nothing to hold)
                once = None
            events = self._events_of(flow, block, kind, owner, caller, calling_inch, warnings)
            if once is None:
                yield from events
                continue
            for event in events:  # (no CALLED run in a loop's pass)
                once.add(event, block, again=kind is FIXED)  # type: ignore[arg-type]
        if once is not None:
            yield from self._told(once, flow, again=not self.ended)

    def _told(self, once: FirstPass, flow: KlartextFlow, again: bool) -> list[Event]:
        """A loop's first pass in its place, once the flow has told whether its text runs again."""
        flow.told(again)
        return once.told(again)

    def _events_of(
        self, flow: KlartextFlow, block: Block, kind: str, owner: Block | None, caller: Block | None,
        calling_inch: bool, warnings: Warnings,
    ) -> Iterator[Event | tuple[tuple[str, Block], Event]]:  # fmt: skip
        """The events of one block the flow yields (`_run_flow`)."""
        # (with --expand a called program's blocks are written in place of its CALL PGM line, in the
        # caller's units; without it, its text is no part of the output)
        expansion = self.expansion
        if kind is SKIP or kind is TEXT or self.done or not block.items:
            if owner is None:  # (after M2/M30/END PGM: a subprogram's text, run where it is called)
                if expansion is not None and block.items and (kind is SKIP or kind is TEXT or self.done):
                    kept = expansion.text(kind is SKIP, block)
                    if kept is None:  # (text a jump goes over: left out)
                        return
                    yield from kept
                yield Pass(block, kind is SKIP or (kind is TEXT and self.ended))
            return
        called = None  # a CALLED run's (subprogram, call): its run as a run in place
        if kind is CALLED and flow.called is not None and owner is not None:
            called = (flow.called, owner)
        # (a first pass's moves are not followed under radius compensation: they may run again)
        self.again = (kind is FIXED or kind is ONCE) and expansion is None
        settling: tuple[Event, ...] = ()
        written: Block | None = block
        try:
            if expansion is not None:
                settling, written = self._written_out(expansion, block, kind, owner)
            events = self.block(block)
        except OutOfScope as out:
            self.called = None
            if expansion is not None and (caller is not None or expansion.refuses_leaving(flow)):
                raise refused(out.reason, Location(self.file, block.line, out.col)) from None
            self.leave_scope(warnings, out.reason, block, out.col, owner)
            if owner is None:
                yield from settling
                yield Pass(block)
            return
        if expansion is not None:  # each block where it runs, a stretch's as this run's numbers
            if caller is not None and self.inch != calling_inch:
                raise refused(f"a called program in {'inches' if self.inch else 'mm'} (its caller's "
                              "units differ)", Location(self.file, block.line, 1))  # fmt: skip
            yield from settling
            if written is not block:
                if written is not None:
                    if caller is not None:  # (told at its CALL PGM line, as the input's moves are)
                        written.line = caller.line
                    for event in events:
                        event.block = written
                    yield from events or (Pass(written),)
                yield from self._called_program(flow, owner or block, warnings)  # (CALL PGM's line left out)
                return
        elif kind is FIXED:
            events = _in_flow(events, owner)
        if kind is not FIXED and flow.labels and any(type(e) is Line or type(e) is Arc for e in events):
            flow.moved(kind is ONCE)  # (before the first label nothing can jump back over it)
        if called is not None:
            yield from ((called, event) for event in events or (Pass(block),))
            return
        yield from events or ((Pass(block),) if owner is None else ())
        yield from self._called_program(flow, owner or block, warnings)

    def _called_program(self, flow: KlartextFlow, caller: Block, warnings: Warnings) -> Iterator[Event]:
        """The events of the program the block just run called by CALL PGM (none if it called none),
        after which `flow` goes on."""
        if self.called is not None:
            path, self.called = self.called, None
            yield from self._program(path, caller, warnings)
            self.flow = flow

    def _written_out(
        self, expansion: KlartextExpansion, block: Block, kind: str, owner: Block | None
    ) -> tuple[tuple[Event, ...], Block | None]:
        """With --expand, before `block` runs: the assignments to write before it and the block
        to write for it (itself where it stands and runs once, a stretch's block as this run's
        numbers, None for a line left out: a call or jump, a label run again away from its text,
        a block of assignments only)."""
        if is_control(block):
            expansion.control()
            return (), None
        if is_label(block):  # (its text stays where it stands, once)
            if owner is None:
                return (), block
            expansion.control()
            return (), None
        if kind is not FIXED:
            return expansion.in_place(block), block
        return (), expansion.body(block, self.value, self.inch)

    def _refuse_leaving(self, reason: str, block: Block, col: int | None) -> None:
        """With --expand, an out-of-scope construct where the rest cannot pass through as it is
        (`KlartextExpansion.refuses_leaving`, or anywhere in a program CALL PGM runs: its calling
        line is left out) is refused."""
        expansion, flow = self.expansion, self.flow
        if expansion is not None and flow is not None and (self.programs or expansion.refuses_leaving(flow)):
            raise refused(reason, Location(self.file, block.line, col))

    # -- CALL PGM (TNC 640 Klartext manual, "Calling any program as a subprogram") ------------
    def _call_program(self, block: Block, item) -> Path:
        """`CALL PGM name`: the called program's file, `name` (its drive and folders aside, which
        are the control's: `TNC:\\PARTS\\PLAN.H` is PLAN.H) on the subroutine path, `.H` if
        the name has no type.  Alone in its block but for comments."""
        for other in block.items:
            if (
                other is not item
                and type(other) is not Comment
                and not (type(other) is Word and other.letter == "N")
            ):
                raise OutOfScope("CALL PGM with more in its block", other.start + 1)
        name = re.split(r"[\\/:]", item.node[0])[-1]
        _, dot, kind = name.rpartition(".")
        if dot and kind.upper() != "H":
            raise OutOfScope(f"CALL PGM {item.node[0]} (a program that is not Klartext, .H)", item.start + 1)
        names = [name] if dot else [f"{name}.h", name]
        if len(self.programs) >= MAX_PROGRAM_NESTING:
            raise OutOfScope(f"programs called more than {MAX_PROGRAM_NESTING} deep", item.start + 1)
        files = self._files = self._files or Files(self.subroutine_path, "heidenhain")
        path = files.find(names)
        if path is None:
            raise OutOfScope(
                f"CALL PGM {item.node[0]} (its file not found: {searched(self.subroutine_path, names)})",
                item.start + 1,
            )
        if path.resolve() in self.programs or path.resolve() == self.main_path:
            raise OutOfScope(
                f"CALL PGM {item.node[0]}, a program that calls itself (for ever)", item.start + 1
            )
        return path

    def _program(self, path: Path, caller: Block, warnings: Warnings) -> Iterator[Event]:
        """The called program from its first block to its END PGM, in the caller's state: the Q
        parameters are global (what it sets, the caller reads after), and so is the modal
        state; its own units (BEGIN PGM ... MM|INCH) hold while it runs."""
        assert self._files is not None  # (`_call_program` found the file)
        blocks = self._files.blocks(path)
        outer_file, outer_inch = self.file, self.inch
        self.programs.append(path.resolve())
        self.file = str(path)
        try:
            around = self.flow.around_call if self.flow is not None else list  # (the caller's flow)
            flow = KlartextFlow(str(path), blocks, around)  # (with no CALLED run: all its blocks run FIXED)
            yield from self._run_flow(flow, warnings, caller)  # type: ignore[misc]
            if not self.done and not self.returned:
                self._refuse_leaving(f"the called program {path.name} ends without END PGM", caller, None)
                self.leave_scope(warnings, f"the called program {path.name} ends without END PGM",
                                 blocks[-1] if blocks else caller, None, caller)  # fmt: skip
        finally:
            self.programs.pop()
            self.file, self.returned = outer_file, False
        if not self.done:
            self.set_units(outer_inch)

    def _call_label(self, block: Block, item) -> None:
        """`CALL LBL n [REP k]`: a subprogram call or a program-section repeat."""
        assert self.flow is not None
        name, repeat = item.node
        if type(repeat) is not int:  # (the manual's REP takes a number: a count of Q9 = 35.5 is not defined)
            raise OutOfScope(f"CALL LBL ... REP{repeat[1].upper()} (a repeat count from a Q parameter)",
                             item.start + 1)  # fmt: skip
        words = block.raw[item.start : item.end].rpartition('"')[2]  # (after a quoted name)
        if repeat == 0 and "REP" in words.upper():  # (the parser reads no REP as REP 0)
            raise OutOfScope("CALL LBL ... REP 0 (REP counts the section's runs after the first, TNC 640 "
                             "Klartext manual: how the control reads none is not told)", item.start + 1)  # fmt: skip
        index = self.flow.target(name, lambda q: self.value(q, block, item), item.start + 1, repeat == 0)
        key = label_key(self.value(name, block, item) if type(name) is tuple else name)
        self.flow.call(index, repeat, key, item.start + 1, self.radius_comp or self.centre.off_path)

    def _jump(self, block: Block, item) -> None:
        """FN 9-12: `IF a EQU|NE|GT|LT b GOTO LBL n` jumps to the label when the comparison holds."""
        assert self.flow is not None
        number, text = item.node
        parts = jump_parts(text or "")
        if (
            parts is None
            or parts[1] != JUMPS[number]
            or not all(re.fullmatch(_FN_OPERAND, o.strip(), re.I) for o in parts[:3:2])
        ):
            self.fail(f"FN {number}: expected IF a {JUMPS[number]} b GOTO LBL n", block, item)
        left, test, right, name = parts
        operands = [_fn_operand(o) for o in (left, right)]
        a, b = (self.value(operand, block, item) for operand in operands)
        if {"EQU": a == b, "NE": a != b, "GT": a > b, "LT": a < b}[test]:
            index = self.flow.target(name, lambda q: self.value(q, block, item), item.start + 1)
            if all(never_changes(operand) for operand in operands):  # (a jump back that nothing may leave)
                self.flow.refuse_without_way_out(index, block, item.start + 1)
            self.flow.goto(index)

    def _corner(self, block: Block, item, words: dict) -> Corner:
        function = item.node[0]
        if self.corner_waits:
            self.fail(f"{function} right after another RND/CHF block", block, item)
        previous = self.last_move
        if previous is not None and previous.context.rotation != self.rotation:
            raise OutOfScope(f"{function} after CYCL DEF 10 changed the rotation", item.start + 1)
        if type(previous) is not Line or previous.rapid:
            raise OutOfScope(
                f"{function} after {'no move' if previous is None else 'an arc or a rapid move'}",
                item.start + 1,
            )
        if function == "RND":
            if "R" not in words:
                self.fail("RND without a radius R", block, item)
            kind, size = "R", words["R"][0]
        else:
            kind, size = "C", item.node[1]
        if size <= 0:
            self.fail(f"{function} needs a positive size", block, item)
        self.corner_waits = True
        return Corner(
            block, kind=kind, size=size, feed=words["F"][0] if "F" in words else None, col=item.start + 1
        )

    # -- path functions ---------------------------------------------------------------------
    def _target(self, words: dict) -> tuple[list[float], set[int]]:
        """End point of X/Y/Z (absolute) and IX/IY/IZ (incremental) words, and the axes written."""
        end = list(self.pos)
        written = set()
        for n, axis in enumerate(AXES):
            if axis in words:
                end[n] = words[axis][0]
                written.add(n)
            elif "I" + axis in words:
                end[n] = self.pos[n] + words["I" + axis][0]
                written.add(n)
        return end, written

    def _rotary(
        self, words: list[tuple[Word | ExprWord, float]], on_line: bool, machine_datum: bool
    ) -> list[float] | None:
        """Where the block's rotary words (`ROTARY_WORDS`) put A B C, on a line (`on_line`: L or LP,
        without M91 or a cycle call), a move as ISO's `G0 A0` is; None in another block, which may
        name them where they stand.  A turn is followed where the control turns by the difference
        (not under M126)."""
        item = words[0][0]
        if machine_datum:  # (the machine datum's rotary positions are not told)
            raise OutOfScope(f"the rotary axis word {item.letter} with M91", item.start + 1)
        axes = [ROTARY_WORDS[i.letter] for i, _ in words]
        end = self.rotary_end((k, value, incremental) for (k, incremental), (_, value) in zip(axes, words))
        if end == self.rotary:
            return end if on_line else None
        turned = next(i for (k, _), (i, _) in zip(axes, words) if end[k] != self.rotary[k])
        if not on_line:
            raise OutOfScope(f"a turn of the rotary axis {turned.letter[-1]} in a block other than a line L or LP",
                             turned.start + 1)  # fmt: skip
        if self.shortest_way:
            raise OutOfScope(f"a turn of the rotary axis {turned.letter[-1]} under M126 (the shortest way)",
                             turned.start + 1)  # fmt: skip
        return end

    def _path(
        self,
        block: Block,
        function: str,
        item,
        words: dict,
        rapid: bool,
        rotation: str | None,
        rotary: list[float] | None = None,
    ) -> list[Event]:
        end, written = self._target(words)
        if function == "L":
            return [self.line(block, end, rapid, rotary=rotary)] if written or rotary else []
        if function == "CC":
            return [self._set_pole(block, end, written)]
        if function == "C":
            return [self._circle(block, item, end, rotation)]
        if function == "CR":
            if "R" not in words:
                self.fail("CR without a radius R", block, item)
            clockwise = rotation != "+"
            centre = self.centre_from_radius(block, words["R"][1], end, words["R"][0], clockwise)
            return [self.arc(block, end, centre, -1 if clockwise else 1)]
        if function == "CT":
            return [self.tangential(block, end)]
        if function == "LP":
            return [self.line(block, self._polar(block, item, words, end), rapid, rotary=rotary)]
        if function == "CP":
            return [self._polar_arc(block, item, words, end, rotation)]
        raise OutOfScope(f"the path function {function}", item.start + 1)

    def _machine_move(self, block: Block, function: str, item, words: dict, rapid: bool) -> Line:
        """`L ... M91`: the coordinates are the machine datum's, and the tool length is not
        applied (TNC 640 Klartext manual, "Miscellaneous functions for coordinate data": "M91 and
        M92 are effective only in the blocks in which they are programmed ... the tool length,
        however, is not compensated").  The control's own position, left as programmed (MACHINE);
        the axes it names end there, the others stay where they stand."""
        if function != "L":
            raise OutOfScope(f"M91 with the path function {function}", item.start + 1)
        if self.rotation is not None and ("X" in words or "Y" in words):
            raise OutOfScope("M91 with X or Y under a rotation of CYCL DEF 10", item.start + 1)
        end, written = self._target(words)
        context = self.context()
        for n, axis in enumerate(AXES):
            if axis in words:  # machine position = program position + the context's offset (its tool too)
                end[n] = words[axis][0] - context.offset[n]
        move = self.line(block, end, rapid)
        move.fixed = MACHINE
        move.placed = (0 in written and AXES[0] in words, 1 in written and AXES[1] in words,
                       2 in written and AXES[2] in words)  # fmt: skip
        return move

    def _fn(self, block: Block, item) -> None:
        """FN 0-8, 13: a Q parameter set to one operand, an operation of two, or a function of one."""
        number, text = item.node
        operation = FN_ARITHMETIC[number]
        found = _FN_TARGET.fullmatch(text)
        operands: tuple[str, ...] | None = None
        if found is not None:
            body = found.group(2)
            if number == 0:
                operands = (body,)
            elif number in (5, 6, 7):
                unary = re.fullmatch(rf"{operation}[ \t]*(.+)", body, re.I)
                operands = None if unary is None else (unary.group(1),)
            else:
                binary = re.fullmatch(rf"(.+?)[ \t]*{re.escape(operation)}[ \t]*(.+)", body, re.I)
                operands = None if binary is None else (binary.group(1), binary.group(2))
        if (
            found is None
            or operands is None
            or not all(re.fullmatch(_FN_OPERAND, o.strip(), re.I) for o in operands)
        ):
            shape = "a" if number == 0 else f"{operation} a" if number in (5, 6, 7) else f"a {operation} b"
            self.fail(f"FN {number}: expected Q.. = {shape}", block, item)
        values = [self.value(_fn_operand(o), block, item) for o in operands]
        self.q[found.group(1).lower()] = self._fn_value(number, values, block, item)

    def _fn_value(self, number: int, values: list[float], block: Block, item) -> float:
        if number == 0:
            return values[0]
        if number in (5, 6, 7):
            (a,) = values
            if number == 5 and a < 0:
                self.fail("FN 5: the square root of a negative number", block, item)
            return (
                math.sqrt(a)
                if number == 5
                else math.sin(math.radians(a))
                if number == 6
                else math.cos(math.radians(a))
            )
        a, b = values
        if number == 4 and b == 0:
            self.fail("FN 4: division by zero", block, item)
        return FN_BINARY[number](a, b)

    def _preset(self, block: Block, item) -> None:
        """CYCL DEF 247: the first preset the program activates is the program zero ncpp was
        told; activating another one is out of scope."""
        number = next(
            (self.value(i.node[1], block, i) for i in block.items
             if type(i) is Statement and i.kind == "assignment" and i.node[0][1] == "q339"),
            None,
        )  # fmt: skip
        if number is None:
            self.fail("CYCL DEF 247 without Q339 (the preset number)", block, item)
        if self.rotation is not None:  # (the preset's own basic rotation replaces it: not followed)
            raise OutOfScope("CYCL DEF 247 under a rotation of CYCL DEF 10", item.start + 1)
        if any(self.shift):
            raise OutOfScope("CYCL DEF 247 with a datum shift of CYCL DEF 7 in effect (whether it stays "
                             "is not followed)", item.start + 1)  # fmt: skip
        if self.preset is None:
            self.preset = number
        elif number != self.preset:
            raise OutOfScope(
                f"CYCL DEF 247 activating preset {number:g} after preset {self.preset:g} (ncpp is told one "
                "program zero)",
                item.start + 1,
            )

    def _datum_shift(self, block: Block, item: Statement) -> None:
        """A line of CYCL DEF 7 (`SHIFT_CYCLE`): the datum moves, and with it the program coordinates
        of every point (the offset from program to machine); under radius compensation it is not
        followed, as a TOOL CALL there is not."""
        words = [i for i in block.items if (type(i) is Word or type(i) is ExprWord) and i.letter != "N"]
        if not words and item.node[0] in ("7", "7.0"):
            return  # (the cycle's head: its axes follow, a line each)
        axis = words[0].letter.removeprefix("I") if len(words) == 1 else ""
        if len(axis) != 1 or axis not in AXES:
            raise OutOfScope(f"CYCL DEF {item.node[0]} (a datum shift ncpp does not read)", item.start + 1)
        if self.radius_comp:
            raise OutOfScope("CYCL DEF 7 with radius compensation RL/RR", item.start + 1)
        if self.rotation is not None:  # (whether it shifts along the turned axes is not followed)
            raise OutOfScope("CYCL DEF 7 under a rotation of CYCL DEF 10", item.start + 1)
        k = AXES.index(axis)
        shift = self._word_value(words[0], block) + (self.shift[k] if words[0].letter[0] == "I" else 0.0)
        offset = list(self.offset)
        offset[k] += shift - self.shift[k]
        self.shift[k] = shift
        self.set_offset(offset)

    def _retract(self, block: Block, distance: float | str) -> Line:
        """M140 MB: after the block's move, the control retracts along the tool axis (away from the
        workpiece) by `distance` from where it stands, or with MB MAX to the end of the traverse
        range (TNC 640 Klartext manual, "Retraction in the tool-axis direction: M140"); left as
        programmed (MACHINE).  Where MB MAX ends ncpp is not told: the tool axis is unknown until
        a block names it (`_from_unknown`), and the event stands where the retract starts."""
        end = list(self.pos)
        if distance == "MAX":
            self.unknown_axes.add(self.tool_axis)
        else:
            end[self.tool_axis] += float(distance)
        move = self.line(block, end, True, absolute=False)
        move.fixed = MACHINE
        return move

    def _from_unknown(self, events: list[Event], words: dict) -> None:
        """Moves while an axis's position is unknown (after `M140 MB MAX`) run from where the
        control stands, which ncpp does not know: left as programmed, up to and with the first
        block that names the axis absolutely, which puts it where the program says."""
        for event in events:
            if type(event) is Line or type(event) is Arc:
                event.fixed = UNPLACED
        self.unknown_axes -= {n for n, axis in enumerate(AXES) if axis in words}

    def _set_pole(self, block: Block, end: list[float], written: set[int]) -> Pole:
        self.pole, self.pole_rotation = end, self.rotation
        self.pole_plane = _plane_of_axes(written, self.plane)
        return Pole(block, center=as_point(end), plane=self.pole_plane)

    def _need_pole(self, block: Block, item) -> list[float]:
        if self.pole is None:
            self.fail("a circle or polar move with no pole: program CC first", block, item)
        if self.pole_rotation != self.rotation:  # (whether the control turns it with the frame is not said)
            raise OutOfScope("a pole CC set before CYCL DEF 10 changed the rotation", item.start + 1)
        return self.pole

    def _circle(self, block: Block, item, end: list[float], rotation: str | None):
        centre = list(self._need_pole(block, item))
        plane = self.pole_plane
        self.check_radii(block, item, end, centre, plane)
        return self.arc(block, end, centre, 1 if rotation == "+" else -1, plane)

    def _polar(self, block: Block, item, words: dict, end: list[float]) -> list[float]:
        """End point of PR/IPR/PA/IPA about the pole (the third axis from Z/IZ-type words)."""
        pole = self._need_pole(block, item)
        a, b, _ = PLANE_AXES[self.pole_plane]
        radius = math.hypot(self.pos[a] - pole[a], self.pos[b] - pole[b])
        angle = math.degrees(math.atan2(self.pos[b] - pole[b], self.pos[a] - pole[a]))
        if "PR" in words:
            radius = words["PR"][0]
        elif "IPR" in words:
            radius += words["IPR"][0]
        if "PA" in words:
            angle = words["PA"][0]
        elif "IPA" in words:
            angle += words["IPA"][0]
        end = list(end)
        end[a] = pole[a] + radius * math.cos(math.radians(angle))
        end[b] = pole[b] + radius * math.sin(math.radians(angle))
        return end

    def _polar_arc(self, block: Block, item, words: dict, end: list[float], rotation: str | None):
        if "PR" in words or "IPR" in words:
            self.fail("CP takes no radius (it circles the pole at the current distance)", block, item)
        end = self._polar(block, item, words, end)
        centre = list(self._need_pole(block, item))
        turn = 1 if rotation == "+" else -1
        if "IPA" in words:
            sweep = abs(words["IPA"][0])
            if (words["IPA"][0] > 0) != (turn > 0):
                self.fail("the sign of IPA and the direction DR disagree", block, words["IPA"][1])
            full, rest = divmod(sweep, 360.0)
            turns = int(full) + (1 if rest > 1e-9 or full == 0 else 0)
            turn *= turns
        return self.arc(block, end, centre, turn, self.pole_plane)


interpret = placed_interpreting(HeidenhainInterpreter)
