"""Sinumerik 840D blocks -> motion events (`Line`, `Arc`, `Pass`), like `ncpp.motion.interpret`.

Scope: G0-G3 with I/J/K (incremental, `I=AC(..)` absolute) or `CR=` (negative:
more than a half circle), `TURN=` extra helix turns, `CIP` with `I1=/J1=/K1=`
(an arc through an intermediate point, in a principal plane), `CT` (tangential
arc), G90/G91 and `AC()`/`IC()` per word, the rotary axes A B C (`ROTARY`), G17/G18/G19, G70/G71/G700/G710,
`TRANS`/`ATRANS` and `ROT`/`AROT` in G17 (`_frame`: the moves in the turned frame, `Context.rotation`),
R parameters and `DEF` variables with
arithmetic, labels, `MSG`, G4 dwell, M2/M17/M30 (end), and tool lengths: `T n`
or `T="NAME"` selects, M6 loads it with cutting edge D1, `D n` picks an edge
(D0 none); the edge's lengths 1-3 from the control's tool offsets (`_N_TO_INI`,
`tools.py`) act along the plane's axes (G17: length 1 along Z).  Control flow (GOTOF,
GOTOB, GOTO, GOTOC, CASE, IF, WHILE, FOR, REPEAT, LOOP; REPEAT label and REPEATB, program
section repetition) runs as `sinumerik_flow.py` says: a
loop's moves are left as programmed (FLOW), or with --expand each run is written out
(`sinumerik_expand.py`), as are subprogram calls.  The drilling, tapping and boring cycles
CYCLE81-CYCLE89 and CYCLE840, called once or under MCALL, are followed (`sinumerik_cycles.py`),
as are the hole patterns HOLES1 and HOLES2 under MCALL (their moves left as programmed,
PATTERN).  A subprogram call (`L<n>`, a name, `PCALL` with a path, value parameters and parameters by
reference (VAR) of its PROC, `P` runs) runs the subprogram's file from the subroutine path to M17 or
RET (`_call`, `_bind`): its moves are left as
programmed (FLOW), and the moves after the call are compensated.  Calls of other cycles, the
patterns CYCLE801 and CYCLE802, subprogram files not found, splines, other frames, polar
coordinates (AP=, RP=),
arcs by opening angle (AR=) and unknown G codes make the position unknown: one warning (an error with `strict`) and the
rest passes through.  Under cutter compensation (G41/G42 to the first move after
G40) the moves are the programmed contour, the tool centre off it by the edge's radius
($TC_DP6 + $TC_DP15 in `_N_TO_INI`): in G17, G18 and G19 (left and right as seen from the
positive applicate), in G90 or G91 and with AC()/IC() words, they carry where the tool centre
stands (`centre_shift`, `ModalInterpreter.radius_compensation`), the entry move's end square
to the contour's first element with NORM (and KONT in front of it: `ToolCentre.approach`),
else (an entry or exit arc, a block that turns it to the other side, a loop's) they are marked
`fixed`; M6 or D under it, and KONTC and KONTT, are out of scope.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import numpy as np

from ncpp.errors import Location, Warnings
from ncpp.motion.called import Files, count_called, searched
from ncpp.motion.endless import Revisits
from ncpp.motion.flow import FIXED, ONCE, RUN, SKIP, TEXT, Around, CountedPasses
from ncpp.motion.modal import (
    MAX_HOLES,
    MM_PER_INCH,
    ModalInterpreter,
    OutOfScope,
    as_point,
    circle_through,
    placed_interpreting,
    plane_of,
)
from ncpp.motion.once import FirstPass
from ncpp.motion.segments import FLOW, MACHINE, PATTERN, PLANE_AXES, Event, Line, Pass, Setting
from ncpp.motion.sinumerik_cycles import PARAMETERS as DRILLING
from ncpp.motion.sinumerik_cycles import CycleError, Drilling, drilling
from ncpp.motion.sinumerik_expand import SinumerikExpansion
from ncpp.motion.sinumerik_flow import SinumerikFlow, is_repetition
from ncpp.motion.tools import ToolTable, UntoldLengths
from ncpp.program.blocks import Block, Comment, ExprWord, Statement, Word

AXES = "XYZ"
# The rotary axes A B C: `A90` absolute in G90, incremental in G91, `A=AC(..)` / `A=IC(..)` absolute /
# incremental in either; `A=DC(..)` turns by the shortest way to its position within a turn (840D sl
# Programming Manual Fundamentals, "Absolute dimensions for rotary axes (DC, ACP, ACN)"): followed where
# the axis stands there (the shortest way is none), else, and ACP / ACN, out of scope.  A turn is followed
# on a line G0 / G1 (`_move`).
ROTARY = ("A", "B", "C")
CENTRE_LETTERS = "IJK"
INTERMEDIATE = ("I1", "J1", "K1")
# G codes that change nothing the motion depends on (exact stop, continuous path, feed types, work offsets
# the control holds, spindle modes, acceleration; G40-G42 are read apart: `block`)
NEUTRAL_G = frozenset((9.0, 40.0, 41.0, 42.0, 60.0, 64.0, 601.0, 602.0, 603.0, 641.0, 642.0,
                       643.0, 644.0, 645.0, 94.0, 95.0, 96.0, 97.0, 450.0, 451.0, 961.0, 971.0))  # fmt: skip
# Settable frames (G54-G57, G505-G599) and G500, which turns them off: the program zero ncpp is
# told is the frame the program selects first (or the one in effect, if it selects none); a move
# under another is out of scope
SETTABLE_FRAMES = frozenset((54.0, 55.0, 56.0, 57.0, *(float(n) for n in range(505, 600))))
NO_SETTABLE_FRAME = 500.0
# Non-modal machine coordinates: G53 suppresses the settable and programmable frames, G153 the
# basic frame too, SUPA every offset (840D sl Programming Manual, Fundamentals, "Frame
# suppression"); with no basic frame or external offsets, as ncpp assumes, all three are the
# machine's coordinates (the tool offset still applies)
MACHINE_G = frozenset((53.0, 153.0))
UNITS_G = {70.0: True, 700.0: True, 71.0: False, 710.0: False}
HARMLESS_CALLS = frozenset(("MSG", "BNAT", "ENAT", "BTAN", "ETAN", "BAUTO", "EAUTO", "FFWON", "FFWOF", "SOFT",
                            "BRISK", "CFC", "CFTCP", "CFIN", "M",
                            # what CAM posts write that moves no axis (840D sl Job Planning manual):
                            # the compressor, a preprocessing stop, the blank for simulation, feed
                            # groups, radius programming, and a transformation off or its
                            # orientation modes (this interpreter stops at any that turns one on)
                            "COMPOF", "COMPCAD", "COMPCURV", "COMPSURF", "STOPRE", "WORKPIECE", "FGROUP",
                            "UPATH", "SPATH", "DIAMOF", "TRAFOOF", "ORIWKS", "ORIMKS", "ORIAXES", "ORIVECT",
                            # the feedrate profile over a block, not its path (840D sl Programming
                            # Manual, Fundamentals, "Feedrate characteristic (FNORM, FLIN, FCUB)")
                            "FNORM", "FLIN", "FCUB",
                            # waits and settings that move no axis of the path (Job Planning manual):
                            # the wait for a positioning axis or a spindle, the master spindle, the end
                            # of an interrupt assignment
                            "WAITP", "WAITS", "SETMS", "CLRINT",
                            # the editor's program blocks, which group lines for display (SINUMERIK
                            # Operate Milling operating manual, "Creating program blocks")
                            "GROUP_BEGIN", "GROUP_END"))  # fmt: skip
# Calls that move nothing when given no arguments: CYCLE800() deselects the swivelled plane without
# turning an axis (SINUMERIK 840D sl Milling manual, "Swiveling plane - CYCLE800": "CYCLE800()"
# resets the swivel frames); CYCLE832() deselects the high-speed settings.  CYCLE832 with its
# arguments sets the contour tolerance and smoothing only ("High-speed settings - CYCLE832").
RESETTING_CALLS = frozenset(("CYCLE800", "CYCLE832"))
SETTING_CALLS = frozenset(("CYCLE832",))
# Hole patterns that run the modal drilling cycle at positions of their own (Programming Guide Cycles,
# "Drilling patterns"): their positioning moves are the control's, made from one block that cannot
# carry their corrections.  HOLES1 and HOLES2 are followed (`_pattern`); the order of a grid's
# (CYCLE801) holes is the cycle's own and CYCLE802's positions come with a mask of its own: not followed
HOLE_PATTERNS = frozenset(("HOLES1", "HOLES2", "CYCLE801", "CYCLE802"))
FOLLOWED_PATTERNS = {"HOLES1": 6, "HOLES2": 6}  # and how many parameters each reads
END_M = frozenset((2.0, 17.0, 30.0))
# Addresses that say where the tool goes in a way this interpreter does not follow
UNREAD_GEOMETRY = {
    "AR": "the opening angle",
    "AP": "the polar angle",
    "RP": "the polar radius",
    # The control inserts a chamfer or an arc at the corner the block ends in, or finds the end point
    # from the angle; a measuring move stops where the probe switches (MEAS) or records that place.
    "CHF": "the chamfer",
    "CHR": "the chamfer",
    "RND": "the rounding",
    "RNDM": "the modal rounding",
    "ANG": "the contour angle",
    "MEAS": "the measuring move",
    "MEAW": "the measuring move",
    # The tool's length or radius changed in the program, or by a sum offset from the control's table
    "TOFFL": "the programmable tool length offset",
    "TOFFR": "the programmable tool radius offset",
    "DL": "the sum offset",
    # A corner's transition circle, and a smooth approach or retraction the control shapes itself
    "DISC": "the transition circle",
    "DISR": "the approach distance",
    "DISCL": "the approach distance",
    "DISRP": "the approach distance",
}
# Frame instructions followed (`_frame`): translations, rotations in the plane G17 (about Z); a bare
# substituting ROT / SCALE / MIRROR resets the frame.
FRAMES = frozenset(("TRANS", "ATRANS", "ROT", "AROT", "SCALE", "MIRROR"))


# The axis (X, Y, Z index) that lengths 1, 2 and 3 of a milling tool act along, per plane
LENGTH_AXES = {17: (2, 1, 0), 18: (1, 0, 2), 19: (0, 2, 1)}
SIDES = {41.0: 1, 42.0: -1, 40.0: 0}  # cutter compensation's side of the contour (0: off)
APPROACHES = frozenset(("NORM", "KONT", "KONTC", "KONTT"))  # how compensation approaches the contour
TOOL_CHANGE = 6.0  # M6 loads the tool T selected, with its cutting edge D1 unless the block says another


_FROM_THE_CALLER = "(the caller's value)"  # a PROC parameter's value: not told


MAX_ELEMENTS = 65_536  # the elements of an array this interpreter holds (each is a variable)

# Subprograms (840D sl Programming Manual, Fundamentals, "Subprogram technique"): a program runs
# another by its name (`MYSUB`, `MYSUB(1, 2)` for `PROC MYSUB(REAL A, INT B)`) or its number
# (`L100`; leading zeros count: L0100 is another), `P` times (1-9999); M17 or RET returns.  The
# control nests up to 16 program levels, the main program's among them.
MAX_RUNS = 9999
MAX_PROGRAM_LEVELS = 16
# A name a subprogram can be called by: two letters or `_` and a letter first ("Subprogram names"),
# or L and 1-7 digits, a subprogram's by number, which a PROC's parameters may follow, `L140(2)`
_SUBPROGRAM_NAME = re.compile(r"(?:[A-Z]{2}|_[A-Z])\w*|L\d{1,7}", re.I)
# The Siemens cycles and their helpers, which stay as the cycles they are (`block`), not files
KNOWN_CYCLE = re.compile(r"CYCLE\d|POCKET\d|SLOT\d|LONGHOLE|HOLES\d|E_|F_", re.I)
# The prefixes Siemens reserves for its cycles that a name of letters and underscores may still begin with
# (Programming Manual Fundamentals 12/2019, "Naming rules": "The first two characters should be letters or
# underscores"; E_ and F_ "reserved for SIEMENS cycles"): the control runs the program of the called name,
# so one found on the subroutine path is the user's own (`_own_program`)
SHOP_CYCLE = re.compile(r"[EF]_\w+", re.I)
# Predefined procedures that call programs otherwise than by their name (`PCALL` with its path: `_call_path`)
CALL_KEYWORDS = frozenset(("PCALL", "CALLPATH", "MCALL", "RET"))
# Predefined procedures of the control (Job Planning manual, "Tables: list of instructions"), not
# subprograms: the transformations, diameter programming, curve tables, interrupt routines, a block
# run from a string, the tool-management functions.  Not followed, and named as what they are.
PREDEFINED_PROCEDURES = frozenset((
    "TRAORI", "TRANSMIT", "TRACYL", "TRAANG", "TRACON", "DIAMON", "DIAM90", "DIAMCYCOF", "CTABDEF", "CTABEND",
    "SETINT", "EXECSTRING", "EXECTAB", "GETT", "GETSELT", "GETEXET", "FIFOCTRL", "CUT2DF", "CUT3DC", "CUT3DF",
    "CUT3DFF", "CUT3DFS", "POSA", "SPOSA", "LEADON", "EGON", "COUPON",
))  # fmt: skip
# The actual-value settings (SINUMERIK 828D Basic Functions function manual 01/2023, "Axes,
# coordinate systems, frames", "Coordinate systems": `PRESETONS(<axis>, <value>)` makes <value> the
# machine axis's actual value in the machine coordinate system, where it stands, so shifting that
# system's zero, $AC_PRESET, by the difference): the program's zero moves with it (`_preset`)
PRESETS = frozenset(("PRESETON", "PRESETONS"))
# Control statements after which the flow may run blocks again (`sinumerik_flow`): their moves the line's
RUNS_OTHERS = frozenset(("endwhile", "endfor", "until", "endloop", "goto", "case"))
# PROC attributes that change nothing the motion depends on: the display and single-block
# behaviour of the subprogram's blocks (SAVE, which restores the caller's modal state, is not followed)
HARMLESS_PROC_ATTRIBUTES = frozenset(("DISPLOF", "DISPLON", "SBLOF", "SBLON", "ACTBLOCNO"))
# the channel's R parameters: shared by every program level, and by every program the channel runs
# (SINUMERIK 840C installation guide, NC setting data, "R parameters": R100-R199 "memory for data which
# must be accessible for the main programs and subroutines", R110-R199 the measuring cycles' results),
# so one a program reads before it sets it holds an earlier program's value, not 0
_R_PARAMETER = re.compile(r"r\d+")
# `_N_MYSUB_SPF`, `MYSUB_SPF`: a name with the control's own prefix and type (all are the same program)
_CONTROL_NAME = re.compile(r"(?:_N_)?(\w+?)(?:_(SPF|MPF))?", re.I)
# The types a parameter by reference (VAR) is followed for: a scalar's, an array's
REFERENCE_TYPES = frozenset(("REAL", "INT", "STRING"))
ARRAY_REFERENCE_TYPES = frozenset(("REAL", "INT"))


@dataclass(frozen=True)
class _Reference:
    """A parameter by reference (VAR): the caller's variable it names, by its key among the caller's
    variables (`r1`, `width`, `feld[2]`), or the caller's array and its sizes."""

    parameter: str
    key: str
    integer: bool  # an INT's (assignments round)
    sizes: tuple[int, ...] | None = None  # an array's


@dataclass(frozen=True)
class _Call:
    """A subprogram call: the file, its blocks, its PROC parameters' values and references, its runs."""

    name: str
    path: Path
    blocks: list[Block]
    parameters: dict
    runs: int
    references: tuple[_Reference, ...] = ()


class SinumerikInterpreter(ModalInterpreter):
    # (the counts of blocks run and the counted loops around a subprogram's run: no loop's state)
    not_loop_state = ModalInterpreter.not_loop_state | {"called_passes", "outside"}

    def __init__(
        self,
        file: str = "<stdin>",
        zero: tuple[float, float, float] = (0.0, 0.0, 0.0),
        tools: ToolTable | None = None,
    ):
        super().__init__(file, zero)
        self.tools = tools  # the control's tool offsets (_N_TO_INI), if told
        self.selected: float | str = 0.0  # the tool T selected: a number, or a name
        self.loaded: float | str = 0.0  # the tool M6 loaded (0: none)
        self.edge = 0  # the cutting edge D in effect (0: no tool offset)
        self.edge_told = False  # M6 or D said the edge (before it, the control's own is in effect)
        # the block just run applied a told edge's lengths: (D, its length 1 in mm), which the
        # tool guard checks after the block (`guard.sinumerik_tool_guard_lines`)
        self.length_told: tuple[int, float] | None = None
        self.untold_lengths = UntoldLengths()  # warns where a tool length applies that nothing tells
        self.motion: float | str = 0.0  # 0-3, 'CIP' or 'CT' (G0 after power on)
        self.absolute = True
        self.variables: dict[str, float | str] = {}
        self.integers: set[str] = set()  # DEF INT variables round on assignment
        self.arrays: dict[str, tuple[int, ...]] = {}  # DEF arrays' sizes (their elements are variables)
        # A subprogram's parameters by reference that name a variable held under another key: an R
        # parameter (the channel's, shared) or another parameter given the same variable (`_bind`)
        self.aliases: dict[str, str] = {}
        self.started = False  # a block has run (a PROC opens the program or is out of scope)
        self.modal_cycle: Drilling | None = None  # MCALL's drilling cycle, run after each block that moves
        self.spindle = 0.0  # the spindle speed S programmed (rev/min): a tapping cycle's feed follows it
        # A frame's offset is traversed with the axis's next incremental move (MD 42440
        # FRAME_OFFSET_INCR_PROG = 1): IC(d) after TRANS goes d from the old program position.
        self.frame_shift = [0.0, 0.0, 0.0]
        self.told_frame: float | None = None  # the settable frame the program selected first
        self.zero_frame: float | None = None  # the one in effect (None: as when the program started)
        self.calls: list[str] = []  # the subprograms running, outermost first
        self.called: _Call | None = None  # the subprogram the block just run calls
        self.returned = False  # M17 or RET ended the subprogram running
        self.called_blocks = 0  # blocks run in subprogram files so far
        # A call's P runs and the counted loops around it, measured in blocks run in subprogram files
        # (`called_blocks`, whose bound a program that calls for ever passes)
        self.called_passes = CountedPasses(file)
        # The counted loops around the subprogram running, innermost first (`_subprogram`)
        self.outside: Callable[[], list[Around]] = list
        self._files: Files | None = None  # the subprogram files, once a call needs them
        self.centre.approach = "NORM"  # (the control's initial setting: `ToolCentre.approach`)
        self.expansion: SinumerikExpansion | None = None  # --expand: what it writes (`sinumerik_expand`)

    def loop_quick(self) -> object:
        """The position and the variables (copies), compared first of a loop's state."""
        return self.pos[:], dict(self.variables)

    # -- the event stream ---------------------------------------------------------------
    def run(self, blocks: Iterable[Block], warnings: Warnings) -> Iterator[Event]:
        """Events block by block, in the order the blocks run (`sinumerik_flow.py`): a block
        run out of the text's order gives its moves, left as programmed, to the line that
        runs it (its `owner`), so that every block's text is written once, where it stands;
        with --expand (`expand`) each run of it is written where it runs (`sinumerik_expand`)."""
        main = self.variables  # (the main program's: a subprogram runs with its own, `_subprogram`)
        self.expansion = SinumerikExpansion(lambda: main, self.file) if self.expand else None
        return self.approached(self._run(blocks, warnings, None))

    def _run(self, blocks: Iterable[Block], warnings: Warnings, caller: Block | None) -> Iterator[Event]:
        """`run` over the program (`caller` None) or over a subprogram file the line `caller`
        calls: its blocks all run out of the text's order, their moves the caller's, and its
        text is no part of the output."""
        expansion = self.expansion

        def leave(reason: str, block: Block, col: int | None, owner: Block | None) -> None:
            if expansion is not None:  # (a control line out of scope inside a stretch written out)
                inside = caller is not None or owner is not None or _inside(flow)
                expansion.refuse(reason, Location(self.file, block.line, col), inside)
            self.leave_scope(warnings, reason, block, col, caller or owner)

        flow = SinumerikFlow(self.file, self.value, self._count, lambda: self.done or self.returned, leave,
                             Revisits(None, None, self.loop_quick, self.loop_state), self.outside)  # fmt: skip
        once: FirstPass | None = None  # a loop's first pass in its place, while the flow has not told
        for block, kind, owner in flow.steps(blocks):
            if caller is not None:
                if kind is not RUN and kind is not FIXED and kind is not ONCE:
                    continue
                kind, owner = FIXED, caller
                self.called_blocks = count_called(self.called_blocks, self.program_file, caller)
                self.called_passes.steps = self.called_blocks
            if kind is ONCE and (expansion is not None or (once is not None and once.full())):
                kind = FIXED  # (--expand writes each run out; a longer first pass stays as programmed)
            if once is not None and (self.done or flow.in_straight_code() or once.full()):
                yield from self._told(once, flow, again=self.left or once.full())
                once = None
            if kind is ONCE and once is None:
                once = FirstPass(_as_programmed)
            elif once is not None and kind is FIXED and owner is not None and once.rerun(block):
                yield from self._told(once, flow, again=True)  # (all of it runs again: nothing to hold)
                once = None
            events = self._events_of(block, kind, owner, flow, caller, warnings)
            if once is None:
                yield from events
            else:
                for event in events:
                    once.add(event, block, again=kind is FIXED)

    def _events_of(
        self, block: Block, kind: str, owner: Block | None, flow: SinumerikFlow, caller: Block | None,
        warnings: Warnings,
    ) -> Iterator[Event]:  # fmt: skip
        """The events of one block the flow yields (`_run`)."""
        expansion = self.expansion
        if (kind is not RUN and kind is not FIXED and kind is not ONCE) or not block.items:
            if owner is None:  # (a block run out of the text's order is written in its place)
                if expansion is not None and block.items:
                    kept = expansion.text(self.done, block)
                    if kept is None:  # (a control line, text that does not run: left out)
                        return
                    yield from kept
                runs_others = kind is TEXT and not self.done and _runs_others(block)
                yield Pass(block, kind is SKIP, self.motion if runs_others else None)
            return
        if expansion is not None:
            yield from self._expanded(expansion, flow, block, kind, owner, caller, warnings)
            return
        # (a first pass's moves are not followed under cutter compensation: they may run again)
        self.again = kind is not RUN
        self.length_told = None
        try:
            events = self.block(block)
        except OutOfScope as stop:
            self.called = None
            self.leave_scope(warnings, stop.reason, block, stop.col, owner)
            if owner is None:  # (a block run out of the text's order is written in its place)
                # (a setting's step back where the block runs once, in its place: `_preset`)
                yield Pass(block, setting=stop.setting if kind is RUN and caller is None else None)
            return
        moves = [event for event in events if type(event) is not Pass]
        if kind is FIXED:
            for move in moves:
                move.fixed = move.fixed or FLOW  # type: ignore[union-attr]
                if owner is not None:
                    move.block = owner
        elif moves and kind is RUN:
            flow.last_run_move = flow.pc
        elif moves:
            flow.once_move = flow.pc
        if kind is FIXED and owner is not None:
            yield from moves
        else:  # (a call's line: the mode its subprogram starts in, `SinumerikWriter.written_at_once`)
            yield from events or (Pass(block, False, self.motion if self.called is not None else None),)
            if self.length_told is not None and kind is not FIXED:  # (a block that runs again: none)
                yield Pass(block, length_told=self.length_told)
        if self.called is not None:
            call, self.called = self.called, None
            yield from self._subprogram(call, owner or block, warnings, flow, block)

    def _told(self, once: FirstPass, flow: SinumerikFlow, again: bool) -> list[Event]:
        """A loop's first pass in its place, once the flow has told whether its text runs again
        (`ncpp.motion.once`); a backward jump may no longer run what ran so."""
        if not again:
            flow.last_run_move = max(flow.last_run_move, flow.once_move)
        flow.once_move = -1
        return once.told(again)

    def _expanded(
        self,
        expansion: SinumerikExpansion,
        flow: SinumerikFlow,
        block: Block,
        kind: str,
        owner: Block | None,
        caller: Block | None,
        warnings: Warnings,
    ) -> Iterator[Event]:
        """With --expand, a block that runs: where it stands and runs once, as it is (after the
        assignments that settle the variables it may read); in a loop, a jump's loop or a
        subprogram, as this run's numbers; a call's line left out, the subprogram's runs written
        in its place.  (No backward jump is refused for the moves it goes over: they are written
        again, `flow.last_run_move` stays.)"""
        in_place = kind is RUN and caller is None
        self.again, self.length_told = False, None
        settling: tuple[Event, ...] = ()
        try:
            if in_place:
                settling = expansion.settle(block)
            else:
                expansion.start_body(block)
            events = self.block(block)
            written: Block | None = block
            if self.called is not None:  # (a call's line: its subprogram's blocks written for it)
                expansion.left_out(block)
                written = None
            elif not in_place:
                written = expansion.body(block, self.value, caller is None, owner is None)
        except OutOfScope as stop:
            self.called = None
            inside = not in_place or owner is not None or _inside(flow)
            expansion.refuse(stop.reason, Location(self.file, block.line, stop.col), inside)
            self.leave_scope(warnings, stop.reason, block, stop.col, owner)
            if owner is None:
                yield from settling
                yield Pass(block)
            return
        yield from settling
        if written is not None:
            for event in events:
                event.block = written
            yield from events or (Pass(written),)
            if self.length_told is not None and in_place:  # (a run written out of a loop: none)
                yield Pass(written, length_told=self.length_told)
        if self.called is not None:
            call, self.called = self.called, None
            yield from self._subprogram(call, owner or block, warnings, flow, block)

    # -- subprogram calls (840D sl Programming Manual, Fundamentals, "Subprogram technique") --
    def _call(self, block: Block, item: Word | Statement, name: str, args: tuple) -> _Call:
        """A call of subprogram `name` (`L100`, `MYSUB`, `MYSUB(1, 2)`), alone in its block but for
        its block number, labels, comments and `P` (the number of runs, 1-9999): its file from
        the subroutine path, its `PROC` parameters given the call's values."""
        runs = 1
        for other in block.items:
            if other is item or type(other) is Comment or (type(other) is Word and other.letter in "N:"):
                continue
            if type(other) is Statement and other.kind == "label":
                continue
            if (type(other) is Word or type(other) is ExprWord) and other.letter == "P":
                value = self._word_value(other, block)[0] if type(other) is ExprWord else other.value
                if value != round(value) or not 1 <= value <= MAX_RUNS:
                    self.fail(f"P{value:g}: a subprogram runs 1 to {MAX_RUNS} times", block, other)
                runs = int(value)
                continue
            raise OutOfScope(f"the subprogram call {name} with more in its block", other.start + 1)
        if len(self.calls) + 1 >= MAX_PROGRAM_LEVELS:
            self.fail(f"the subprogram call {name} nests deeper than the control's {MAX_PROGRAM_LEVELS} "
                      "program levels (the main program's and its subprograms')", block, item)  # fmt: skip
        names = _subprogram_files(name)
        files = self._files = self._files or Files(self.subroutine_path, "sinumerik")
        path = files.find(names)
        if path is None:  # (a name may be a predefined procedure ncpp does not follow, or a subprogram)
            what = "the subprogram call" if type(item) is Word else "call"
            raise OutOfScope(
                f"{what} {name} (its file not found: {searched(self.subroutine_path, names)})", item.start + 1
            )
        blocks = files.blocks(path)
        parameters, references = self._parameters(blocks, name, args, block, item)
        if (parameters or references) and runs > 1:
            raise OutOfScope(f"the subprogram call {name} with parameters and P (later runs keep the "
                             "values the first left)", item.start + 1)  # fmt: skip
        return _Call(name, path, blocks, parameters, runs, references)

    def _own_program(self, name: str) -> bool:
        """Whether `name`, one of the ShopMill/ShopTurn cycles' (`E_...`, `F_...`), is a program of
        the user's on the subroutine path (`F_TP_GRINDING(..)` beside its main program), which the
        control runs as any called program; a cycle of the control's is not there."""
        if not SHOP_CYCLE.fullmatch(name) or not self.subroutine_path:
            return False
        files = self._files = self._files or Files(self.subroutine_path, "sinumerik")
        return files.find(_subprogram_files(name.upper())) is not None

    def _indirect(self, expr: tuple, block: Block, item) -> str:
        """The program `CALL` or `EXTCALL` names: a string, or a string variable's value (Job Planning
        manual, "Indirect program call (CALL)"; Function Manual Basic Functions K1, "Program control",
        EXTCALL: `EXTCALL("<path/><program name>")`, the name with or without `_N_` and its type
        after `_` or `.`); its folders, the control's or a drive's, dropped: the file is looked for
        in the subroutine path, as the control looks in its program memories."""
        name = expr[1] if expr[0] == "str" else None
        if expr[0] == "param":
            name = self.variables.get(self._key(expr[1]))
        if type(name) is not str or not name.strip("/\\"):
            raise OutOfScope(f"{item.node[0]} of a program named other than by a string", item.start + 1)
        return _program_of(name)

    def _call_path(self, block: Block, item: Statement) -> _Call:
        """`PCALL/_N_WKS_DIR/_N_SHAFT_WPD/SHAFT(R1, 2)` (Job Planning manual, "Subprogram call with
        path specification and parameters (PCALL)"): the program the path ends in, with the
        parameters of a call by its name; its folders dropped, as `_indirect`'s.  Without a path
        (`PCALL SHAFT(1)`) PCALL calls as the program's name alone does."""
        path, *args = item.node[1]
        return self._call(block, item, _program_of(path[1]), tuple(args))

    def _parameters(
        self, blocks: list[Block], name: str, args: tuple, block: Block, item
    ) -> tuple[dict, tuple[_Reference, ...]]:
        """The subprogram's PROC parameters (its first block, if any) given the call's values
        (840D sl Job Planning manual, "Subprograms with parameter transfer": an omitted value
        parameter is 0, an empty string), and its parameters by reference (VAR: `_reference`)."""
        proc = next((i for b in blocks for i in b.items if type(i) is Statement and i.kind == "proc"), None)
        declared = () if proc is None else proc.node[1]
        if len(args) > len(declared):
            self.fail(f"{name} takes {len(declared)} parameters, not {len(args)}", block, item)
        if proc is not None:
            extra = [a for a in proc.node[2] if a.upper() not in HARMLESS_PROC_ATTRIBUTES]
            if extra:
                raise OutOfScope(f"the subprogram {name} with PROC ... {extra[0].upper()}", item.start + 1)
        values: dict[str, float | str] = {}
        references: list[_Reference] = []
        for (kind, parameter, by_reference, dims), arg in zip(declared, (*args, *(None,) * len(declared))):
            if by_reference and kind in (REFERENCE_TYPES if dims is None else ARRAY_REFERENCE_TYPES):
                references.append(self._reference(name, (kind, parameter, dims), arg, block, item))
                continue
            if by_reference or dims is not None or kind not in ("REAL", "INT", "BOOL", "STRING"):
                what = "VAR " if by_reference else ""
                raise OutOfScope(f"the subprogram {name}'s parameter {what}{kind} {parameter.upper()}",
                                 item.start + 1)  # fmt: skip
            if kind == "STRING":
                if arg is not None and arg[0] != "str":
                    self.fail(f"{name}: the STRING parameter {parameter.upper()} given a number", block, item)
                values[parameter] = "" if arg is None else arg[1]
                continue
            value = 0.0 if arg is None else self.value(arg, block, item)
            values[parameter] = float(round(value)) if kind == "INT" else value
        _refuse_overlaps(references, name, item)
        return values, tuple(references)

    def _reference(self, name: str, declared: tuple, arg: tuple | None, block: Block, item) -> _Reference:
        """A parameter by reference (VAR) given the caller's variable `arg` (Job Planning manual,
        "Subprograms with parameter transfer", call-by-reference: the subprogram reads and writes
        the caller's variable itself): an R parameter, a variable or an array element the program
        defined, or (`VAR REAL X[]`, `X[,3]`) an array of the program of those sizes, of the
        parameter's type.  Anything else (a value, an omitted parameter, a variable the program
        does not define: a global user variable, a system variable) is out of scope."""
        kind, parameter, dims = declared
        what = f"the subprogram {name}'s parameter VAR {kind} {parameter.upper()}"
        where = item.start + 1
        if arg is None:
            raise OutOfScope(f"{what} not given (call by reference names a variable of the caller)", where)
        if dims is not None:
            return self._array_reference(what, parameter, kind, dims, arg, block, item)
        if arg[0] == "index":
            key, integer = self._element(arg, block, item), self._key(arg[1]) in self.integers
        elif arg[0] == "param":
            key = self._key(arg[1])
            integer = key in self.integers
            if key not in self.variables and not _R_PARAMETER.fullmatch(key):
                raise OutOfScope(f"{what} given {arg[1].upper()} (not defined in the program)", where)
        else:
            raise OutOfScope(f"{what} given a value (call by reference names a variable of the caller)",
                             where)  # fmt: skip
        value = self.variables.get(key, 0.0)
        if value is _FROM_THE_CALLER:
            raise OutOfScope(f"the parameter {key.upper()} (its value comes from the caller)", where)
        if (kind == "STRING") != (type(value) is str) or (kind == "INT") != integer:
            raise OutOfScope(f"{what} given {key.upper()}, a variable of another type", where)
        return _Reference(parameter, key, integer)

    def _array_reference(
        self, what: str, parameter: str, kind: str, dims: tuple, arg: tuple, block: Block, item
    ) -> _Reference:
        """`VAR REAL X[]`, `VAR INT X[,3]` given an array of the program: its sizes, each the
        parameter gives (a number) the array's."""
        key = self._key(arg[1]) if arg[0] == "param" else ""
        sizes = self.arrays.get(key)
        where = item.start + 1
        if sizes is None:
            raise OutOfScope(f"{what} given other than an array of the program", where)
        given = dims or (None,)  # (`X[]`: one size, not given)
        if len(given) != len(sizes) or any(
            size is not None and (size[0] != "num" or size[1] != n) for size, n in zip(given, sizes)
        ):
            raise OutOfScope(f"{what} given the array {key.upper()}{list(sizes)} of other sizes", where)
        if (kind == "INT") != (key in self.integers):
            raise OutOfScope(f"{what} given {key.upper()}, an array of another type", where)
        return _Reference(parameter, key, kind == "INT", sizes)

    def _subprogram(
        self, call: _Call, caller: Block, warnings: Warnings, flow: SinumerikFlow, at: Block
    ) -> Iterator[Event]:
        """The subprogram's runs: its blocks run as the program's, with variables of their own
        (the R parameters are the channel's, shared), to M17 or RET.  Its P runs are a counted
        loop at the calling line `at` of `flow` (`CountedPasses`), inside the loops around the call."""
        outer = (self.file, self.variables, self.integers, self.arrays, self.started, self.aliases)
        outside, around_call = self.outside, flow.enclosing
        what = f"the subprogram call {call.name} P{call.runs}"

        def around_run(left: int) -> Callable[[], list[Around]]:
            """The counted loops around one run: its P runs still to run, those around the call."""
            return lambda: [Around(left, call.runs, at.line, what, outer[0]), *around_call()]

        self.calls.append(call.name)
        self.file = str(call.path)
        mark: int | None = self.called_passes.steps
        try:
            for run in range(call.runs):
                left = call.runs - 1 - run
                self.outside = around_run(left)
                self.variables = {k: v for k, v in outer[1].items() if _R_PARAMETER.fullmatch(k)}
                self.variables.update(call.parameters)
                self.integers, self.arrays, self.started = set(), {}, False
                self._bind(call.references, outer[1])
                yield from self._run(call.blocks, warnings, caller)
                shared = {k: v for k, v in self.variables.items() if _R_PARAMETER.fullmatch(k)}
                outer[1].update(shared)
                if self.done:
                    return
                if not self.returned:
                    if self.expansion is not None:
                        where = call.blocks[-1] if call.blocks else caller
                        reason = f"the subprogram {call.name} ending without M17 or RET"
                        self.expansion.refuse(reason, Location(self.file, where.line, None), True)
                    self.leave_scope(warnings, f"the subprogram {call.name} ends without M17 or RET",
                                     call.blocks[-1] if call.blocks else caller, None, caller)  # fmt: skip
                    return
                self.returned = False
                self._give_back(call.references, outer[1])
                if left:
                    around = around_call if run == 0 else None  # (its first run ended: the loops around it)
                    mark = self.called_passes.ended(mark, self.called_blocks, left, at.line, what, outer[0], around,
                                             call.runs)  # fmt: skip
        finally:
            self.calls.pop()
            self.outside = outside
            self.file, self.variables, self.integers, self.arrays, self.started, self.aliases = outer

    def _bind(self, references: tuple[_Reference, ...], caller: dict) -> None:
        """The subprogram's parameters by reference, as it starts: one given an R parameter is that R
        parameter (the channel's: read and written in place), one given the variable an earlier
        one was given is that one; any other holds the caller's variable's value (its elements'),
        given back where the subprogram returns (`_give_back`): no other name reaches a caller's
        variable, so the caller sees what a reference would have shown it."""
        self.aliases = {}
        held: dict[str, str] = {}  # the caller's variable -> the parameter that holds it
        for reference in references:
            parameter, key = reference.parameter, reference.key
            if key in held or _R_PARAMETER.fullmatch(key):
                self.aliases[parameter] = held.get(key, key)
                continue
            held[key] = parameter
            if reference.integer:
                self.integers.add(parameter)
            if reference.sizes is None:
                self.variables[parameter] = caller[key]
                continue
            self.arrays[parameter] = reference.sizes
            for mine, theirs in _elements_of(reference):
                self.variables[mine] = caller[theirs]

    def _give_back(self, references: tuple[_Reference, ...], caller: dict) -> None:
        """At the subprogram's return: the caller's variables its parameters by reference hold (`_bind`)
        take their values."""
        for reference in references:
            parameter, key = reference.parameter, reference.key
            if parameter in self.aliases:
                continue
            if reference.sizes is None:
                caller[key] = self.variables[parameter]
                continue
            for mine, theirs in _elements_of(reference):
                caller[theirs] = self.variables[mine]

    # -- variables --------------------------------------------------------------------
    def _key(self, name: str) -> str:
        """The key a variable's value is held under: a parameter by reference's may be another's (`_bind`)."""
        return self.aliases.get(name, name)

    def _procedure(self, node: tuple, block: Block, item) -> None:
        """`PROC NAME(params)` opening the program: the program runs as the procedure, whose
        parameters take the caller's values, which ncpp is not told: reading one ends
        interpretation; its other blocks are followed.  A PROC anywhere else is out of scope."""
        if self.started:
            raise OutOfScope("PROC below the program's first block", item.start + 1)
        if self.calls:  # (a subprogram's: the call gave its parameters their values)
            return
        for _type, name, _by_reference, _dims in node[1]:
            self.variables[name] = _FROM_THE_CALLER

    def lookup(self, name: str) -> float:
        name = self._key(name)
        value = self.variables.get(name)
        if value is _FROM_THE_CALLER:
            raise OutOfScope(f"the parameter {name.upper()} (its value comes from the caller)")
        if value is None:
            if name[0] == "r" and name[1:].isdigit():  # (`_R_PARAMETER`: not 0, what is left there)
                raise OutOfScope(f"the R parameter {name.upper()} (not set in the program: it holds what an "
                                 "earlier program or a measuring cycle left in the channel)")  # fmt: skip
            raise OutOfScope(f"the variable {name.upper()} (not defined in the program)")
        if isinstance(value, str):
            raise OutOfScope(f"the string variable {name.upper()} in arithmetic")
        return value

    def assign(self, target: tuple, expr: tuple, block: Block, item) -> None:
        if expr[0] == "list":
            raise OutOfScope(f"the value list assigned to {target[1].upper()}", item.start + 1)
        if target[0] == "index":
            self._assign_elements(target, expr, block, item)
            return
        if target[0] != "param" or target[1].startswith("$"):
            raise OutOfScope(f"the assignment to {target[1].upper()}", item.start + 1)
        name = self._key(target[1])
        if name not in self.variables and not _R_PARAMETER.fullmatch(name):
            # (a global variable defined in a file of the control's, or an address this reading does not
            # know: the control reads either its own way)
            raise OutOfScope(f"the assignment to {name.upper()} (not defined in the program)", item.start + 1)
        if expr[0] == "str":
            self.variables[name] = expr[1]
            return
        value = self.value(expr, block, item)
        self.variables[name] = float(round(value)) if name in self.integers else value

    def _count(self, target: tuple, expr: tuple, block: Block, item) -> None:
        """A FOR loop's counter set: one the program did not define is taken as a REAL of its own
        (as the CEAD interpreter takes it)."""
        if target[0] == "param":
            self.variables.setdefault(self._key(target[1]), 0.0)
        self.assign(target, expr, block, item)

    def define(self, node: tuple, block: Block, item) -> None:
        type_name, _, variables = node
        for target, init in variables:
            name = target[1]
            if type_name == "INT":
                self.integers.add(name)
            if target[0] == "index":
                self._define_array(type_name, target, init, block, item)
                continue
            self.variables[name] = "" if type_name == "STRING" else 0.0
            if init is not None:
                self.assign(target, init, block, item)

    # -- arrays (Job Planning manual, "Definition and initialization of array variables (DEF,
    # SET, REP)": indices from 0, up to three dimensions, the elements in row order, SET(a, b, ...)
    # assigning from the element named on, REP(v) every element from it to the end, REP(v, n) n) --
    def _define_array(self, type_name: str, target: tuple, init: tuple | None, block: Block, item) -> None:
        if type_name not in ("REAL", "INT", "BOOL"):
            raise OutOfScope(f"the {type_name} array {target[1].upper()}", item.start + 1)
        sizes = tuple(int(self.value(size, block, item)) for size in target[2])
        if len(sizes) > 3 or min(sizes) < 1:
            self.fail(f"the array {target[1].upper()} cannot have the sizes {list(sizes)}", block, item)
        if math.prod(sizes) > MAX_ELEMENTS:
            raise OutOfScope(
                f"the array {target[1].upper()} of over {MAX_ELEMENTS:,} elements", item.start + 1
            )
        name = target[1]
        self.arrays[name] = sizes
        self.variables.update((key, 0.0) for key in _element_keys(name, sizes))
        if init is not None:
            self._assign_elements(("index", name, (("num", 0.0),) * len(sizes)), init, block, item)

    def _assign_elements(self, target: tuple, expr: tuple, block: Block, item) -> None:
        name = self._key(target[1])
        keys = _element_keys(name, self.arrays.get(name, ()))
        if not keys:
            raise OutOfScope(f"the array {name.upper()} (not defined in the program)", item.start + 1)
        first = keys.index(self._element(target, block, item))
        values: list[float | None]
        if expr[0] == "call" and expr[1] in ("SET", "REP"):
            # (an empty place in SET leaves its element as it is; REP(v, n) fills n elements)
            args = [None if arg is None else self.value(arg, block, item) for arg in expr[2:]]
            if expr[1] == "SET":
                values = args
            elif len(args) in (1, 2) and args[0] is not None:
                count = len(keys) - first if len(args) == 1 or args[1] is None else int(args[1])
                values = [args[0]] * count
            else:
                self.fail("REP takes a value and, perhaps, how many elements it fills", block, item)
            if first + len(values) > len(keys):
                self.fail(f"{expr[1]} gives {name.upper()} more values than it holds from here", block, item)
        else:
            values = [self.value(expr, block, item)]
        integer = name in self.integers
        for key, value in zip(keys[first:], values):
            if value is not None:
                self.variables[key] = float(round(value)) if integer else value

    def _element(self, target: tuple, block: Block, item) -> str:
        """The variable key of an array element `("index", name, (exprs))`, its indices checked."""
        name = self._key(target[1])
        sizes = self.arrays.get(name)
        if self.variables.get(name) is _FROM_THE_CALLER:
            raise OutOfScope(
                f"the parameter {name.upper()} (its value comes from the caller)", item.start + 1
            )
        if sizes is None:
            raise OutOfScope(f"the array {name.upper()} (not defined in the program)", item.start + 1)
        index = tuple(int(round(self.value(i, block, item))) for i in target[2])
        if len(index) != len(sizes) or any(not 0 <= i < n for i, n in zip(index, sizes)):
            self.fail(
                f"the index {list(index)} is outside the array {name.upper()}{list(sizes)}", block, item
            )
        return _element_key(name, index)

    def value(self, expr: tuple, block: Block, item) -> float:
        return super().value(self._elements_named(expr, block, item), block, item)

    def _elements_named(self, expr: tuple, block: Block, item) -> tuple:
        """`expr` with each array element read as the variable that holds it."""
        if expr[0] == "index":
            return ("param", self._element(expr, block, item))
        if expr[0] in ("num", "str", "param"):
            return expr
        return tuple(
            self._elements_named(part, block, item) if type(part) is tuple else part for part in expr
        )

    # -- one block ------------------------------------------------------------------------
    def block(self, block: Block) -> list[Event]:
        words: dict[str, tuple[float, str | None, object]] = {}  # letter -> (value, 'ac' | 'ic' | None, item)
        gcodes: list[tuple[float, Word | ExprWord]] = []
        path: str | None = None
        frame: Statement | None = None
        rpl: tuple[float, Statement] | None = None  # `ROT RPL=30`: the rotation in the plane, its item
        machine = False  # SUPA: the block's coordinates are the machine's
        mcall = False  # MCALL: the drilling cycle of the block is called after each move from here on
        drilling: Drilling | None = None  # a drilling cycle the block runs where it ends
        holes: list[tuple[float, float]] | None = None  # HOLES1 / HOLES2: the modal cycle runs at each
        end = False
        tool_words: list = []  # the block's T, M6 and D words, in order
        previous: Word | ExprWord | Statement | None = None
        for item in block.items:
            if type(item) is Comment:
                continue
            before, previous = previous, item
            if type(item) is Statement:
                what = item.kind
                if what == "assignment" and item.node[0] == ("param", "rpl") and frame is not None:
                    # (RPL= is an address of the frame's, no variable)
                    rpl = (self.value(item.node[1], block, item), item)
                elif what == "assignment":
                    target, expr = item.node
                    self.assign(target, expr, block, item)
                elif what == "def":
                    self.define(item.node, block, item)
                elif what == "proc":
                    self._procedure(item.node, block, item)
                elif what == "path" and item.node[0] in ("CIP", "CT"):
                    path = item.node[0]
                elif what == "frame" and item.node[0] in FRAMES:
                    frame = item
                elif what == "call" and item.node[0] == "SUPA" and not item.node[1]:
                    machine = True
                elif what == "call" and item.node[0] == "MCALL":
                    mcall, self.modal_cycle = True, None  # (alone it ends the modal call)
                elif what == "call" and item.node[0] in DRILLING:
                    drilling = self._drilling(item.node, block, item)
                    if mcall:
                        self.modal_cycle, drilling = drilling, None
                elif what == "call" and item.node[0] in FOLLOWED_PATTERNS:
                    holes = self._holes(item.node, block, item)
                elif what == "call" and item.node[0] in HOLE_PATTERNS:
                    raise OutOfScope(
                        f"the hole pattern {item.node[0]} (the control places its holes itself)",
                        item.start + 1,
                    )
                elif what == "call" and item.node[0] == "PCALL" and _with_path(item):
                    self.called = self._call_path(block, item)
                elif what == "call" and item.node[0] in ("CALL", "EXTCALL") and len(item.node[1]) == 1:
                    self.called = self._call(block, item, self._indirect(item.node[1][0], block, item), ())
                elif what == "call" and item.node[0].upper() in APPROACHES and not item.node[1]:
                    self._approach(item.node[0].upper(), item)
                elif what == "call" and item.node[0] == "EXTERN":
                    return []  # (it declares a subprogram's parameters)
                elif what == "call" and item.node[0] == "CALLPATH":
                    pass  # (the control's search path: called programs are looked for on --subroutine-path)
                elif what == "call" and item.node[0] == "RET" and self.calls:
                    if item.node[1]:
                        raise OutOfScope("RET with parameters (a return elsewhere)", item.start + 1)
                    self.returned = True  # (after the block)
                elif what == "call" and (
                    item.node[0] in HARMLESS_CALLS
                    or item.node[0] in SETTING_CALLS
                    or (item.node[0] in RESETTING_CALLS and not item.node[1])
                ):
                    pass
                elif what == "call" and item.node[0] in PRESETS:
                    raise self._preset(item.node, block, item)
                elif what == "call" and item.node[0] in PREDEFINED_PROCEDURES:
                    raise OutOfScope(f"the predefined procedure {item.node[0]}", item.start + 1)
                elif what == "call" and (
                    (
                        _SUBPROGRAM_NAME.fullmatch(item.node[0])
                        and item.node[0] not in CALL_KEYWORDS
                        and not KNOWN_CYCLE.match(item.node[0])
                    )
                    or self._own_program(item.node[0])
                ):
                    self.called = self._call(block, item, item.node[0].upper(), item.node[1])
                elif what == "call" and SHOP_CYCLE.fullmatch(item.node[0]):
                    names = _subprogram_files(item.node[0].upper())
                    raise OutOfScope(f"call {item.node[0]} (a Siemens cycle's name; as a program of the user's, its "
                                     f"file not found: {searched(self.subroutine_path, names)})", item.start + 1)  # fmt: skip
                elif what == "sync_action":
                    raise OutOfScope("the synchronized action (it acts beside the blocks)", item.start + 1)
                elif what not in ("label", "program_name", "block_delete"):
                    name = item.node[0] if what in ("call", "path", "frame") else what.upper()
                    raise OutOfScope(
                        f"{what} {name}" if what in ("call", "path", "frame") else name, item.start + 1
                    )
                continue
            if type(item) is ExprWord and item.letter == "T" and item.expr[0] == "str":  # T="NAME"
                tool_words.append((item, item.expr[1]))
                continue
            if type(item) is Word:
                letter, value, mode = item.letter, item.value, None
                if (
                    letter == "E"
                    and type(before) is not Word
                    and before is not None
                    and before.end == item.start
                ):
                    self._exponent(block, before, item)
            else:
                letter, (value, mode) = item.letter, self._word_value(item, block)
            if letter == "G":
                gcodes.append((value, item))
            elif letter == "M":
                if value in END_M and self.calls:
                    if value != 17.0:
                        raise OutOfScope(f"M{value:g} in a subprogram (M17 or RET ends one)", item.start + 1)
                    self.returned = True  # (after the block)
                end = end or (value in END_M and not self.calls)
                if value == TOOL_CHANGE:
                    tool_words.append((item, value))
            elif letter in ("T", "D"):
                tool_words.append((item, value))
            elif letter in ("N", ":"):
                continue
            else:
                if letter in UNREAD_GEOMETRY:
                    raise OutOfScope(f"{UNREAD_GEOMETRY[letter]} {letter}=", item.start + 1)
                if letter == "OFFN" and value != 0.0:
                    # The contour offset widens the tool radius the control compensates by (Fundamentals,
                    # "Tool radius compensation (G40, G41, G42, OFFN)"); 0, the reset value, changes nothing.
                    raise OutOfScope("the contour offset OFFN=", item.start + 1)
                if letter == "L" and type(item) is Word and item.number.isdigit():
                    # (leading zeros name another subprogram: L0100 is not L100)
                    self.called = self._call(block, item, f"L{item.number}", ())
                    continue
                if letter == "L":
                    raise OutOfScope(f"the subprogram call L{value:g}", item.start + 1)
                if letter in words:
                    self.fail(f"the address {letter} twice in one block", block, item)
                if letter == "S":
                    self.spindle = value
                words[letter] = (value, mode, item)
        # (comments and the program's name, `%_N_MYSUB_SPF` above its PROC, do not start the program)
        self.started = self.started or any(
            type(i) is not Comment and not _program_name(i) for i in block.items
        )
        plane = self.plane
        codes = {code for code, _ in gcodes}
        # cutter compensation: G41 left, G42 right, G40 off (the block's last of them)
        turn = next((SIDES[code] for code, _ in reversed(gcodes) if code in SIDES), None)
        if turn and self.rotation is not None:
            code, side = next((code, item) for code, item in reversed(gcodes) if code in SIDES)
            raise OutOfScope(
                f"cutter compensation G{code:g} under a rotation of the frame (ROT)", side.start + 1
            )
        changes = [item for item, _ in tool_words if item.letter in ("M", "D")]
        if changes and self.radius_comp and not turn:  # (its radius is the edge's it was turned on with)
            raise OutOfScope(
                "a tool or cutting edge change under radius compensation G41/G42", changes[0].start + 1
            )
        dwell = self._modal_codes(gcodes, block)
        if tool_words or (self.plane != plane and self.edge):
            self._place_tool(block, tool_words)
        if path is not None:
            self.motion = path
        if frame is not None:
            self._frame(frame, words, rpl)
            return []
        events: list[Event] = []
        dwelling = next((words[a][2] for a in ROTARY if a in words), None) if dwell else None
        if dwelling is not None:
            raise OutOfScope("a rotary axis word in a dwell block", dwelling.start + 1)  # type: ignore[attr-defined]
        if not dwell:
            if "F" in words:
                self.feed = words["F"][0]
            if machine or codes & MACHINE_G:
                events = self._machine_move(block, words)
            else:
                events = self._move(block, words)
            if events and self.zero_frame != self.told_frame:
                raise OutOfScope(
                    f"a move under {_frame_name(self.zero_frame)} (ncpp is told the zero of {_frame_name(self.told_frame)})",
                    block.items[0].start + 1,
                )
        if end:
            self.done = True
        events = self.radius_compensation(events, turn)
        if holes is not None:
            return self._pattern(block, holes, events, mcall or drilling is not None)
        if drilling is None and not mcall and self.modal_cycle is not None and events:
            drilling = self.modal_cycle
        if drilling is not None:
            if self.radius_comp or self.plane != 17:
                raise OutOfScope(
                    "a drilling cycle under radius compensation or outside G17", block.items[0].start + 1
                )
            events = [*events, *self._drill(block, drilling)]
        return events

    def _approach(self, name: str, item: Statement) -> None:
        """NORM or KONT: how compensation approaches the contour (`ToolCentre.approach`).  KONTC and
        KONTT approach and leave it on polynomials the control makes (840D sl Programming Manual
        Fundamentals, "Contour approach and retraction"), which ncpp does not follow."""
        if name not in ("NORM", "KONT"):
            raise OutOfScope(f"the approach {name} (the control's polynomial to the contour)", item.start + 1)
        self.centre.approach = name

    # -- drilling cycles ----------------------------------------------------------------------
    def _drilling(self, node: tuple, block: Block, item) -> Drilling:
        """CYCLE81, CYCLE82 or CYCLE83 with its parameters (`sinumerik_cycles.py`).  The later
        versions' further parameters (AXN, GMODE, DMODE, AMODE, ...) change what the others
        mean: given, they are out of scope."""
        name, args = node
        known = DRILLING[name]
        if len(args) > known and any(a is not None for a in args[known:]):
            raise OutOfScope(f"{name} with more than {known} parameters", item.start + 1)
        values = [
            None if a is None else self.value(a, block, item) for a in (*args, *(None,) * known)[:known]
        ]
        try:
            return drilling(name, values, self.inch, self.spindle)
        except CycleError as error:
            self.fail(str(error), block, item)
        except OutOfScope as out:
            out.col = item.start + 1
            raise

    def _preset(self, node: tuple, block: Block, item) -> OutOfScope:
        """`PRESETON(X, 10)`: the axis's actual value set where it stands, which shifts the machine
        coordinate system (`PRESETS`) and with it every position after it: the scope ends there.  As a
        G92 does, it sets its offset from where the control stands, the corrected point: naming X, Y
        or Z with values, it carries a `Setting` (its values the machine coordinates it gives), so that
        the writer steps back to the programmed point before it and the offset is the program's."""
        name, args = node
        reason = (f"{name} (it sets a machine axis's actual value, shifting the machine coordinate system and "
                  "the program's zero with it)")  # fmt: skip
        pairs = list(zip(args[::2], args[1::2]))
        if len(args) % 2 or not pairs or not all(type(a) is tuple and a[0] == "param" for a, _ in pairs):
            return OutOfScope(f"{name} other than as (axis, value) pairs", item.start + 1)
        axes = ["XYZ".find(a[1].upper()) if len(a[1]) == 1 else -1 for a, _ in pairs]
        if min(axes) < 0:  # (a machine axis by another name: which of X Y Z it is ncpp is not told)
            return OutOfScope(reason, item.start + 1)
        try:
            values = tuple((axis, self.value(expr, block, item)) for axis, (_, expr) in zip(axes, pairs))
        except OutOfScope:  # (a value ncpp cannot compute: `$AA_IM[X]+70`, the actual position read)
            return OutOfScope(reason, item.start + 1)
        context = self.context()
        here = context.turned((self.pos[0], self.pos[1], self.pos[2]))
        return OutOfScope(reason, item.start + 1, Setting(values, context, here, leaves=True))

    def _holes(self, node: tuple, block: Block, item) -> list[tuple[float, float]]:
        """HOLES1 and HOLES2's holes in the plane, in the order the cycle drills them (840D
        Programming Guide Cycles, "Row of holes - HOLES1": SPCA SPCO a reference point on the
        row, STA1 its angle to the abscissa, FDIS the first hole's distance from the reference
        point, DBH the distance between holes, NUM holes; "to avoid idle travel" the cycle starts
        at the end of the row nearer the tool; "Circle of holes - HOLES2": CPA CPO the centre,
        RAD the radius, STA1 the first hole's angle, INDA the angle between holes (0: 360/NUM
        over a full circle), NUM holes)."""
        name, args = node
        known = FOLLOWED_PATTERNS[name]
        if len(args) > known and any(a is not None for a in args[known:]):
            raise OutOfScope(f"{name} with more than {known} parameters", item.start + 1)
        values = [
            None if a is None else self.value(a, block, item) for a in (*args, *(None,) * known)[:known]
        ]
        a, b, angle, first, between, count = values  # (HOLES2: CPA CPO RAD STA1 INDA NUM)
        if a is None or b is None or count is None or count != int(count) or not 1 <= count <= MAX_HOLES:
            self.fail(f"{name}: the reference point and a whole number of holes NUM are needed", block, item)
        k = np.arange(int(count))
        if name == "HOLES2":
            radius, start, step = abs(angle or 0.0), first or 0.0, between or 360.0 / count
            turns = np.radians(start + step * k)
            return list(zip((a + radius * np.cos(turns)).tolist(), (b + radius * np.sin(turns)).tolist()))
        along = abs(first or 0.0) + abs(between or 0.0) * k
        direction = math.radians(angle or 0.0)
        row = list(
            zip((a + along * math.cos(direction)).tolist(), (b + along * math.sin(direction)).tolist())
        )
        near_first, near_last = (math.dist(self.pos[:2], row[end]) for end in (0, -1))
        if len(row) > 1 and math.isclose(near_first, near_last, abs_tol=1e-9):
            raise OutOfScope("HOLES1 with the tool as far from either end of the row (the cycle picks the end)",
                             item.start + 1)  # fmt: skip
        return row if near_first < near_last or len(row) == 1 else row[::-1]

    def _pattern(
        self, block: Block, holes: list[tuple[float, float]], events: list, called: bool
    ) -> list[Event]:
        """The modal drilling cycle (MCALL) at each hole of HOLES1/HOLES2, the tool moving to each
        at G0 in the plane: the control's moves, from one block that cannot carry a correction
        for each hole, left as programmed (PATTERN); compensation resumes after the block."""
        where = block.items[0].start + 1
        cycle = self.modal_cycle
        if cycle is None or called or events:
            raise OutOfScope("a hole pattern without a drilling cycle under MCALL, or with a move or a cycle "
                             "of its own in its block", where)  # fmt: skip
        if self.radius_comp or self.plane != 17:
            raise OutOfScope("a hole pattern under radius compensation or outside G17", where)
        moves: list[Event] = []
        for x, y in holes:
            moves.append(self.line(block, [x, y, self.pos[2]], True, self.absolute))
            moves += self._drill(block, cycle)
        for move in moves:
            if type(move) is Line:
                move.fixed, move.placed = PATTERN, (True, True, True)
        return moves

    def _drill(self, block: Block, cycle: Drilling) -> list[Event]:
        """The cycle's moves where the block leaves the tool (`drilled`), its feeds from the feed
        programmed before."""
        feed = self.feed
        if feed <= 0 and any(step.feed for step in cycle.steps):
            self.fail(f"{cycle.name}: no feed rate programmed before it", block)
        return self.drilled(
            block,
            [(s.level, s.rate or (feed * s.feed if s.feed else None), s.dwell) for s in cycle.steps],
        )

    def _exponent(self, block: Block, expression, word: Word) -> None:
        """Refuse `X=1e3`: the grammar reads `X=1` and an address E, as a Sinumerik would."""
        value, written = block.raw[expression.start : word.start], block.raw[word.start : word.end]
        self.fail(f"{value}{written}: a Sinumerik writes an exponent as EX ({value}EX{word.number}); "
                  f"as written this is {value} and an address E", block, word)  # fmt: skip

    # -- tool lengths -----------------------------------------------------------------------
    def _place_tool(self, block: Block, tool_words: list) -> None:
        """Follow T, M6 and D (in that order, wherever they stand in the block: M6 loads the T
        of its block, D picks that tool's edge), then apply the lengths of the loaded tool's
        edge along the plane's axes."""
        changed = False
        for item, value in sorted(tool_words, key=lambda word: "TMD".index(word[0].letter)):
            if item.letter == "T":
                self.selected = value
            elif item.letter == "M":
                self.loaded, self.edge, changed = self.selected, 1, True
                self.tool_id = _tool_id(self.loaded)
            else:
                self.edge, changed = int(value), True
            self.edge_told = self.edge_told or changed
            if changed and self.tools is None and self.edge:
                self.untold_lengths(
                    f"{item.letter}{value:g}", "_N_TO_INI", Location(self.file, block.line, item.start + 1)
                )
        lengths = self._edge_lengths(block, tool_words[-1][0] if tool_words else None)
        if changed and self.tools is not None and self.edge and self.loaded not in (0.0, ""):
            self.length_told = (self.edge, lengths[0])
        tool = [0.0, 0.0, 0.0]
        for length, axis in zip(lengths, LENGTH_AXES[self.plane]):
            tool[axis] = length / (MM_PER_INCH if self.inch else 1.0)
        # (whether the frame turns a length in X or Y the manual does not say)
        if self.rotation is not None and tool[:2] != self.tool[:2]:
            where = tool_words[-1][0].start + 1 if tool_words else None
            raise OutOfScope("a tool length in X or Y under a rotation of the frame (ROT)", where)
        self.set_tool(tool)

    def _edge_lengths(self, block: Block, item) -> tuple[float, float, float]:
        """Lengths 1-3 (mm) of the loaded tool's cutting edge in effect (none: D0, no tool, no table)."""
        if self.tools is None or not self.edge or self.loaded in (0.0, ""):
            return (0.0, 0.0, 0.0)
        number = self._loaded_number()
        if number is None:
            self.fail(f'tool "{self.loaded}" is not in {self.tools.source}', block, item)
        lengths = self.tools.edges.get((number, self.edge))
        if lengths is None:
            self.fail(f"tool {self.loaded if type(self.loaded) is str else f'{number:g}'} has no cutting edge D{self.edge} in {self.tools.source}",
                      block, item)  # fmt: skip
        return lengths

    def _loaded_number(self) -> float | None:
        """The loaded tool's number (a name's, in the tool offsets), None: a name they lack."""
        assert self.tools is not None
        return self.loaded if type(self.loaded) is float else self.tools.names.get(self.loaded)  # type: ignore[arg-type]

    def tool_radius(self) -> float | None:
        """The radius of the loaded tool's cutting edge in effect (radius plus wear radius in the
        control's tool offsets, `_N_TO_INI`), program units; 0 with D0, None when the offsets are
        not told or do not give it (or no M6 or D said the edge, or no M6 loaded the tool)."""
        if not self.edge_told:
            return None
        if not self.edge:
            return 0.0
        if self.tools is None or self.loaded in (0.0, ""):  # (no M6: the spindle's tool is the control's)
            return None
        radius = self.tools.radii.get((self._loaded_number(), self.edge))  # type: ignore[arg-type]
        return None if radius is None else radius / (MM_PER_INCH if self.inch else 1.0)

    def _word_value(self, item: ExprWord, block: Block) -> tuple[float, str | None]:
        expr = item.expr
        if expr[0] in ("dc", "acp", "acn", "cac", "cic") and not (expr[0] == "dc" and item.letter in ROTARY):
            raise OutOfScope(f"the rotary-axis mode {expr[0].upper()}()", item.start + 1)
        if expr[0] == "str":
            return 0.0, None  # `T="MILL"`: a name, no motion
        mode = expr[0] if expr[0] in ("ac", "ic", "dc") else None
        value = self.value(expr[1] if mode else expr, block, item)
        if (
            self.expansion is not None
        ):  # (the value where the word stands: the block's assignments go in order)
            self.expansion.seen[id(item)] = value
        return value, mode

    def _modal_codes(self, gcodes: list[tuple[float, Word | ExprWord]], block: Block) -> bool:
        """Apply the block's G codes; True for a dwell block (its F is a time)."""
        dwell = False
        for code, item in gcodes:
            if code in (0.0, 1.0, 2.0, 3.0):
                self.motion = code
            elif code in (17.0, 18.0, 19.0):
                if code != 17.0 and self.rotation is not None:  # (the rotation is about Z: in G17's plane)
                    raise OutOfScope(f"G{code:g} under a rotation of the frame (ROT)", item.start + 1)
                self.plane = int(code)
            elif code in (90.0, 91.0):
                self.absolute = code == 90.0
            elif code in UNITS_G:
                self.set_units(UNITS_G[code])
            elif code == 4.0:
                dwell = True
            elif code in SETTABLE_FRAMES or code == NO_SETTABLE_FRAME:
                self._select_frame(code)
            elif code not in NEUTRAL_G and code not in MACHINE_G:
                reason = {33.0: "thread cutting", 93.0: "inverse time feed"}.get(code, "the G code")
                raise OutOfScope(f"{reason} G{code:g}", item.start + 1)
        return dwell

    def _frame(self, frame: Statement, words: dict, rpl: tuple[float, Statement] | None) -> None:
        """A programmable frame instruction (840D sl Programming Manual Fundamentals, "Coordinate
        transformations (frames)"): TRANS, ROT, SCALE and MIRROR replace the programmable frame (bare, they
        reset it), ATRANS and AROT add to it in the frame in effect, so that ATRANS after a rotation
        translates along the turned axes.  The frame holds its translation (`offset`, with the tool's
        lengths) and its rotation about Z in G17 (`rotation`, about the zero of the settable frame plus the
        translation: `_rotated`); a change under a rotation leaves X and Y to a move that gives both
        (`settle_rotation`)."""
        name = frame.node[0]
        if name in ("ROT", "AROT") and (words or rpl is not None):
            return self._rotated(frame, words, rpl)
        if rpl is not None:
            raise OutOfScope(f"{name} with RPL=", rpl[1].start + 1)
        if name not in ("TRANS", "ATRANS") and words:
            raise OutOfScope(f"frame {name}", frame.start + 1)
        offset = (
            list(self.offset) if name == "ATRANS" else list(self.tool)
        )  # TRANS replaces the frame, not the tool length
        moved = [0.0, 0.0, 0.0]
        for letter, (value, _, item) in words.items():
            if letter not in AXES:
                raise OutOfScope(f"{frame.node[0]} of the {letter} axis", item.start + 1)
            moved[AXES.index(letter)] = value
        rotation = self.rotation if name == "ATRANS" else None
        if rotation is not None:  # (ATRANS under a rotation: along the turned axes)
            moved = list(self.context().turned(as_point(moved)))
        for k in range(3):
            if moved[k] or AXES[k] in words:
                offset[k] += moved[k]
        self._set_frame(name, offset, rotation)

    def _rotated(self, frame: Statement, words: dict, rpl: tuple[float, Statement] | None) -> None:
        """`ROT RPL=a` / `ROT Z a` (the frame replaced by a rotation of a degrees counter-clockwise in the
        plane G17, about the settable frame's zero) and `AROT RPL=a` / `AROT Z a` (a added to the rotation in
        effect, about the frame's zero).  Not followed: a rotation about X or Y, or in G18 / G19 (the plane
        turns off the machine's), or under cutter compensation."""
        name = frame.node[0]
        other = next((item for letter, (_, _, item) in words.items() if letter != "Z"), None)
        if other is not None:
            raise OutOfScope(
                f"{name} about {other.letter} (a rotation out of the plane G17)", other.start + 1
            )
        if rpl is not None and words:
            raise OutOfScope(f"{name} with RPL= and Z", rpl[1].start + 1)
        angle, item = rpl if rpl is not None else (words["Z"][0], words["Z"][2])
        why = (f"in G{self.plane}" if self.plane != 17 else "under cutter compensation" if self.radius_comp
               else "with AC() or IC()" if rpl is None and words["Z"][1] is not None else None)  # fmt: skip
        if why is not None:
            raise OutOfScope(f"{name} {why}", item.start + 1)
        before = self.rotation[0] if self.rotation is not None else 0.0
        turned = angle + before if name == "AROT" else angle
        self._set_frame(name, list(self.offset) if name == "AROT" else list(self.tool),
                        (turned, 0.0, 0.0) if turned else None)  # fmt: skip

    def _set_frame(self, name: str, offset: list[float], rotation: tuple[float, float, float] | None) -> None:
        """The frame's translation and rotation set: the machine stays (`set_frame`); a translation's
        offset is traversed with the axis's next incremental move (`frame_shift`), and under a rotation
        before or after, the next move in the plane gives X and Y (`settle_rotation`)."""
        if (self.rotation is not None or rotation is not None) and (
            rotation != self.rotation or offset[:2] != self.offset[:2]
        ):
            self.unsettled = name
        self.frame_shift = [s + new - old for s, new, old in zip(self.frame_shift, offset, self.offset)]
        self.set_frame(offset, rotation)

    def _target(self, words: dict) -> list[float]:
        end = list(self.pos)
        for n, axis in enumerate(AXES):
            if axis in words:
                value, mode, _ = words[axis]
                absolute = mode == "ac" or (mode is None and self.absolute)
                end[n] = value if absolute else self.pos[n] + self.frame_shift[n] + value
                self.frame_shift[n] = 0.0
        return end

    def _rotary(self, words: dict, line: bool) -> list[float] | None:
        """Where the block's rotary words (`ROTARY`) put A B C on a `line` (G0 / G1), a move as ISO's
        `G0 A0` is; None where no word names them, or in another move where they stand.  A turn is
        followed on a line only."""
        given = [(ROTARY.index(a), *words[a]) for a in ROTARY if a in words]
        if not given:
            return None
        for k, value, mode, item in given:  # (DC: followed where the shortest way is none)
            if mode == "dc" and not math.isclose(
                math.remainder(value - self.rotary[k], 360.0), 0.0, abs_tol=1e-9
            ):
                raise OutOfScope(f"{item.letter}=DC() turning the axis (the shortest way within a turn)",
                                 item.start + 1)  # fmt: skip
        end = self.rotary_end((k, self.rotary[k] if mode == "dc" else value,
                               mode == "ic" or (mode is None and not self.absolute))
                              for k, value, mode, _ in given)  # fmt: skip
        if end == self.rotary:
            return end if line else None
        if not line:
            turned = next(item for k, _, _, item in given if end[k] != self.rotary[k])
            raise OutOfScope(f"a turn of the rotary axis {turned.letter} in a move other than G0 or G1",
                             turned.start + 1)  # fmt: skip
        return end

    def _move(self, block: Block, words: dict) -> list[Event]:
        motion = self.motion
        has_axes = any(a in words for a in AXES)
        arc_words = any(k in words for k in ("I", "J", "K", "CR", "TURN", *INTERMEDIATE))
        rotary = self._rotary(words, motion in (0.0, 1.0))
        if (
            not has_axes
            and not (arc_words and motion in (2.0, 3.0))
            and (rotary is None or motion not in (0.0, 1.0))
        ):
            return []
        if self.unsettled is not None:
            placing = ("ac", None) if self.absolute else ("ac",)  # (the modes of an absolute word)
            given = [a for a in "XY" if a in words and words[a][1] in placing]
            named = next((words[k][2] for k in ("X", "Y", "I", "J", "CR", "I1", "J1") if k in words), None)
            self.settle_rotation(len(given) == 2, named)
        end = self._target(words)
        absolute = self.absolute  # the modal mode: a rewritten word is written plain, in that mode
        if motion in (0.0, 1.0):
            return [self.line(block, end, motion == 0.0, absolute, rotary)]
        if motion == "CT":
            return [self.tangential(block, end, absolute)]
        if motion == "CIP":
            return [self._cip(block, words, end, absolute)]
        return [self._arc(block, words, end, motion == 2.0, absolute)]

    def _select_frame(self, code: float) -> None:
        if self.told_frame is None and code != NO_SETTABLE_FRAME:
            self.told_frame = code
        self.zero_frame = code

    def _machine_move(self, block: Block, words: dict) -> list[Event]:
        """A G0/G1 block in machine coordinates (G53, G153, SUPA): left as programmed (MACHINE);
        the axes it names end at the machine positions it says."""
        rotary = next((words[a][2] for a in ROTARY if a in words), None)
        if rotary is not None:  # (the rotary axes' machine positions are not told)
            raise OutOfScope(f"the rotary axis word {rotary.letter} in machine coordinates", rotary.start + 1)
        if not any(a in words for a in AXES):
            return []
        item = next(iter(words.values()))[2]
        if self.rotation is not None and ("X" in words or "Y" in words):
            raise OutOfScope("a move of X or Y in machine coordinates under a rotation of the frame (ROT)",
                             item.start + 1)  # fmt: skip
        if self.motion not in (0.0, 1.0) or any(words[a][1] is not None for a in AXES if a in words):
            raise OutOfScope(
                "a move in machine coordinates other than G0/G1 to absolute positions", item.start + 1
            )
        end = list(self.pos)
        offset = self.context().offset
        for n, axis in enumerate(AXES):
            if axis in words:  # machine position = program position + the context's offset (tool, frames)
                end[n] = words[axis][0] - offset[n]
        move = self.line(block, end, self.motion == 0.0)
        move.fixed = MACHINE
        move.placed = cast(tuple[bool, bool, bool], tuple(axis in words for axis in AXES))
        return [move]

    def _arc(self, block: Block, words: dict, end: list[float], clockwise: bool, absolute: bool):
        a, b, _ = PLANE_AXES[self.plane]
        item = next(iter(words.values()))[2]
        turns = 1 + round(words["TURN"][0]) if "TURN" in words else 1
        if "CR" in words:
            centre = self.centre_from_radius(block, words["CR"][2], end, words["CR"][0], clockwise)
        else:
            letters = [CENTRE_LETTERS[a], CENTRE_LETTERS[b]]
            if not any(letter in words for letter in letters):
                self.fail("circular interpolation without I/J/K, CR= or an intermediate point", block, item)
            centre = list(self.pos)
            for axis, letter in zip((a, b), letters):
                if letter in words:
                    value, mode, _ = words[letter]
                    centre[axis] = value if mode == "ac" else self.pos[axis] + value
            self.check_radii(block, item, end, centre)
        return self.arc(block, end, centre, -turns if clockwise else turns, absolute=absolute)

    def _cip(self, block: Block, words: dict, end: list[float], absolute: bool):
        middle = list(self.pos)
        for n, letter in enumerate(INTERMEDIATE):
            if letter in words:
                value, mode, _ = words[letter]
                middle[n] = value if mode == "ac" or (mode is None and self.absolute) else self.pos[n] + value
        points = [self.pos, middle, end]
        item = next(iter(words.values()))[2]
        plane = plane_of(points)
        if plane is None:
            raise OutOfScope("CIP in a plane other than XY, ZX, YZ", item.start + 1)
        if plane != self.plane:
            raise OutOfScope(f"CIP outside the working plane G{self.plane}", item.start + 1)
        found = circle_through(self.pos, middle, end, plane)
        if found is None or math.dist(points[0], points[2]) < 1e-9:
            self.fail("CIP points in a line (or a full circle): no arc through them", block, item)
        centre, turn = found
        return self.arc(block, end, centre, turn, plane, absolute)


def _tool_id(loaded: float | str) -> str:
    """`Context.tool_id` of the tool M6 loaded: its number, or its name in quotes ("": none)."""
    if type(loaded) is str:
        return f'"{loaded}"' if loaded else ""
    return f"{loaded:g}" if loaded else ""


def _frame_name(code: float | None) -> str:
    return "the frame in effect at the start" if code is None else f"G{code:g}"


interpret = placed_interpreting(SinumerikInterpreter)


def _as_programmed(event: Event) -> Event | None:
    """An event of a loop's first pass whose text runs again: a move left as programmed, the
    tool guard's mark dropped (none is written for a block that runs again)."""
    if type(event) is Pass:
        return None if event.length_told is not None else event
    event.fixed = event.fixed or FLOW  # type: ignore[union-attr]
    return event


def _runs_others(block: Block) -> bool:
    """A control line after whose text other blocks' moves may run, owned by it: a loop's end,
    a jump, a CASE."""
    return any(type(i) is Statement and i.kind in RUNS_OTHERS for i in block.items) or is_repetition(block)


def _inside(flow: SinumerikFlow) -> bool:
    """Whether the flow is inside a control structure or a stretch a backward jump runs again."""
    return bool(flow.open) or flow.pc in flow.looped


def _program_name(item) -> bool:
    return type(item) is Statement and item.kind == "program_name"


def _subprogram_files(name: str) -> list[str]:
    """The files subprogram `name` may be kept in on a PC: `MYSUB.SPF`, the control's own
    `_N_MYSUB_SPF`, and a main program (a program called by its name may be either)."""
    found = _CONTROL_NAME.fullmatch(name)
    base, kind = (found.group(1), found.group(2)) if found else (name, None)
    kinds = [kind.upper()] if kind else ["SPF", "MPF"]
    return [f for k in kinds for f in (f"{base}.{k}", f"_N_{base}_{k}", f"_N_{base}_{k}.{k}")]


def _with_path(item: Statement) -> bool:
    """Whether a PCALL is the parser's reading of `PCALL path(...)` (the path its first argument, a string)."""
    return bool(item.node[1]) and item.node[1][0] is not None and item.node[1][0][0] == "str"


def _program_of(path: str) -> str:
    """The program a path names (`/_N_WKS_DIR/PART2`, `LOCAL_DRIVE:PART2.SPF`): its last part, the
    type after `.` written as the control's `_SPF`."""
    name = re.split(r"[/\\:]", path.rstrip("/\\"))[-1].upper()
    return re.sub(r"\.(SPF|MPF)$", r"_\1", name)


def _refuse_overlaps(references: list[_Reference], name: str, item) -> None:
    """Out of scope: an array element given to a parameter by reference and its array to another
    (one variable under two keys, which `_bind` does not tie)."""
    arrays = {r.key for r in references if r.sizes is not None}
    for reference in references:
        if reference.sizes is None and reference.key.split("[")[0] in arrays:
            raise OutOfScope(f"the subprogram {name} given {reference.key.upper()} and its array by reference",
                             item.start + 1)  # fmt: skip


def _elements_of(reference: _Reference) -> list[tuple[str, str]]:
    """An array parameter by reference's element keys, each with the caller's array's."""
    sizes = reference.sizes or ()
    return list(zip(_element_keys(reference.parameter, sizes), _element_keys(reference.key, sizes)))


def _element_key(name: str, index: tuple[int, ...]) -> str:
    return f"{name}[{','.join(map(str, index))}]"


def _element_keys(name: str, sizes: tuple[int, ...]) -> list[str]:
    """An array's element keys in row order (the order SET and REP fill them)."""
    if not sizes:
        return []
    return [_element_key(name, index) for index in itertools.product(*(range(n) for n in sizes))]
