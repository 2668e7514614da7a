"""Blocks -> motion events, as LinuxCNC's rs274ngc interpreter reads them.

`interpret(blocks)` is a generator: one event per block (`Line`, `Arc` or
`Pass`; a G28/G30 block gives two `Line`s), in the order the blocks run
(o-word control flow, `flow.py`), state bounded whatever the program length.  Positions are program (work) coordinates in program units,
exactly what rs274 prints in its canonical calls; `Context.offset` says where
the program origin sits in machine coordinates.  Under a rotation of the coordinate system
(G10 L2 R, Fanuc's G68 in any plane: `Context.rotation`) they are turned as the control turns them, a
translation of the machine position (`canon_call` turns them back to rs274's).

Scope: modal G0-G3, planes, G90/G91, G90.1/G91.1, G20/G21 (state converted
on a switch, like LinuxCNC), G54-G59.3, G10 L2/L20 (L2's R: the system turned about Z; Fanuc's and
Haas's G68, additional work offsets and their readings of G10: `fanuc.py`), G92 family,
G52, G53, G28/G30, T, M6, M61, G43 / G43.1 / G43.2 H / G49 (lengths from the
control's tool table, `tools.py`, or as the program set them with G10 L1/L10/L11:
`_set_tool_offsets`; zero when neither tells them), F and inverse time, IJK and R arcs, helices,
P turns, parameters and expressions, Fanuc corner rounding and
chamfering between two lines (`,R` `,C`, `G1 ... R`: a one-move look-ahead),
the canned cycles G73 G74 G81-G87 G89 with G98/G99 (`cycles.py`), LinuxCNC's
rigid tap G33.1 (`_rigid_tap`), and o-word subroutines, branches and loops, Fanuc M98/M99 subprograms, Haas's
M97 local subprograms and Fanuc
macro B (GOTO, IF ... GOTO, WHILE ... DO ... END, G65 and G66/G67 macro calls: `flow.py`;
`IF [..] THEN #i = ..`, vacant variables, #3000 alarms and #3006 stops,
#5001-#5003 where known: here), and cutter compensation G40-G42.1
(`_in_comp`): where the control offsets the path by the tool radius the moves
are the programmed contour, not the tool centre, and after G40 the position is
the program's again, as in rs274ngc.  The moves the tool makes off the programmed
path (from the first move under G41/G42 to the first after G40) carry where the
tool centre stands (`centre_shift`, `ncpp.motion.cutter`), in G17 and G18 (LinuxCNC
compensates in those two planes only), in G90 and G91; with a lathe tool's orientation (1-8), and
about a Fanuc corner (its fillet or chamfer and the two lines it joins), they are marked `fixed`,
as are the moves of cycles, loops, subroutines and macros: compensation leaves them as
programmed.  Anything else (subroutine files ncpp is not told of, a move of a subprogram under
G66, a Fanuc system variable it does not know, M99 in the main program, G88 (a manual retract)
and the lathe cycles, splines, G33 threading, a rigid tap under cutter compensation or with a
rotary axis word, probing) makes the interpreter's state unknown: that block and
every later block pass through as `Pass` after ONE warning (an error with
`strict`).
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Iterable, Iterator
from typing import NoReturn, cast

from ncpp.errors import Location, NcppError, Warnings, resolve_warnings
from ncpp.lathe import SPINDLE_LIMIT
from ncpp.motion import modal
from ncpp.motion.corners import CornerError, round_corner
from ncpp.motion.cutter import ToolCentre
from ncpp.motion.cycles import (
    CANNED,
    DWELLING,
    PECKING,
    RAPID_DELTA_INCH,
    SPINDLE,
    approach,
    back_bore,
    fanuc_back_bore,
    hole,
)
from ncpp.motion.endless import exact
from ncpp.motion.entries import STRAIGHT, entered, left_at, stepped_back
from ncpp.motion.expand import Expansion, number, refused
from ncpp.motion.expressions import ExpressionError, OutOfScope, Parameters, evaluate, vacant
from ncpp.motion.flow import CALLED, FIXED, ONCE, RUN, SKIP, TEXT, Flow, MainProgram
from ncpp.motion.offsets import SYSTEMS, WorkOffsets
from ncpp.motion.once import FirstPass, OnceRuns, held_to_the_end
from ncpp.motion.segments import (
    COMP,
    CYCLE,
    FLOW,
    HELD,
    HOLE,
    HOME,
    PLANE_AXES,
    TAP_IN,
    TAP_OUT,
    Arc,
    Context,
    Event,
    Hole,
    Line,
    Mirror,
    Pass,
    Setting,
    mirror_axes,
    plane_letters,
    turn_in_plane,
)
from ncpp.motion.tools import OFFSET_LETTERS, UntoldLengths
from ncpp.program.blocks import STRAY_TAPE, UNREADABLE, Block, Comment, ExprWord, Statement, Word

MM_PER_INCH = 25.4
# Cycles --expand-cycles refuses: what G0/G1 blocks cannot do
UNEXPANDED = {
    74.0: "tapping: the spindle reverses at the bottom, in step with the feed",
    84.0: "tapping: the spindle reverses at the bottom, in step with the feed",
    86.0: "the spindle stops at the bottom",
    87.0: "back boring: the spindle stops and orients",
    76.0: "fine boring: the spindle orients and the tool shifts off the wall at the bottom",
}
AXES = "XYZABCUVW"
AXIS_INDEX = {letter: i for i, letter in enumerate(AXES)}
LINEAR = (0, 1, 2, 6, 7, 8)  # axes that change with G20/G21 (not the rotary A B C)
# LinuxCNC's parameters of the tool in the spindle: #5400 its number, #5401-#5409 its offsets X..W,
# #5410 its diameter, #5411 #5412 its front and back angles, #5413 its orientation (`_tool_parameter`)
TOOL_PARAMETERS = range(5400, 5414)
TOOL_DIAMETER, TOOL_ORIENTATION = 5410, 5413

# rs274ngc tolerances (interp_internal.hh), in program units
# how far an R arc's chord may exceed its diameter (rs274ngc's RADIUS_TOLERANCE_INCH, 0.00005 in): mm, inch
RADIUS_TOLERANCE = {False: 0.00005 * 25.4, True: 0.00005}
CENTER_ARC_ABS = {False: 2 * 0.01 * math.sqrt(2), True: 2 * 0.001 * math.sqrt(2)}
CENTER_ARC_REL = 0.001
TINY = 1e-12
# Moves of one canned-cycle block (L repeats, pecks): held at once, so bounded; a real one makes thousands
MAX_CYCLE_MOVES = 1_000_000

_GROUP_CODES = {
    0: (4, 10, 28, 28.1, 30, 30.1, 52, 53, 92, 92.1, 92.2, 92.3),
    1: (0, 1, 2, 3, 5, 5.1, 5.2, 5.3, 33, 33.1, 38.2, 38.3, 38.4, 38.5, 70, 71, 71.1, 71.2, 72, 72.1, 72.2,
        73, 74, 76, 80, 81, 82, 83, 84, 85, 86, 87, 88, 89),
    2: (17, 18, 19, 17.1, 18.1, 19.1),
    3: (90, 91),
    4: (90.1, 91.1),
    5: (93, 94, 95),
    6: (20, 21),
    7: (40, 41, 42, 41.1, 42.1),
    8: (43, 43.1, 43.2, 43.4, 43.5, 49),
    10: (98, 99),
    12: (54, 55, 56, 57, 58, 59, 59.1, 59.2, 59.3),
    13: (61, 61.1, 64),
    14: (96, 97),
    15: (7, 8),
    # Fanuc codes rs274ngc lacks; recognised so that they pass through as out of scope
    16: (15, 16, 50, 51, 50.1, 51.1, 54.1, 65, 66, 67, 68, 69, 31),
}  # fmt: skip
G_GROUP: dict[float, int] = {float(code): group for group, codes in _GROUP_CODES.items() for code in codes}

# G codes whose meaning the interpreter does not follow (the reason names them in the warning)
OUT_OF_SCOPE_G = {
    **{c: "canned cycle" for c in (76.0, 88.0)},
    **{c: "lathe cycle" for c in (70.0, 71.0, 71.1, 71.2, 72.0, 72.1, 72.2)},
    **{c: "spline" for c in (5.0, 5.1, 5.2, 5.3)},
    **{c: "threading" for c in (33.0, 33.1)},
    **{c: "probing" for c in (38.2, 38.3, 38.4, 38.5)},
    **{c: "UVW-plane arcs" for c in (17.1, 18.1, 19.1)},
    7.0: "lathe diameter mode",
    43.2: "additional tool length offset without H",
    43.4: "tool-centre-point control", 43.5: "tool-centre-point control",
    15.0: "polar coordinates", 16.0: "polar coordinates",
    50.0: "scaling", 51.0: "scaling", 50.1: "mirroring", 51.1: "mirroring",
    54.1: "extended work offsets", 65.0: "macro call", 66.0: "modal macro call", 67.0: "modal macro call",
    68.0: "coordinate rotation", 69.0: "coordinate rotation", 31.0: "skip function",
}  # fmt: skip
OUT_OF_SCOPE_M = {98.0: "M98 subprogram call", 99.0: "M99 subprogram return", 70.0: "M70 modal state save",
                  71.0: "M71 modal state invalidate", 72.0: "M72 modal state restore", 73.0: "M73 modal state save"}  # fmt: skip
OUT_OF_SCOPE_STATEMENT = {"oword": "o-word control flow", "if": "Fanuc macro IF", "while": "Fanuc macro WHILE",
                          "end": "Fanuc macro END", "goto": "Fanuc macro GOTO"}  # fmt: skip
IGNORED_STATEMENTS = frozenset(("tape", "checksum", "block_delete", "program_name"))

# check_other_codes: which motion codes may use a word
_ARC_LIKE = {2.0, 3.0, 5.0, 5.1, 76.0, 87.0, 71.0}
_CYCLES = {73.0, 81.0, 82.0, 83.0, 84.0, 85.0, 86.0, 87.0, 88.0, 89.0}
_K_MOTIONS = {2.0, 3.0, 33.0, 33.1, 71.0, 76.0, 87.0}
RIGID_TAP = 33.1
ENTRY_TOO_SHORT = "Length of cutter compensation entry move is not greater than the tool radius"
ENTRY_ARC_TOO_SHORT = "Radius of cutter compensation entry arc is not greater than the tool radius"
_P_MOTIONS = {76.0, 82.0, 86.0, 88.0, 89.0, 5.0, 5.2, 2.0, 3.0, 71.0, 74.0, 84.0}
_P_MCODES = {50.0, 51.0, 52.0, 53.0, 62.0, 63.0, 64.0, 65.0, 66.0, 19.0}
_Q_MOTIONS = {83.0, 73.0, 5.0, 71.0, 76.0}
_R_MOTIONS = {2.0, 3.0, 76.0, 73.0, 71.0, 74.0} | _CYCLES
_ARC_LETTERS = {17: ("I", "J", "K"), 18: ("K", "I", "J"), 19: ("J", "K", "I")}  # first, second, normal offset
_PLANE_NAMES = {17: "xy", 18: "xz", 19: "yz"}
# What rs274ngc refuses with cutter compensation on (`Interpreter._check_with_comp`): modal groups,
# non-modal codes, motions
_REFUSED_WITH_COMP = {
    8: "Cannot change tool offset with cutter radius compensation on",
    12: "Cannot change coordinate systems with cutter radius compensation on",
    13: "Cannot change control mode with cutter radius compensation on",
}
_MODE0_WITH_COMP = {
    **{c: "Cannot change axis offsets with cutter radius comp" for c in (52.0, 92.0)},
    **{c: "Cannot use g28 or g30 with cutter radius comp" for c in (28.0, 30.0)},
    **{c: "Cannot set reference point with cutter compensation in effect" for c in (28.1, 30.1)},
    53.0: "Cannot use g53 with cutter radius comp",
}
_FANUC_MESSAGES = (3000, 3006)  # Fanuc's alarm and stop-with-message system variables
_MOTION_WITH_COMP = {
    **{
        c: "Cannot use canned cycles with cutter compensation on"
        for c in (73.0, 74.0, 76.0, 81.0, 82.0, 83.0, 84.0, 85.0, 86.0, 87.0, 88.0, 89.0)
    },
    **{c: "Cannot probe with cutter radius comp on" for c in (38.2, 38.3, 38.4, 38.5)},
    **{c: "Cannot convert spline with cutter radius compensation" for c in (5.0, 5.1, 5.2, 5.3)},
}


class _OutOfScope(modal.OutOfScope):
    """The ISO interpreter's: a control line's expression raises it in `flow.py` too.  `setting`: the
    offset a block that leaves the scope sets from where the control stands, which the writer moves
    by the correction there as it does an offset set in scope (the control stands at the corrected
    point, and the block must set the offset the program means)."""


class _SetInFlow(_OutOfScope):
    """A block that sets an offset from where the control stands, in a loop or subroutine: the
    construct gets a step back to the programmed point before it (`entries.py`)."""


def interpreting(flavour: type[Interpreter]) -> Callable[..., Iterator[Event]]:
    """The `interpret` function of a flavour of the ISO family, whose interpreter is `flavour`."""

    def interpret(
        blocks: Iterable[Block],
        *,
        file: str = "<stdin>",
        warnings: Warnings | None = None,
        strict: bool = False,
        offsets: WorkOffsets | None = None,
        expand_cycles: bool = False,
        expand: bool = False,
        once_runs: OnceRuns | None = None,
        main_program: MainProgram | None = None,
        guard_reads: bool = False,
    ) -> Iterator[Event]:
        """Motion events of a program's blocks, lazily, as the flavour reads them (see the
        module docstring).

        `offsets`: the zeros and the tool table the control holds at the start
        (none: all zero, as rs274's default parameter file).  Given, a coordinate
        system selected whose zero they do not tell gets a warning where it is
        first selected, and so does the first G43 when they hold no tool table.

        Raises NcppError (file, line, column of the offending word) on a program
        the control would refuse.  Out-of-scope constructs warn once through
        `warnings` (stderr by default) and end interpretation; with `strict`
        (or a strict `warnings`) they raise NcppError instead.

        `expand_cycles`: a canned cycle's block is to be written as its moves (`expanded`);
        `expand`: loops and subroutines are to be written out as straight code (`expand.py`).
        `once_runs`: given, a subroutine that runs once is followed as its run (`Interpreter.run`)
        and told there, to be written where its definition stands.
        `main_program`: given, it is told which of the file's programs runs as the main one
        (`flow.MainProgram`) before the first event.
        `guard_reads`: the tool guard checks the tool parameters the program reads: a read where
        its check has no place (text that runs again or elsewhere) is warned of.
        """
        interpreter = flavour(file, offsets)
        interpreter.once_runs = once_runs
        interpreter.main_program = main_program
        interpreter.expand_cycles = expand_cycles
        interpreter.expansion = Expansion(interpreter.params, file) if expand else None
        interpreter.guard_reads = guard_reads
        return run(interpreter, blocks, warnings, strict)

    return interpret


def run(
    interpreter: Interpreter, blocks: Iterable[Block], warnings: Warnings | None, strict: bool
) -> Iterator[Event]:
    """The events of `interpreter` (LinuxCNC's, or a flavour's subclass) running `blocks`."""
    return interpreter.run(blocks, resolve_warnings(warnings, strict))


class Interpreter:
    """Modal state of one program run (program units throughout).

    A flavour of the ISO family subclasses it where its control reads a construct
    otherwise (`grbl.py`); the class attributes below are the rules it may change."""

    # An arc's offset word along the plane's normal (K in G17): rs274ngc refuses it
    arc_normal_offset_ignored = False
    # G33.1 is LinuxCNC's rigid tap (`_rigid_tap`); a control without it leaves it out of scope
    rigid_tapping = True
    # G73/G83 take a P, the dwell at the bottom of each hole (Haas); rs274ngc refuses it there
    peck_dwell = False
    # A P in the block of a canned cycle whose format has none (G81: Fanuc, Haas) is kept as written, the
    # cycle's moves its own (`FanucInterpreter`); rs274ngc refuses it
    any_cycle_p = False
    # A D word alone selects the radius offset a later G41/G42 without D uses (Fanuc); rs274ngc refuses it
    modal_d = False
    # The motion mode a program starts in (grbl: G0); rs274ngc starts in none
    start_motion: float | None = None
    # Axis words before the program names any of G0-G3 move in a mode the control holds at its start
    # (Fanuc, Haas: `_held_move`); rs274ngc refuses them
    holds_start_mode = False
    # The taps G74/G84 in G18 and G19 feed along the plane's normal (Fanuc); rs274ngc's do not:
    # its convert_cycle_g74_g84 hands cycle_feed the plane's coordinates already permuted, so the
    # tap feeds other axes (in G18 X to the Y word, Y to the Z word, Z to the X word)
    taps_in_any_plane = False
    # Canned cycles are a modal group of their own (Fanuc, Haas: group 09, G0-G3 group 01), so G80
    # leaves the G0-G3 mode the cycle interrupted in effect; rs274ngc leaves no motion mode
    cycles_own_group = False
    # G87 is rs274ngc's back bore (R above, Z below the part, K the top of the cut, I J the offset:
    # LinuxCNC G-code manual, "G87 Back Boring Cycle") and compensated hole by hole; Fanuc's reads its
    # words otherwise (R below, Z the top, I J or Q the shift, K repeats: `_fanuc_back_bore`)
    back_bore_holes = True
    fanuc_back_bore = False  # (where not back_bore_holes) G87 is Fanuc's back bore, compensated hole by hole
    # The canned cycles: rs274ngc's; Fanuc's and Haas's G76 (fine boring) too (`FanucInterpreter`)
    canned: frozenset[float] = CANNED
    # The letters of a canned cycle's repeats: rs274ngc's L; Fanuc's K too (`FanucInterpreter`)
    repeat_letters: tuple[str, ...] = ("L",)
    # A cycle block of 0 repeats and no hole position stores the cycle's data and drills nothing (Fanuc:
    # `G81 R.. Z.. F.. L0`, its holes in a subprogram after it); rs274ngc refuses zero repeats
    stores_cycle = False
    # G28/G30 under cutter compensation (Fanuc: the offset is dropped at the intermediate point and
    # restored after the return): not followed, out of scope; rs274ngc refuses it
    returns_under_comp = False
    # G41/G42 while compensation is on renews the offset vector (Fanuc, Haas): out of scope there;
    # rs274ngc refuses it
    comp_again = False
    # Macro B's external output (POPEN, DPRNT[..], BPRNT[..], PCLOS: Fanuc, Haas) moves nothing and
    # passes through; rs274ngc refuses it
    external_output = False
    # `M98 P51002` runs O1002 five times (Fanuc, `Flow._m98`); rs274ngc calls O51002
    repeats_in_p = False
    # `M97 P1000` runs the program's own blocks from N1000 to M99 (Haas, `Flow._m97`); rs274ngc has no M97
    local_calls = False
    # A file whose first program ends with M99 runs a later one as the main program (Fanuc, Haas:
    # `Flow._stored_first`); rs274ngc runs the file from its top, an M99 there ending an endless main program
    main_after_subprograms = False
    # An R arc that ends where it starts is an arc of 0 degrees, no move (Fanuc); rs274ngc refuses it
    still_r_arc = False
    # R with I, J or K in an arc block: the arc is R's, the others are ignored (Fanuc); rs274ngc refuses it
    r_over_ijk = False
    # G10 L2 in G91 adds its values to the offset (Fanuc, Haas); rs274ngc sets them whatever G90/G91
    incremental_zero_set = False
    # #1000 and up are the control's system variables (Fanuc, Haas), not only where the program's flow
    # shows a Fanuc macro (`Flow`): rs274ngc numbers its parameters to #5601 and reads an unset one as 0
    fanuc_variables = False
    # numbered variables the control keeps from before the program (Fanuc's and Haas's common variables):
    # read before the program sets one, its value is not ncpp's to know
    kept_variables: frozenset[int] = frozenset()
    # AND OR XOR: "logical" (rs274ngc's 1.0 or 0.0), "bitwise" (Haas) or "binary" (Fanuc): `Parameters.logic`
    logic = "logical"
    # G92 with S and no axis words is a spindle speed clamp (Fanuc's lathes and machining centres): the
    # refusal says so (`G92_SPEED_CLAMP`); rs274ngc has no G92 S and refuses it as a G92 without axes
    g92_speed_clamp = False
    # G10 L2 R turns the system's X Y about Z (LinuxCNC G-code manual, G10 L2: "optionally program R to
    # indicate the rotation of the XY axis around the Z"); elsewhere an R there is out of scope
    rotating_g10 = True
    # G10 L1/L10/L11 set a tool's offsets in the control's tool table (`_set_tool_offsets`); grbl has none
    tool_table_g10 = True
    # The L numbers a G10 takes (rs274ngc's; Fanuc's and Haas's also L12 L13, their D offsets)
    g10_l_numbers = frozenset((1.0, 2.0, 10.0, 11.0, 20.0))
    # Codes that cancel a mode ncpp does not follow (which, while it interprets, is not in effect): in a
    # block they cancel nothing and are passed over (Fanuc's and Haas's safety lines, `G40 G49 G69 G80`)
    idle_cancels: frozenset[float] = frozenset()

    def __init__(self, file: str = "<stdin>", offsets: WorkOffsets | None = None):
        self.file = file
        self.pos = [0.0] * 9  # program position of X Y Z A B C U V W
        self.unmoved: list[float] | None = (
            None  # where the next move's unnamed axes go, when not `pos` (`_base`)
        )
        self.plane = 17
        self.absolute = True
        self.arc_absolute = False
        self.inch = False
        self.inverse_time = False
        self.feed = 0.0
        self.feed_given = False  # an F word has set the feed (`_check_feed`)
        self.motion: float | None = (
            self.start_motion
        )  # modal motion G code (0-3, a canned cycle), None for G80 / none yet
        self.before_cycle: float | None = None  # the G0-G3 mode a canned cycle replaced (`cycles_own_group`)
        self.retract_to_r = True  # G99 (rs274ngc's default) / G98: where a cycle retracts to
        # A canned cycle's sticky words (R, the normal axis's, Q; P is a dwell: no move) and the
        # normal-axis position its series of cycles started from (a series ends with any other motion)
        self.cycle_r = self.cycle_cc = self.cycle_q = self.cycle_il = 0.0
        self.cycle_ijk = (0.0, 0.0, 0.0)  # G87's sticky I J K
        self.cycle_holes = False  # the series' cycles are compensated hole by hole (`Hole`)
        self.series_stored = False  # a block of 0 repeats started the series: its first hole is still to come
        # G82 G89's dwell, in the control's unit (sticky within the cycle; Haas: G73 G83 too), and its word
        self.cycle_p = 0.0
        self.cycle_p_word: Word | ExprWord | None = None
        self.per_revolution = False  # G95 (a Fanuc G04 may then count revolutions: `_dwell_word`)
        self.expand_cycles = False  # cycles are written as their moves (`expanded`)
        self.cycle_written_out = False  # a cycle's moves were written as G0/G1 blocks (`_held_move`)
        self.held_told = False  # the warning of a move in the mode the control holds at the start was given
        self.expansion: Expansion | None = None  # --expand: loops and subroutines written out
        self.spindle = 0  # M3 1, M4 -1, stopped 0 (tapping and boring cycles check it)
        self.coord_system = 1
        # by system number: 1..9 G54..G59.3, then the additional work offsets told (`offsets.ADDITIONAL`)
        self.g5x = {n: [0.0] * 9 for n in range(1, 10)}
        self.rotations: dict[int, float] = {}  # by system number: its G10 L2 R, degrees (absent: 0)
        # Fanuc's G68 in effect: (degrees, the centre's coordinates in its plane, program units), and the plane
        # it turns (kept after G69); after G68 or G69 (its code) until a move puts that plane's axes at
        # absolute positions (`_settle_rotation`)
        self.g68: tuple[float, float, float] | None = None
        self.g68_plane = 17
        self.unsettled_rotation: float | None = None
        self.rotation_homed: set[str] = set()  # the plane's axes a G28/G30 homed since (`_settle_rotation`)
        self.mirror: Mirror = ()  # Fanuc's G51.1 in effect: the axes it mirrors (`Context.mirror`)
        self.g92 = [0.0] * 9
        self.g92_saved = [0.0] * 9
        self.tool = [0.0] * 9  # the tool length offset in effect, program units
        self.tools = offsets.tools if offsets is not None else None  # the control's tool table
        self.unit_mm = offsets.unit_mm if offsets is not None else 1.0  # its units (the machine's)
        self.selected_tool = 0  # T
        self.spindle_tool = 0  # M6, M61 (0: none)
        self.tool_changed = False  # the program has changed the tool: ncpp knows which is in the spindle
        # the reads of #5401-#5413 answered since the last block taken (the tool, the parameter, its
        # value): the tool guard checks them before the block (`Pass.tool_read`, `_with_reads`)
        self.tool_reads: list[tuple[int, int, float]] = []
        self.checked_reads: set[tuple[int, int, float]] = set()  # those checked in straight code
        self.guard_reads = False  # a read whose check has no place is warned of (`_unchecked`)
        self.unchecked_lines: set[int] = set()  # the lines warned of so
        # what the program set in the control's tool table (G10 L1/L10/L11, Fanuc's and Haas's G10 L10-L13):
        # per tool (offset) number its offsets by axis in mm, over the told table's (`_table_offsets`),
        # its radius in mm as given, signed (None: set to a value ncpp does not read), its lathe tool
        # orientation and its front and back angles (by letter, I J)
        self.set_offsets: dict[int, dict[int, float]] = {}
        self.set_radii: dict[int, float | None] = {}
        self.set_orientations: dict[int, int] = {}
        self.set_angles: dict[int, dict[str, float]] = {}
        # Fanuc's and Haas's H offsets the program set: (geometry, wear) in mm (geometry None: not known)
        self.h_memory: dict[int, tuple[float | None, float]] = {}
        # Fanuc's D offsets the program set (memory C): (geometry, wear), radii in mm (geometry None: not known)
        self.d_memory: dict[int, tuple[float | None, float]] = {}
        self.unpositioned = {0, 1, 2}  # the axes X Y Z no move has put at a known position yet
        self.untold_lengths = UntoldLengths(
            offsets is not None and offsets.tools is None
        )  # warned at the first G43 that reads the table
        self.home = {28: [0.0] * 9, 30: [0.0] * 9}  # G28/G30 positions, machine coordinates
        self.uses_extra_axes = False
        self.params = Parameters(self._system_parameter, self._fanuc_system_variable, self._tool_parameter)
        self.params.kept = self.kept_variables
        self.params.fanuc = self.fanuc_variables
        self.params.logic = self.logic
        self._context: Context | None = None
        self._fast = False
        self.done = False  # program end (M2/M30) reached or state unknown
        self.ended = False  # program end (M2/M30) reached
        self.corner: tuple[str, float, Word | ExprWord] | None = None  # Fanuc ,R / ,C of the last block
        self.cutter_comp: float | None = None  # G41, G41.1, G42 or G42.1 in effect (None: G40)
        self.comp_radius: float | None = (
            None  # its tool radius, program units, where known (G41.1/G42.1's D; G41/G42: the tool table's)
        )
        # its lathe tool orientation (G41.1/G42.1's L, the tool table's Q; 0 and 9: the tool centre is
        # controlled), kept after G40 for the exit move
        self.comp_orientation = 0
        self.radius_offset: int | None = None  # the D in effect where D is modal (`modal_d`)
        self.centre = ToolCentre()  # where the tool centre stands off the programmed path (`_in_comp`)
        self.arc_refused = False  # after G40 ended compensation that moved the tool off the path: until a G0/G1 move (rs274ngc)
        # the exit move after G40 has a Fanuc corner (`,R` `,C`): the move it rounds into is left as programmed too
        self.exit_corner = False
        self.untold: set[int] = set()  # coordinate systems whose zero nobody said (warned when selected)
        # systems whose zero is still the one ncpp was told (the program has not set it with G10):
        # the placement guard checks them where the program selects them (`Pass.zero_told`)
        self.told_zeros: set[int] = set()
        # systems whose zero the program has set (G10): whether it is known from then on (`_zero_set`)
        self.zeros_set: dict[int, bool] = {}
        self.warnings: Warnings | None = None
        self.flow: Flow | None = None  # while `run` runs
        # Fanuc: the axes (0 X, 1 Y, 2 Z) a move has put at a programmed position since the start or
        # the last program stop (where the operator may jog the machine): #5001-#5003 read them
        self.placed: set[int] = set()
        # the blocks of the subroutines whose one run is written where their definition stands (`run`)
        self.once_runs: OnceRuns | None = None
        self.main_program: MainProgram | None = None  # told which program runs as the main one (`Flow`)
        self.subroutine_path = offsets.subroutine_path if offsets is not None else ()
        if offsets is not None:
            self._start_from(offsets)

    def _start_from(self, offsets: WorkOffsets) -> None:
        """The control's zeros (mm, the interpreter starts in mm), its system in effect and the systems'
        rotations (LinuxCNC's parameter file holds them: `WorkOffsets.rotations`)."""
        for n in (*range(1, 10), *offsets.told_additional()):
            self.g5x[n] = [*offsets.zero(n), *[0.0] * 6]
        self.coord_system = offsets.active
        self.g92[:3] = offsets.g92
        self.g92_saved[:3] = offsets.g92_saved
        self.home[28][:3], self.home[30][:3] = offsets.g28, offsets.g30
        self.untold = {n for n in range(1, 10) if not offsets.told(n)}
        if self.rotating_g10:  # (a Fanuc control's #5230 is an axis of G54, no rotation)
            self.rotations = {n: angle for n, angle in enumerate(offsets.rotations, 1) if angle}
        self.told_zeros = {n for n in (*range(1, 10), *offsets.told_additional()) if offsets.told(n)}

    # -- the event stream ---------------------------------------------------------
    def run(self, blocks: Iterable[Block], warnings: Warnings) -> Iterator[Event]:
        """Events block by block, in the order the blocks run (`_run`).  The run of a subroutine that
        may be its only one (CALLED, `flow.py`) is followed as a run in place, its events and all
        after them held until the program ends (`once.held_to_the_end`): if no other call ran it
        (`Flow.called_again`), its text ran once and is rewritten for that run where its definition
        stands (`once_runs`); else its moves are left as programmed, as a FIXED run's.  A construct
        whose run sets an offset from where the control stands gets its step back (`entries.py`)."""
        runs = self.once_runs
        items: Iterable = self._run(blocks, warnings)
        if runs is not None:  # (else no run is CALLED)
            items = held_to_the_end(
                items, runs, lambda: (self.done, self.ended),
                lambda: self.flow.called_again, self._as_programmed,  # type: ignore[union-attr]  # (`_run` made it)
            )  # fmt: skip
        return stepped_back(items, warnings.warn)  # type: ignore[return-value]

    def _run(self, blocks: Iterable[Block], warnings: Warnings) -> Iterator[Event | tuple]:
        """Events block by block, in the order the blocks run (o-word control flow,
        `flow.py`), a CALLED run's as (its subroutine's name and call, event).  A line with a Fanuc corner word (`,R` `,C`, `G1 ... R`) waits
        for the next move, which decides the corner; the blocks in between wait
        with it (bounded by the program's own layout).  The events of a loop's first pass in
        its place (ONCE) wait until the flow tells whether its text runs again (`_told`).  Where a
        construct entered from straight code starts and ends, and where a setting in it ends
        interpretation, it yields the marks of `entries.stepped_back`."""
        block_event = self.block
        self.warnings = self.untold_lengths.warnings = warnings
        pending: Line | None = None  # the line whose end corner is rounded
        corner: tuple = ()  # its corner word: (kind, size, item); read only with a pending line
        held: list[Event] = []  # non-moving events after it
        once: FirstPass | None = None  # a loop's first pass in its place, while the flow has not told
        # where the flow ended interpretation, and at which block, until its next step tells `entries`
        stopped: tuple[Location, Block] | None = None

        def leave_scope(reason: str, block: Block, col: int | None) -> None:  # (the flow's `stop`)
            nonlocal stopped
            stopped = (self._leave_scope(reason, block, col), block)

        flow = self.flow = Flow(
            self.file, self._evaluate, self.params, lambda: self.done, leave_scope,
            self.subroutine_path, state=self._loop_state, position=lambda: self.pos[:],
            repeats_in_p=self.repeats_in_p, once=self.once_runs, local_calls=self.local_calls,
            main_after_subprograms=self.main_after_subprograms, main_program=self.main_program,
            warn=lambda message, block: warnings.warn(message, Location(self.file, block.line, 1)),
        )  # fmt: skip
        self.rounding = False
        expansion = self.expansion
        block: Block | None = None
        inside = False  # a construct entered from straight code is under way (`entries.py`)
        for block, kind, owner in flow.steps(blocks):
            if kind is ONCE and (expansion is not None or pending is not None or self.corner is not None):
                kind = FIXED  # (--expand writes each run out; a corner waiting: `_in_flow` tells why)
            called = None  # a CALLED run's (subroutine, call)
            if kind is CALLED:
                called = (flow.frames[-1].called, owner)
                if (
                    expansion is not None
                    or pending is not None
                    or self.corner is not None
                    or once is not None
                ):
                    flow.called_again.append(called[0])  # type: ignore[arg-type]  # (the run as a FIXED one)
                    self.once_runs.refuse(called[0])  # type: ignore[union-attr,arg-type]
                    kind, called = FIXED, None
            if once is not None and (self.done or flow.in_straight_code() or once.full()):
                yield from self._told(once, again=(self.done and not self.ended) or once.full())
                once = None
            if kind is ONCE and once is None:
                once = FirstPass(lambda ev: self._as_programmed(ev, None))
            elif once is not None and kind is FIXED and owner is not None and once.rerun(block):
                yield from self._told(once, again=True)  # (all of it runs again: nothing to hold)
                once = None
            if stopped is not None:  # (the flow ended interpretation: a call it cannot follow, ...)
                (place, line), stopped = stopped, None
                nothing_held = once is None and pending is None
                if not inside and block is line and self._enters(kind, owner, nothing_held, stopped=True):
                    yield entered(self._step_back(block))  # type: ignore[misc]
                    inside = True
                if inside:
                    yield left_at(place)  # type: ignore[misc]
                    inside = False
            if inside and (kind is RUN or flow.in_straight_code() and (kind is TEXT or kind is SKIP)):
                yield STRAIGHT  # type: ignore[misc]
                inside = False
            if not inside and self._enters(kind, owner, once is None and pending is None):
                yield entered(self._step_back(block))  # type: ignore[misc]
                inside = True
            if (
                kind is not RUN and kind is not FIXED and kind is not ONCE and kind is not CALLED
            ):  # text not run here
                # (verbatim: after the closing `%`; stored: a program before the main one, text as those are)
                ended = self.done or block.verbatim or flow.stored
                if expansion is not None:
                    kept = expansion.text(kind, ended, block)  # (None: left out)
                    if kept is None:
                        continue
                    if pending is not None:
                        held.extend(kept)
                    else:
                        yield from kept
                if block.signature is None and not block.verbatim:
                    _warn_unreadable(block, warnings)
                text = Pass(
                    block, kind is SKIP or block.verbatim, None if ended else self.motion
                )  # (after the end: no mode the control is in)
                # (a control line's condition read them: the writer reads its first event)
                if self.tool_reads:
                    text.tool_read = self._reads_to_check(flow.in_straight_code())
                if pending is not None:
                    held.append(text)
                elif once is not None:
                    once.add(text, block, again=False)
                else:
                    yield text
                continue
            try:
                if expansion is not None:  # each block where it runs, a body's as this run's numbers
                    event, block = expansion.event(block_event, block, kind, flow.frames[-1].local)
                else:
                    event = block_event(block)  # verbatim blocks (after the closing %) have no items
                if self.tool_reads:
                    event = self._with_reads(event, block, kind is RUN or expansion is not None)
                if kind is ONCE and (self.corner is not None or _sets_offset(event) or self._compensating()):
                    if once is not None:
                        yield from self._told(once, again=True)  # (`_in_flow` tells why, below)
                    once, kind = None, FIXED
                if called is not None and (
                    self.corner is not None or _sets_offset(event) or self._compensating()
                ):
                    flow.called_again.append(called[0])  # type: ignore[arg-type]  # the run as a FIXED one
                    self.once_runs.refuse(called[0])  # type: ignore[union-attr,arg-type]
                    kind, called = FIXED, None
                if kind is FIXED and expansion is None:
                    event = self._in_flow(event, owner)
                if flow.modal is not None and _moves(event):  # a move under G66: the macro next
                    flow.moved = True
                if self.params.fanuc:
                    if kind is RUN and _moves(event):  # in its place: no backward GOTO may run it again
                        flow.last_run_move = block.line
                    elif called is not None and _moves(event):  # (nor the call that ran it)
                        flow.last_run_move = max(flow.last_run_move, owner.line)  # type: ignore[union-attr]
                    elif kind is ONCE and _moves(event):
                        flow.once_move = block.line
                    self._note_placed(block)
                if self._compensating():
                    event = self._in_comp(event, block)
            except NcppError as err:
                source = flow.source()
                if source is None or err.where is None or err.where.file != self.file:
                    raise
                raise NcppError(
                    f"{err.message} (in the subroutine line {owner.line} calls)",  # type: ignore[union-attr]
                    Location(source, err.where.line, err.where.col),
                ) from None
            except _OutOfScope as stop:
                place = self._leave_scope(stop.reason, block, stop.col, owner)
                self.tool_reads = []  # (the program passes as it stands from here: no value of ncpp's in it)
                if once is not None:
                    yield from self._told(once, again=True)
                    once = None
                if pending is not None:
                    yield from self._unrounded(pending, held)
                    pending, self.rounding = None, False
                if inside or type(stop) is _SetInFlow:  # (the latter warned of where it has no step)
                    yield left_at(place, type(stop) is _SetInFlow)  # type: ignore[misc]
                    inside = False
                if owner is None:  # (a block that runs out of the text's order is written in its place)
                    if expansion is not None:
                        yield from expansion.owed()
                    yield Pass(block, setting=stop.setting)
                continue
            if pending is None and self.corner is None and type(event) is not tuple:
                # the common case: no corner waits, none starts (and not a tuple)
                if once is None:
                    yield event if called is None else (called, event)
                else:
                    once.add(event, block, again=kind is FIXED)  # type: ignore[arg-type]
                continue
            events: tuple[Event, ...] = event if type(event) is tuple else (event,)  # type: ignore[assignment]
            new_corner, self.corner = self.corner, None
            for ev in events:
                if pending is not None:
                    if type(ev) is Pass:
                        held.append(ev)
                        continue
                    rounded = self._round_corner(pending, corner, ev, warnings)
                    if rounded is None:  # out of scope: everything from the corner on passes
                        yield from self._unrounded(pending, held)
                        pending, self.rounding = None, False
                        yield Pass(ev.block)
                        break
                    yield from rounded[:-1]
                    yield from held
                    ev = rounded[-1]
                    pending, held, self.rounding = None, [], False
                if new_corner is not None and type(ev) is Line and ev.block is block:
                    pending, corner, self.rounding = ev, new_corner, True
                    continue
                if once is None:
                    yield ev if called is None else (called, ev)
                else:
                    once.add(ev, block, again=kind is FIXED)
        if not self.done and block is not None and (block.verbatim or _tape_mark(block)):
            self.ended = True  # the program ran to its closing `%`, which ends it as M2 does (`_tape_mark`)
        if once is not None:
            yield from self._told(once, again=not self.ended)
        if pending is not None:
            _, _, item = corner
            raise NcppError(
                "corner rounding/chamfer has no following move",
                Location(self.file, pending.block.line, item.start + 1),
            )

    def _enters(self, kind: str, owner: Block | None, nothing_held: bool, stopped: bool = False) -> bool:
        """Whether the step (`kind`, `owner`) may start a construct entered from straight code: a
        control line there (a loop's head, a call; `stopped`: one at which the flow ended
        interpretation), or the first line a backward jump runs again in its place, with nothing held
        (no loop's first pass, no corner) and no cutter compensation (a step would be offset)."""
        if (
            not nothing_held
            or (self.done and not stopped)
            or self.expansion is not None
            or self.flow is None
            or self._compensating()
        ):
            return False
        return (kind is TEXT and self.flow.in_straight_code()) or (kind is FIXED and owner is None)

    def _step_back(self, block: Block) -> Pass:
        """The step back to the programmed point where the tool stands (`entries.py`), before `block`: a
        `Pass` of it whose `Setting` sets nothing, ahead of its events."""
        context = self.context()
        at = context.turned((self.pos[0], self.pos[1], self.pos[2]))
        return Pass(block, motion=self.motion, setting=Setting((), context, at, leaves=True))

    def _loop_state(self) -> tuple | None:
        """The modal state a loop's check compares (`endless.py`): all but the parameters (the
        flow journals them), the flow (its own), what only writes or warns, and what does not change
        in a run; None while a corner waits for its next move (`run`'s own, not told)."""
        if self.rounding:
            return None
        return tuple(exact(value) for name, value in vars(self).items() if name not in _NOT_LOOP_STATE)

    def _leave_scope(
        self, reason: str, block: Block, col: int | None, owner: Block | None = None
    ) -> Location:
        """A construct outside the scope: the state is unknown from here on (an error with strict).
        `owner`: the line that ran the block (a call, a loop's end), from which the rest passes.
        Returns the place it warns at."""
        self.done = True
        source = self.flow.source() if self.flow is not None else None
        if self.expansion is not None and self.flow is not None and self.expansion.refuses_leaving(self.flow):
            raise refused(reason, Location(source or self.file, block.line, col))
        place = Location(source or self.file, block.line, col)
        runs_it = owner.line if owner is not None else None
        if source is not None:  # (in a called file: the warning stands at the program's line that runs it, as
            # `modal.ModalInterpreter.leave_scope` places it, and names the place in the file)
            runs_it = runs_it if runs_it is not None else self.flow.frames[0].pc  # type: ignore[union-attr]
            reason, place = f"{reason} (at {place})", Location(self.file, runs_it, None)
        where = "this line" if runs_it is None else f"line {runs_it}, which runs it,"
        self.warnings.warn(  # type: ignore[union-attr]
            f"{reason} is outside the motion interpreter's scope; from {where} on the "
            "program passes through uninterpreted (its modal state is unknown)",
            place,
        )
        return place

    def _in_flow(self, event: Event | tuple[Event, ...], owner: Block | None) -> Event | tuple[Event, ...]:
        """A block's events inside a loop or a subroutine: its moves are left as programmed
        and, where it runs out of the text's order, belong to `owner` (its text is elsewhere)."""
        if self.corner is not None:
            raise _OutOfScope("Fanuc corner rounding in a loop or subroutine", None)
        if _sets_offset(event):  # set from where each run of the text stands: no one shift
            raise _SetInFlow("G92 or G10 L10/L11/L20 in a loop or subroutine (it sets an offset from "
                             "where the control stands, which compensation moves)", None)  # fmt: skip
        events: tuple[Event, ...] = event if type(event) is tuple else (event,)  # type: ignore[assignment]
        out = [kept for ev in events if (kept := self._as_programmed(ev, owner)) is not None]
        return tuple(out) if len(out) != 1 else out[0]

    def _with_reads(
        self, event: Event | tuple[Event, ...], block: Block, straight: bool
    ) -> Event | tuple[Event, ...]:
        """The block's events with a mark of the tool parameters read for it (`tool_reads`), which
        the tool guard checks before it; in `straight` code (it runs once, where it stands, in the
        order it is written) a value checked there since is not checked again."""
        told = self._reads_to_check(straight)
        return event if told is None else _marked(event, [Pass(block, tool_read=told)])

    def _reads_to_check(self, straight: bool) -> tuple[tuple[int, int, float], ...] | None:
        """The reads since the last block taken (`tool_reads`) that a check before it checks (None: none)."""
        reads, self.tool_reads = self.tool_reads, []
        told = dict.fromkeys(read for read in reads if read not in self.checked_reads)
        if straight:
            self.checked_reads.update(told)
        return tuple(told) or None

    def _as_programmed(self, ev: Event, owner: Block | None) -> Event | None:
        """`_as_programmed`, warning where it drops a tool parameter read's check (`_unchecked`)."""
        if type(ev) is Pass and ev.tool_read is not None and self.guard_reads:
            self._unchecked(ev.block, ev.tool_read)
        return _as_programmed(ev, owner)

    def _unchecked(self, block: Block, reads: tuple[tuple[int, int, float], ...]) -> None:
        """A read of the tool parameters in text that runs again or elsewhere: no check has a
        place where it runs once with that tool in the spindle."""
        if block.line in self.unchecked_lines:  # (each run of a loop's text reads again)
            return
        self.unchecked_lines.add(block.line)
        said = ", ".join(f"#{key} = {value:g}" for _, key, value in reads)
        self.warnings.warn(  # type: ignore[union-attr]
            f"no tool guard check of {said} (tool {reads[0][0]} in the told table), read in a loop or a "
            "subroutine that runs more than once: make sure the control's tool table gives the same",
            Location(self.file, block.line, None),
        )

    def _compensating(self) -> bool:
        """Whether cutter compensation, or the way out of it, decides where the block's moves go."""
        return self.centre.off_path or self.cutter_comp is not None or self.arc_refused or self.exit_corner

    def _told(self, once: FirstPass, again: bool) -> list[Event]:
        """A loop's first pass in its place (ONCE), once the flow has told whether its text runs
        again: then left as programmed (`_in_flow`'s marks), else as it ran but for the text an
        inner loop ran again; a backward GOTO may no longer run what ran so."""
        events = once.told(again)
        if self.params.fanuc and self.flow is not None:
            lines = [ev.block.line for ev in events if type(ev) is not Pass and not ev.fixed]  # type: ignore[union-attr]
            self.flow.last_run_move = max([self.flow.last_run_move, *lines])
            self.flow.once_move = -1
        return events

    def _in_comp(self, event: Event | tuple[Event, ...], block: Block) -> Event | tuple[Event, ...]:
        """A block's events with cutter compensation on, or the first move after G40: its
        moves are marked `fixed` (the tool is off the programmed path, by the radius the
        control applies).  The first move after G40 brings it back to the programmed end
        point.  As rs274ngc says, no arc may come after G40 before a G0/G1 move (a G28/G30
        or a canned cycle is not one)."""
        if (
            self.comp_radius == 0.0
        ):  # a radius of 0: the tool stays on the programmed path (rs274ngc checks nothing either)
            return event
        events: tuple[Event, ...] = event if type(event) is tuple else (event,)  # type: ignore[assignment]
        moves: list[Line | Arc] = [ev for ev in events if type(ev) is not Pass]  # type: ignore[misc]
        if not moves:
            return event
        if self.exit_corner:  # (the control rounds the corner between the exit move's text and this one's)
            self.exit_corner = False
            for move in moves:
                move.fixed = COMP
            self.centre.corrected = False
            return event
        leaving = self.cutter_comp is None and self.centre.off_path
        if self.arc_refused:
            if type(moves[0]) is Arc:
                self._fail(
                    "The move just after exiting cutter compensation mode must be straight, not an arc",
                    block,
                    block.items[0],
                )
            self.arc_refused = moves[0].fixed in (CYCLE, HOLE) or _expanding(events[0]) or _homes(block)
        if self.cutter_comp is not None and self.comp_radius:
            self._check_radius(moves, block, self.comp_radius)
        # (with a lathe tool's orientation 1-8 the control moves its tip, not its centre, along the offset contour)
        self.centre.follow(moves, self._comp_side(), self.comp_orientation in (0, 9))
        self.exit_corner = leaving and self.corner is not None
        if moves[0].fixed and any(_expanding(ev) for ev in events):  # a cycle left as programmed stays one
            kept = tuple(ev for ev in events if not _expanding(ev))
            return kept if len(kept) != 1 else kept[0]
        return event

    def _comp_side(self) -> float | None:
        """The radius compensation offsets by, positive to the left (G41, G41.1), negative to the
        right (0: the radius is unknown); None: compensation is off (`ToolCentre.follow`)."""
        if self.cutter_comp is None:
            return None
        radius = self.comp_radius or 0.0
        return radius if self._on_the_left() else -radius

    def _on_the_left(self) -> bool:
        """Whether the tool runs left of the contour as the control moves it: G41 (G41.1), but for G42
        under a mirror image of one axis of the plane, which interchanges G41 and G42 as it does G02
        and G03 (SINUMERIK 802D sl/840D ISO Milling programming manual, 3.2 "Programmable mirror image",
        table 3-6)."""
        return (self.cutter_comp in (41.0, 41.1)) != (self._context or self.context()).reverses

    def _check_radius(self, moves: list, block: Block, radius: float) -> None:
        """rs274ngc's checks of moves under compensation against the tool radius: the entry move
        (the first) longer than it in the plane, an entry arc's chord too, and no arc on the
        side the tool is on (G41 and G3, G42 and G2) of a radius not above it.  (The gouging
        checks of later moves need the offset path, which ncpp does not make.)"""
        item = block.items[0]
        a, b, _ = PLANE_AXES[self.plane]
        first = moves[0]
        if (
            not self.centre.off_path
            and math.hypot(first.end[a] - first.start[a], first.end[b] - first.start[b]) <= radius
        ):
            what = ENTRY_ARC_TOO_SHORT if type(first) is Arc else ENTRY_TOO_SHORT
            self._fail(what, block, item)
        left = self._on_the_left()
        for arc in moves:
            if type(arc) is Arc and (arc.turn > 0) == left:
                if math.hypot(arc.start[a] - arc.center[a], arc.start[b] - arc.center[b]) <= radius:
                    self._fail("Tool radius not less than arc radius with comp", block, item)

    def _unrounded(self, pending: Line, held: list[Event]) -> Iterator[Event]:
        """A held corner line whose corner cannot be made: it passes through, uninterpreted."""
        yield Pass(pending.block)
        yield from held
        held.clear()

    def _round_corner(
        self, first: Line, corner: tuple, second: Event, warnings: Warnings
    ) -> list[Event] | None:
        """[shortened first line, fillet arc or chamfer line, second line from the tangent point]."""
        kind, size, item = corner
        where = Location(self.file, first.block.line, item.start + 1)
        if type(second) is not Line or second.rapid or first.rapid:
            self.done = True
            warnings.warn("Fanuc corner rounding next to an arc or a rapid move is outside the motion "
                          "interpreter's scope; from this line on the program passes through uninterpreted", where)  # fmt: skip
            return None
        try:
            pieces = round_corner(first, second, kind, size)
        except CornerError as err:
            raise NcppError(str(err), where) from None
        if first.fixed == COMP or second.fixed == COMP:  # the control rounds the contour, then offsets it
            pieces[1].fixed = COMP  # type: ignore[union-attr]  # (the lines keep their own)
        if first.centre_shift is not None or second.centre_shift is not None:
            # (the same: every piece left as programmed, the lines too)
            for piece in cast(list[Line | Arc], pieces):
                if piece.centre_shift is not None or piece is pieces[1]:
                    piece.fixed, piece.centre_shift = COMP, None
        return pieces

    def context(self) -> Context:
        if self._context is None:
            offset = self.g5x[self.coord_system]
            self._context = Context(
                self.plane,
                self.absolute,
                self.arc_absolute,
                self.inch,
                tuple(offset[i] + self.g92[i] + self.tool[i] for i in range(3)),  # type: ignore[arg-type]
                tuple(self.tool[:3]),  # type: ignore[arg-type]
                self.inverse_time,
                self.coord_system,
                str(self.spindle_tool) if self.spindle_tool else "",
                self.zeros_set.get(self.coord_system),
                self._rotation(),
                self._rotation_plane(),
                self.mirror,
            )
        return self._context

    def _rotation(self) -> tuple[float, float, float] | None:
        """`Context.rotation` in effect: Fanuc's G68 about its centre, or the active system's G10 L2 R about
        the system's zero, where the G92 offset is added before the control turns the point (rs274ngc's
        canon: machine = R (p + G92) + G5x + tool, that is R (p - c) + c + G92 + G5x + tool, c = -G92)."""
        if self.g68 is not None:
            return self.g68
        angle = self.rotations.get(self.coord_system)
        return None if angle is None else (angle, 0.0 - self.g92[0], 0.0 - self.g92[1])

    def _rotation_plane(self) -> int:
        """The plane `_rotation` turns: G68's (Fanuc), else XY (G10 L2 R turns about Z)."""
        return self.g68_plane if self.g68 is not None else 17

    # -- one block ------------------------------------------------------------------
    def block(self, block: Block) -> Event | tuple[Event, ...]:
        """The event(s) of one block; updates the modal state.  Under a rotation of the coordinate
        system the moves are in the turned frame, a translation of the machine's (`Context.turned`:
        `_line`, `_arc` turn their points as they make them)."""
        events = self._block_events(block)
        if self.unpositioned and _moves(events):
            self._note_positioned(block)
        if self.unsettled_rotation is not None and _moves(events):
            self._settle_rotation(block)
        return events

    def _note_positioned(self, block: Block) -> None:
        """The axes X Y Z a block's move puts at a known position (off `unpositioned`): those it
        names in G90 (a canned cycle's X Y: where it leaves Z depends on where it started), and
        those a G28/G30 homes (the named ones, or all)."""
        homes = _homes(block)
        if not (homes or self.absolute):
            return
        named = {
            "XYZ".index(item.letter)
            for item in block.items
            if (type(item) is Word or type(item) is ExprWord) and item.letter in "XYZ"
        }
        if homes:
            self.unpositioned -= named or {0, 1, 2}
        else:
            self.unpositioned -= named - {2} if self.motion in self.canned else named

    def _settle_rotation(self, block: Block) -> None:
        """Fanuc: after G68, moves in G91 run from where the tool stood at G68 (the centre for them,
        Fanuc Series 16/18-MC operator's manual, "Coordinate system rotation"), as they do here; after G69
        the first move must be absolute (its WARNING).  Until a move gives both axes of the rotation's
        plane (X and Y in G17, Z and X in G18, Y and Z in G19) absolutely, a move that gives one of them
        alone takes the other from a position the manual does not say: not followed; nor a G91 move of
        one of them after G69.  A G53 move leaves this as it is; a G28/G30 in G91 whose increments of
        them are 0 (the return posts write) moves from where the tool stands and homes them, which places
        them as an absolute move does (`G91 G28 Z0.` then `G28 X0. Y0.` after a G68 in G18)."""
        letters = plane_letters(self.g68_plane)
        given = [
            item for item in block.items if isinstance(item, (Word, ExprWord)) and item.letter in letters
        ]
        codes = {item.value for item in block.items if type(item) is Word and item.letter == "G"}
        if not given or 53.0 in codes:
            return
        placed = {item.letter for item in given} | self.rotation_homed
        if (
            codes & {28.0, 30.0}
            and not self.absolute
            and all(type(i) is Word and i.value == 0.0 for i in given)
        ):
            self.rotation_homed = placed
            self.unsettled_rotation = None if len(placed) == 2 else self.unsettled_rotation
        elif self.absolute and len(placed) == 2:
            self.unsettled_rotation = None
        elif self.absolute:
            raise _OutOfScope(f"an absolute move of {' or '.join(letters)} alone after G{self.unsettled_rotation:g}",
                              given[0].start + 1)  # fmt: skip
        elif self.unsettled_rotation == 69.0:
            raise _OutOfScope(f"an incremental move of {' or '.join(letters)} after G69", given[0].start + 1)

    def _block_events(self, block: Block) -> Event | tuple[Event, ...]:
        items = block.items
        if not items:
            return Pass(block)
        if self._fast:  # absolute G0/G1 with a usable feed: try the plain `X.. Y.. Z..` line
            end = self.pos[:]
            seen = 0
            for item in items:
                if type(item) is not Word:
                    break
                slot = _XYZ_SLOT.get(item.letter)
                if slot is None or seen & slot[1]:
                    break
                seen |= slot[1]
                end[slot[0]] = item.value
            else:
                return self._fast_line(block, end)
        try:
            move = _PLAIN_MOVES[block.signature]
        except KeyError:
            move = _plain_move(block.signature)
        if move is not None and len(items) == move[0] and self.unmoved is None:  # no comment among the words
            event = self._plain_move(block, move)
            if event is not None:
                return event
        words: dict[str, tuple[float, Word | ExprWord]] = {}
        gcodes: dict[int, tuple[float, Word | ExprWord]] | None = None
        mcodes: dict[float, Word | ExprWord] | None = None
        assignments = None
        for item in items:
            kind = type(item)
            if kind is Word:
                numeric: Word = item  # type: ignore[assignment]  # (`kind` is its type: one type() per item)
                letter = numeric.letter
                if letter in _AXIS_LETTERS_F:  # the common case first
                    if letter in words:
                        self._fail(f"Multiple {letter.lower()} words on one line", block, item)
                    words[letter] = (numeric.value, numeric)
                    continue
                value = numeric.value
            elif kind is Comment:
                continue
            elif kind is ExprWord:
                computed: ExprWord = item  # type: ignore[assignment]  # (as above)
                if vacant(computed.expr, self.params):  # Fanuc: `X#1`, #1 vacant, is no X word
                    continue
                letter, value = computed.letter, self._evaluate(computed.expr, block, computed)
            else:
                statement: Statement = item  # type: ignore[assignment]  # (as above)
                what = statement.kind
                if what == "if" and statement.node[2].upper() == "THEN":  # Fanuc `IF [..] THEN #i = ..`
                    if self._evaluate(statement.node[1], block, item) == 0.0:
                        continue
                    statement, what = statement.node[3], "assignment"
                if what == "assignment":
                    target, expr = statement.node
                    key = self._param_key(target, block, item)
                    if type(key) is str and not self.params.exists(key):
                        # rs274ngc creates the name (at 0) as it reads it: the rest of the line,
                        # the value's expression too, reads 0; the value is set after the line
                        self.params.write(key, 0.0)
                    assignments = assignments or []
                    assignments.append((key, self._assigned(key, expr, block, item), item))
                elif what == "oword" and len(statement.node) == 1:  # `O<name>` alone: a program's name
                    pass
                elif what == UNREADABLE:  # read where it runs, as rs274ngc reads it
                    raise statement.node[0]
                elif what == STRAY_TAPE:  # a `%` after the program's first line that was not one, or `% text`
                    alone = statement.node[0].strip() == "%"
                    why = "only where the program starts with one" if alone else "is a line of % alone"
                    self._fail(f"Bad character '%' used (a tape mark {why})", block, item)
                elif what == "external_output":
                    if not self.external_output:
                        self._fail("Unknown word where unary operation could be", block, item)
                elif what not in IGNORED_STATEMENTS:
                    raise _OutOfScope(OUT_OF_SCOPE_STATEMENT.get(what, what), item.start + 1)
                continue
            if letter == "G":
                if value in self.idle_cancels and self._cancels_nothing(value, block):
                    continue
                group = G_GROUP.get(value)
                if group is None:
                    self._fail("Unknown g code used", block, item)
                if gcodes is None:
                    gcodes = {}
                elif group in gcodes:
                    if group == 1 and (value == 80.0 or gcodes[1][0] == 80.0):
                        # rs274ngc lets G80 share a line with a motion code (`G00 G80 G90`): the motion wins
                        if value == 80.0:
                            continue
                    else:
                        self._fail("Two g codes used from same modal group", block, item)
                gcodes[group] = (value, item)  # type: ignore[assignment]  # (a word: `kind`)
            elif letter == "M":
                if mcodes is None:
                    mcodes = {}
                mcodes[value] = item  # type: ignore[assignment]  # (a word: `kind`)
            elif letter == "N" or letter == "$":
                continue
            else:
                if letter in words:
                    self._fail(f"Multiple {letter.lower()} words on one line", block, item)
                words[letter] = (value, item)  # type: ignore[assignment]  # (a word: `kind`)
        if assignments is not None:  # rs274ngc: after the whole line is read
            for key, assigned, item in assignments:
                if key in _FANUC_MESSAGES and self.params.fanuc:
                    if isinstance(assigned, str):  # (an alarm number ncpp cannot know)
                        raise _OutOfScope(assigned, item.start + 1)
                    self._fanuc_message(key, assigned, block, item)
                    continue
                try:
                    if isinstance(assigned, str):
                        self.params.set_unknown(key, assigned)
                    elif assigned is None and type(key) is int:  # `#i = #0`: vacant, as Fanuc assigns it
                        self.params.vacate(key)
                    else:
                        self.params.write(key, 0.0 if assigned is None else assigned)
                except ExpressionError as err:
                    self._fail(str(err), block, item)
                except OutOfScope as err:
                    raise _OutOfScope(str(err), item.start + 1) from None
        if mcodes is None:
            if gcodes is None:
                if not words:
                    return Pass(block)
                motion = self.motion
                if (
                    motion is not None
                    and words.keys() <= _PLAIN_LETTERS[motion]
                    and not words.keys() <= _F_ONLY
                ):
                    return self._modal_move(block, words, motion)
            elif len(gcodes) == 1 and 1 in gcodes:
                motion, motion_item = gcodes[1]
                plain = _PLAIN_LETTERS.get(motion)
                if plain is not None and words.keys() <= plain:
                    return self._motion_move(block, words, motion, motion_item)
        return self._execute(block, words, gcodes or {}, mcodes or {})

    def _fanuc_message(self, key: int | str, value: float | None, block: Block, item) -> None:
        """Fanuc's `#3000 = n (MESSAGE)`: the control stops with alarm 3000 + n and the message,
        so ncpp refuses the program there; `#3006 = n (MESSAGE)`: it stops and shows the message
        until the operator starts it again, as M0 (Fanuc 16i/18i operator's manual, "Custom macro",
        System variables: alarm #3000, stop with message #3006)."""
        comments = [i for i in block.items[block.items.index(item) + 1 :] if type(i) is Comment]
        message = comments[0].text if comments else ""
        if key == 3000:
            self._fail(f"macro alarm {3000 + int(value or 0)}: {message}".rstrip(": "), block, item)
        self.placed.clear()

    def _fanuc_system_variable(self, key: int) -> float | None:
        """The Fanuc system variables ncpp knows: #5001-#5003, the end point of the last block
        in the workpiece coordinate system, of an axis a move has placed since the start or the
        last stop, with no G92/G52 shift (Fanuc 16i/18i operator's manual, "Custom macro", System
        variables: position information).  Not #5021-#5023, the machine position: the control
        reads it ahead, while the block before moves ("reading during movement: not possible")."""
        axis = key - 5001
        # (whether the control gives a mirrored axis mirrored there is not said)
        mirrored = any(axis == i for i, _ in self.mirror)
        if 0 <= axis <= 2 and axis in self.placed and not any(self.g92[:3]) and not mirrored:
            return self.pos[axis]
        return None

    def _note_placed(self, block: Block) -> None:
        """Which axes a Fanuc program's block puts at a programmed position (`placed`): the X Y Z
        words of a G0-G3 move in G90.  A program stop (M0, M1, M60) lets the operator move the
        machine, and a G10, G28, G92 ... (or a G or M code from a variable) may shift or move it
        elsewhere: no axis is placed after them."""
        signature = block.signature
        if signature is not None and "M" not in signature:  # (plain words: the signature tells)
            effect = _PLACING.get(signature)
            if effect is None:
                effect = _placing(block, self.params)
                if len(_PLACING) < 4096:  # a program has few distinct signatures
                    _PLACING[signature] = effect
        else:
            effect = _placing(block, self.params)
        if effect is None:
            self.placed.clear()
        elif effect and self.absolute and self.motion in (0.0, 1.0, 2.0, 3.0):
            self.placed.update(effect)

    def _set_feed(self, block: Block, word: tuple) -> None:
        if word[0] < 0.0:
            self._fail("Negative f word used", block, word[1])
        self.feed = word[0]
        self.feed_given = True
        if self.feed == 0.0:  # (a feed move is refused now: `_check_feed`, not the fast path)
            self._fast = False

    def _zero_feed(self) -> bool:
        """Whether an F word has set the feed to 0 (a feed move is then refused: `_check_feed`)."""
        return self.feed == 0.0 and self.feed_given

    def _update_fast(self) -> None:
        """Whether a block of plain X/Y/Z words can take the fast path (nothing to check)."""
        motion = self.motion
        self._fast = (
            self.absolute
            and (motion == 0.0 or (motion == 1.0 and not self.inverse_time and not self._zero_feed()))
            and self.unmoved is None
        )

    def _plain_move(self, block: Block, move: tuple) -> Event | None:
        """A block `_plain_move` read (G0-G3 or the modal motion with distinct
        axis / F / IJKR words) without the checks; None leaves it to them."""
        _, code, letters, xyz = move
        items: tuple[Word, ...] = block.items  # type: ignore[assignment]  # (the signature's: words only)
        words_from = len(items) - len(letters)  # after N and G
        if xyz is not None and code is not None and self._enter_straight_motion(code):
            end = self.pos[:]
            for i, item in zip(xyz, items[words_from:]):
                end[i] = item.value
            return self._fast_line(block, end)
        words = {letter: (item.value, item) for letter, item in zip(letters, items[words_from:])}
        if code is not None:
            return self._motion_move(block, words, code, items[words_from - 1])
        motion = self.motion
        if motion is not None and words.keys() <= _PLAIN_LETTERS[motion] and letters != "F":
            return self._modal_move(block, words, motion)
        return None

    def _enter_straight_motion(self, code: float) -> bool:
        """Make `code` the modal motion when it is a `G0` / `G1` whose axis words need no
        check (as `_motion_move` would); False (nothing changed) leaves the block to the checks."""
        if not self.absolute or code > 1.0 or (code == 1.0 and (self.inverse_time or self._zero_feed())):
            return False
        self.motion = code
        self._fast = True
        return True

    def _fast_line(self, block: Block, end: list[float]) -> Line:
        """A Line of the modal motion (G0/G1) from the current position to `end` (the hot path)."""
        pos = self.pos
        self.pos = end
        context = self._context or self.context()
        start_point, end_point = (pos[0], pos[1], pos[2]), (end[0], end[1], end[2])
        # (as `_line` turns them; no call per point where none turns)
        if context.framed:
            start_point, end_point = context.turned(start_point), context.turned(end_point)
        return Line(
            start_point,
            end_point,
            self.motion == 0.0,
            self.feed,
            block,
            context,
            (end[3], end[4], end[5], end[6], end[7], end[8]) if self.uses_extra_axes else (),
            extra_start=(pos[3], pos[4], pos[5], pos[6], pos[7], pos[8]) if self.uses_extra_axes else (),
        )

    def _modal_move(self, block: Block, words: dict, motion: float) -> Event:
        """The hot path: a block of axis words (and F) continuing the modal motion."""
        f = words.get("F")
        if f is not None:
            self._set_feed(block, f)
            self._update_fast()
        if motion > 1.0:
            return self._arc(block, words, motion, None, None)
        if motion == 1.0 and (self.inverse_time or self.feed == 0.0):
            self._check_feed(
                block, words, "Cannot do g1 with zero feed rate", "F word missing with inverse time g1 move"
            )
        if not self.uses_extra_axes and not words.keys() <= _XYZF:
            self.uses_extra_axes = True
        end = self._base()
        if self.absolute:
            for letter, value in words.items():
                if letter != "F":
                    end[AXIS_INDEX[letter]] = value[0]
        else:
            for letter, value in words.items():
                if letter != "F":
                    end[AXIS_INDEX[letter]] += value[0]
        return self._fast_line(block, end)  # motion is the modal motion here

    def _motion_move(self, block: Block, words: dict, motion: float, motion_item: Word | ExprWord) -> Event:
        """`G0`-`G3` and words that need no check: what `_execute` does with such a block."""
        f = words.get("F")
        if f is not None:
            self._set_feed(block, f)
        self.motion = motion
        if motion > 1.0:
            event: Event = self._arc(block, words, motion, motion_item, motion_item)
        else:
            event = self._straight(block, words, motion, False)
            self.corner = None  # plain words hold no corner word
        self._update_fast()
        return event

    def _execute(self, block: Block, words: dict, gcodes: dict, mcodes: dict) -> Event | tuple[Event, ...]:
        mode0, mode0_item = gcodes.get(0, (None, None))
        mode1, mode1_item = gcodes.get(1, (None, None))
        axis_item = next((item for letter, (_, item) in words.items() if letter in AXIS_INDEX), None)
        polar_item = (words.get("@") or words.get("^") or (None, None))[1]
        if polar_item is not None:
            self._check_polar(block, words, polar_item)
        for value, item in mcodes.items():  # subprogram calls use words (L, P) of their own
            if value in OUT_OF_SCOPE_M:
                raise _OutOfScope(OUT_OF_SCOPE_M[value], item.start + 1)
        tool_axes = gcodes.get(8, (None,))[0] == 43.1  # G43.1's axis words are offsets, not a move
        motion = self._motion_to_be(
            block, 43.1 if tool_axes and mode0 is None else mode0, mode1, mode1_item, axis_item, polar_item
        )
        self._check_words(block, words, gcodes, mcodes, motion, mode0, mode0_item, mode1_item)
        if self.cutter_comp is not None or 7 in gcodes:
            self._check_with_comp(block, words, gcodes, mcodes, motion, mode1_item or axis_item)
        self._check_scope(words, gcodes)

        # rs274ngc's order of execution (interp_execute.cc, convert_g)
        if 5 in gcodes:
            self._set(inverse_time=gcodes[5][0] == 93.0, per_revolution=gcodes[5][0] == 95.0)
        if "F" in words:
            self._set_feed(block, words["F"])
        if 2 in gcodes:
            self._set(plane=int(gcodes[2][0]))
        if 6 in gcodes:
            self._set_units(gcodes[6][0] == 20.0)
        if "D" in words and self.modal_d:
            self._set(radius_offset=self._radius_offset(block, words["D"], 7 in gcodes))
        if 7 in gcodes:
            self._cutter_compensation(block, gcodes[7], words)
        if "T" in words:
            self.selected_tool = self._tool_number(words["T"], block)
        for code, turning in ((3.0, 1), (4.0, -1), (5.0, 0), (19.0, 0)):  # M19 orients: stopped
            if code in mcodes:
                self.spindle = turning
        if 6.0 in mcodes:
            self._set(spindle_tool=self.selected_tool, tool_changed=True)
        if 61.0 in mcodes and "Q" in words:
            self._set(spindle_tool=self._tool_number(words["Q"], block), tool_changed=True)
        told = None
        if 8 in gcodes:
            told = self._tool_length(gcodes[8], words, block, changed=6.0 in mcodes)
        selected = None
        if 12 in gcodes:
            number = selected = _COORD_SYSTEM[gcodes[12][0]]
            if number in self.untold:
                self._warn_untold(number, block, gcodes[12][1])
            self._coordinate_system(number)
        if 3 in gcodes:
            self._set(absolute=gcodes[3][0] == 90.0)
        if 4 in gcodes:
            self._set(arc_absolute=gcodes[4][0] == 90.1)
        if 10 in gcodes:
            self.retract_to_r = gcodes[10][0] == 99.0
        events: Event | tuple[Event, ...] | None = None
        previous, active = self.motion, self.coord_system  # (a G10 L20 P0's system, before an M2 resets it)
        if mode0 is not None and mode0 not in (4.0, 53.0):
            events = self._non_modal(block, words, mode0)
        if mode1 is not None:
            self.motion = self._motion_mode_after(mode1, previous)
        if motion is not None:
            motion_word = mode1_item if mode1_item is not None else axis_item
            if motion <= 1.0:
                held = self.motion is None  # (axis words before the program names G0-G3: `_held_move`)
                if held:
                    self._held_move(block, words, motion_word)
                events = self._straight(block, words, motion, mode0 == 53.0)
                if held:
                    events.fixed = HELD
                self.corner = _corner_word(words, motion)
            elif motion in self.canned:
                events = self._cycle(block, words, motion, previous, motion_word)
            elif motion == RIGID_TAP:
                events = self._rigid_tap(block, words, motion_word)
            else:
                events = self._arc(block, words, motion, motion_word, mode1_item)
        if 2.0 in mcodes or 30.0 in mcodes:
            self._program_end()
        self._update_fast()
        offset_told = self._offset_told(mode0, words, active)
        marks = (
            [Pass(block, offset_told=offset_told, zero_placed=self._zero_placed(mode0, words, active))]
            if offset_told is not None
            else []
        )
        if selected in self.told_zeros:
            marks.append(Pass(block, zero_told=selected))
        if told is not None:
            marks.append(Pass(block, length_told=told))
        if marks:
            return _marked(events, marks)
        return Pass(block) if events is None else events

    def _offset_told(
        self, code: float | None, words: dict, active: int
    ) -> tuple[int, tuple[tuple[int, float], ...]] | None:
        """The offset after a G92 or a G10 L20 (of system P, or of `active`, the system in effect at
        the block, for P0) on the axes X Y Z it names, or after a G92.3 on X Y Z, in mm
        (`Pass.offset_told`); None for other blocks."""
        if code in (92.0, 92.3):
            system, offset = 0, self.g92
        elif code == 10.0 and words["L"][0] == 20.0:
            system = round(words.get("P", (0.0,))[0]) or active
            offset = self.g5x[system]
        else:
            return None
        scale = MM_PER_INCH if self.inch else 1.0
        named = tuple(i for i, letter in enumerate("XYZ") if code == 92.3 or letter in words)
        return system, tuple((i, offset[i] * scale) for i in named)

    def _zero_placed(
        self, code: float | None, words: dict, active: int
    ) -> tuple[int, tuple[float, float, float]] | None:
        """After a G92, or a G10 L20 of `active` (the system in effect at the block), that names X Y Z:
        `active` and where the program's zero then stands in machine mm, the system's zero plus the
        G92 offset applied (`Pass.zero_placed`); None for other blocks, and where the system is turned
        (its G10 L2 R), whose rotation carries the G92 offset."""
        if not all(letter in words for letter in "XYZ") or self.rotations.get(active):
            return None
        if code == 10.0 and round(words.get("P", (0.0,))[0]) not in (0, active):
            return None
        scale = MM_PER_INCH if self.inch else 1.0
        x, y, z = ((self.g5x[active][i] + self.g92[i]) * scale for i in range(3))
        return active, (x, y, z)

    # -- checks (interp_check.cc, enhance_block) ----------------------------------------
    def _motion_to_be(self, block, mode0, mode1, mode1_item, axis_item, polar_item=None) -> float | None:
        """The motion the block makes (enhance_block): polar words (`@` `^`) count as axis
        words, but for G52 and G92, which take axis words only."""
        motion = self._motion_of_words(block, mode0, mode1, mode1_item, axis_item, polar_item)
        if polar_item is not None and motion is None:
            self._fail("Polar coordinates can only be used for motion", block, polar_item)
        return motion

    def _motion_of_words(self, block, mode0, mode1, mode1_item, axis_item, polar_item) -> float | None:
        covets_axes = mode0 in (10.0, 28.0, 30.0, 52.0, 92.0, 43.1)
        any_item = axis_item or polar_item
        if polar_item is not None and mode0 == 92.0 and (mode1 is None or mode1 == 80.0):
            self._fail("Polar coordinates can only be used for motion", block, polar_item)
        if mode1 is not None:
            if mode1 == 80.0:
                if any_item is not None and not covets_axes:
                    self._fail("Cannot use axis values with G80", block, any_item)
                if axis_item is None and mode0 in (52.0, 92.0):
                    self._no_axes(block, mode0)
                return None
            if covets_axes:
                self._fail("Cannot use two g codes that both use axis values", block, mode1_item)
            if any_item is None and mode1 not in (0.0, 1.0, 2.0, 3.0):
                self._fail("All axes missing with motion code", block, mode1_item)
            return mode1
        if covets_axes:
            if axis_item is None and mode0 in (52.0, 92.0):
                self._no_axes(block, mode0)
            return None
        if any_item is not None:
            if self.motion is None:
                if not self.holds_start_mode:
                    self._fail("Cannot use axis values without a g code that uses them", block, any_item)
                return 0.0  # (`_held_move`)
            return self.motion
        return None

    def _held_move(self, block: Block, words: dict, item) -> None:
        """A block of axis words before the program names any of G0-G3 (`holds_start_mode`: Fanuc's and
        Haas's), which the control moves in the motion mode it holds at its start, G00 or G01 as a
        parameter or setting of its own says (fanuc.py, module docstring): followed as a rapid straight
        to its point (the control ends it there in either mode) and left as programmed (`HELD`), with a
        warning at the first.  Out of scope with a corner word (,C ,R: rounded as G01 only), under
        cutter compensation (its offset contour depends on the mode's path) and, with --expand-cycles,
        after a cycle written as G0/G1 blocks (which leave the control in G0 or G1, not the mode it held)."""
        if ",C" in words or ",R" in words:
            raise _OutOfScope("a corner (,C ,R) on a move before the program names G00-G03 (the control moves "
                              "it in a mode it holds at the start, G00 or G01)", item.start + 1)  # fmt: skip
        if self._compensating():
            raise _OutOfScope("a move under cutter compensation before the program names G00-G03 (the "
                              "control moves it in a mode it holds at the start, G00 or G01)", item.start + 1)  # fmt: skip
        if self.expand_cycles and self.cycle_written_out:
            self._fail("--expand-cycles: a canned cycle before the program names G00-G03, whose moves written as "
                       "G0/G1 blocks would change the motion mode this move runs in; leave the option out",
                       block, item)  # fmt: skip
        if not self.held_told and self.warnings is not None:
            self.held_told = True
            self.warnings.warn(HELD_MOVES, Location(self.file, block.line, item.start + 1))

    def _motion_mode_after(self, mode1: float, previous: float | None) -> float | None:
        """The modal motion once `mode1` (a motion code or G80) is read, `previous` in effect."""
        if mode1 in self.canned and previous not in self.canned:
            self.before_cycle = previous
        if mode1 != 80.0:
            return mode1
        if not self.cycles_own_group:
            return None
        return self.before_cycle if previous in self.canned else previous

    def _check_polar(self, block: Block, words: dict, item) -> None:
        """enhance_block's checks of polar words (`@` radius, `^` angle, LinuxCNC): in the XY
        plane in effect before the line, without X and Y; and what ncpp does not follow."""
        if self.plane != 17:
            self._fail("Cannot use polar coordinate except in G17 plane", block, item)
        for letter in "XY":
            if letter in words:
                self._fail(f"Cannot specify both polar coordinate and {letter} word", block, words[letter][1])
        if self.cutter_comp is not None:  # rs274ngc then starts from the programmed point, not the tool's
            raise _OutOfScope("polar coordinates under cutter compensation", item.start + 1)

    def _check_words(self, block, words, gcodes, mcodes, motion, mode0, mode0_item, mode1_item) -> None:
        """The per-word checks of rs274ngc's check_g_codes and check_other_codes."""
        g7 = gcodes.get(7, (None,))[0]
        if mode0 == 4.0 and "P" not in words:
            self._fail("Dwell time missing with G4", block, mode0_item)
        if mode0 == 53.0:
            if motion not in (0.0, 1.0):
                self._fail("Must use G0 or G1 with G53", block, mode0_item)
            if "@" in words or "^" in words:
                self._fail("Cannot use polar coordinates with G53", block, mode0_item)
            distance = gcodes.get(3, (None,))[0]
            if distance == 91.0 or (distance is None and not self.absolute):
                self._fail("Cannot use g53 incremental", block, mode0_item)
        if mode0 == 10.0:
            l_number = words.get("L", (None,))[0]
            if l_number not in self.g10_l_numbers:
                self._fail("Line with G10 does not have L1, L10, L11, L2, or L20", block, mode0_item)
            p = words.get("P", (0.0,))[0]
            if abs(p - round(p)) > 0.0001:
                self._fail("P value not an integer with G10", block, words["P"][1])
            if l_number in (2.0, 20.0) and (
                "P" not in words or not 0 <= round(p) <= 9
            ):  # P0: the current system
                self._fail(
                    f"P value out of range (0-9) with G10 L{l_number:.0f}",
                    block,
                    words.get("P", (0, mode0_item))[1],
                )
        cycle = motion in _CYCLES
        for letter in "ABC":
            if letter in words and cycle:
                self._fail(
                    f"Cannot put a{'n' if letter == 'A' else ''} {letter.lower()} in canned cycle",
                    block,
                    words[letter][1],
                )
        if (
            "D" in words
            and not self.modal_d
            and g7 not in (41.0, 42.0, 41.1, 42.1)
            and gcodes.get(14, (None,))[0] != 96.0
            and motion != 71.0
        ):
            self._fail("D word with no G41, G41.1, G42, G42.1, G71, or G96 to use it", block, words["D"][1])
        threading = (
            motion == 76.0 and motion not in self.canned
        )  # (rs274ngc's G76; Fanuc's fine boring is a cycle)
        if "E" in words and not threading and not mcodes.keys() & {66.0, 67.0, 68.0}:
            self._fail("E word with no G70, G76, M66, M67 or M68 to use it", block, words["E"][1])
        if "H" in words and gcodes.get(8, (None,))[0] not in (43.0, 43.2, 43.4, 43.5) and not threading:
            self._fail("H word with no G43 or G76 to use it", block, words["H"][1])
        if motion == RIGID_TAP and self.rigid_tapping:
            self._check_rigid_tap(block, words, mode0_item or mode1_item)
        for letter in "IJ":
            if (
                letter in words
                and motion not in _ARC_LIKE
                and mode0 != 10.0
                and not (
                    letter == "I" and motion == RIGID_TAP  # (G33.1's I: the return's spindle speed factor)
                )
            ):
                self._fail(
                    f"{letter} word with no G2, G3, G5, G5.1, G10, G71, G76, or G87 to use it",
                    block,
                    words[letter][1],
                )
        if (
            "K" in words
            and (motion not in _K_MOTIONS or motion == 76.0 and not threading)
            and not ("K" in self.repeat_letters and motion in self.canned)
        ):
            self._fail("K word with no G2, G3, G33, G33.1, G71, G76, or G87 to use it", block, words["K"][1])
        if "L" in words and not (motion in _CYCLES or motion in (76.0, 5.2, 73.0, 71.0) or mode0 == 10.0
                                 or g7 is not None and g7 != 40.0 or 66.0 in mcodes):  # fmt: skip
            self._fail(
                "L word with no G10, cutter compensation, canned cycle, digital/analog input, or NURBS code",
                block,
                words["L"][1],
            )
        if "P" in words:
            p, p_item = words["P"]
            user_m = any(100.0 <= m <= 199.0 for m in mcodes)
            peck_p = self.peck_dwell and motion in PECKING or self.any_cycle_p and motion in self.canned
            if not (mode0 in (10.0, 4.0) or gcodes.get(13, (None,))[0] == 64.0 or motion in _P_MOTIONS
                    or motion == 87.0 and not self.back_bore_holes
                    or mcodes.keys() & _P_MCODES or user_m or peck_p):  # fmt: skip
                self._fail("P word with no G2 G3 G4 G10 G64 G5 G5.2 G71 G76 G82 G86 G88 G89 or M50 M51 M52 M53 "
                           "M62 M63 M64 M65 M66 or user M code to use it", block, p_item)  # fmt: skip
            if motion in (2.0, 3.0):
                if abs(round(p) - p) > 0.001:
                    self._fail("P value not an integer with M19 G2 or G3", block, p_item)
                if round(p) < 1:
                    self._fail("P value should be 1 or greater with G2 or G3", block, p_item)
        if "Q" in words and not (motion in _Q_MOTIONS or mode0 == 10.0 or gcodes.get(13, (None,))[0] == 64.0
                                 or motion == 87.0 and not self.back_bore_holes
                                 or mcodes.keys() & {66.0, 67.0, 68.0, 61.0, 19.0}
                                 or any(100.0 <= m <= 199.0 for m in mcodes)):  # fmt: skip
            self._fail(
                "Q word with no G5, G10, G64, G73, G76, G83, M19, M66, M67, M68 or user M code that uses it",
                block,
                words["Q"][1],
            )
        if "R" in words:
            if gcodes.get(13, (None,))[0] == 64.0 and 19.0 in mcodes:
                self._fail(
                    "R word is ambiguous on a line with both G64 and M19 - use separate lines",
                    block,
                    words["R"][1],
                )
            if motion == 0.0 and mode0 is None:
                # (an R of a G code out of scope, `G68 X0. Y0. R45.` under G0: `_check_scope` names it)
                if not any(value in OUT_OF_SCOPE_G for value, _ in gcodes.values()):
                    raise _OutOfScope("R word with G0", words["R"][1].start + 1)
            elif motion == 1.0 and mode0 is None:
                pass  # Fanuc corner rounding `G1 X.. Y.. R..` (rs274ngc refuses it)
            elif not (motion in _R_MOTIONS or g7 in (41.1, 42.1) or mode0 == 10.0 or 19.0 in mcodes):
                self._fail("R word with no g code that uses it", block, words["R"][1])

    def _check_with_comp(self, block, words, gcodes, mcodes, motion, motion_item) -> None:
        """What rs274ngc refuses with cutter compensation on, in its order of execution: a tool
        change and a plane change (before G40-G42 on the line take effect), then, with the
        compensation the line leaves on, G41/G42 again, tool length, coordinate system and
        path control changes, G10 L2/L20 of the active system, G28/G30, G53, G52/G92, and
        canned cycles, probing and splines."""
        if self.cutter_comp is not None:
            if 6.0 in mcodes:
                self._fail("Cannot change tools with cutter radius compensation on", block, mcodes[6.0])
            if 2 in gcodes and gcodes[2][0] != self.plane:
                self._fail("Cannot change planes with cutter radius compensation on", block, gcodes[2][1])
        code, item = gcodes.get(7, (None, None))
        if code is not None and code != 40.0 and self.cutter_comp is not None:
            if self.comp_again:
                raise _OutOfScope(f"G{code:g} while cutter compensation is on", item.start + 1)
            self._fail("Cannot turn cutter radius comp on when on", block, item)
        if code == 40.0 or (code is None and self.cutter_comp is None):
            return  # off from this line's G40 on
        for group, refusal in _REFUSED_WITH_COMP.items():
            if group in gcodes:
                self._fail(refusal, block, gcodes[group][1])
        mode0, mode0_item = gcodes.get(0, (None, None))
        message = _MODE0_WITH_COMP.get(mode0)
        if mode0 == 53.0 and self.comp_radius == 0.0:  # (G53 only with a radius; the others with any)
            message = None
        if (
            mode0 == 10.0
            and words.get("L", (None,))[0] in (2.0, 20.0)
            and round(words["P"][0]) in (0, self.coord_system)
        ):
            message = "Cannot change the active coordinate system with cutter radius compensation on"
        if message is not None and mode0 in (28.0, 30.0) and self.returns_under_comp:
            raise _OutOfScope(f"G{mode0:g} under cutter compensation", mode0_item.start + 1)
        if message is not None:
            self._fail(message, block, mode0_item)
        message = _MOTION_WITH_COMP.get(motion)
        if message is not None:
            self._fail(message, block, motion_item)

    def _cutter_compensation(self, block: Block, code_item: tuple, words: dict) -> None:
        """G40 off; G41/G42 (the radius of tool D, or of the tool in the spindle, where ncpp is
        told the tool table) and G41.1/G42.1 (D the diameter) on, in the XY or XZ plane
        (LinuxCNC's manual, G41 G42: "It is an error if the YZ plane is active"), with a lathe
        tool's orientation (the table's Q, G41.1's L) in the XZ plane only.  The
        moves are followed as programmed (`_in_comp`); the radius is what rs274ngc checks
        them against (`_check_radius`), and a radius of 0 leaves the tool on the path.  Under a
        rotation about Z (G10 L2 R, Fanuc's G68) in G17: the controls offset the turned contour
        (Fanuc Series 16/18-MC operator's manual, "Coordinate system rotation": cutter compensation
        "is performed after the coordinate system is rotated"), whose moves are in the turned frame
        here, so their tool centre is too; in G18 the offset would turn out of its plane under a rotation
        about Z, and under Fanuc's G68 in G18 a lathe tool's orientation would not turn with the contour
        (neither followed)."""
        code, item = code_item
        if code == 40.0:
            self.arc_refused = self.arc_refused or self.centre.off_path
            self.cutter_comp = self.comp_radius = None
            return
        if self.plane not in (17, 18):
            self._fail("Cutter radius compensation allowed only in XY, XZ planes", block, item)
        if self.plane != 17 and self._rotation() is not None:
            raise _OutOfScope(
                f"cutter compensation G{code:g} in G{self.plane} under a coordinate system rotation",
                item.start + 1,
            )
        d = words.get("D")
        if code in (41.1, 42.1):
            if d is None:
                self._fail(f"G{code:g} with no D word", block, item)
            self.comp_radius = abs(d[0]) / 2
            self.comp_orientation = self._orientation(block, code, words.get("L"))
        elif d is not None:
            if d[0] < 0.0 or abs(d[0] - round(d[0])) > 0.0001:
                self._fail(f"G{code:g} requires D word to be a whole number", block, d[1])
            if not self._in_table(round(d[0])):
                self._fail(f"Requested tool {round(d[0])} not found in the tool table", block, d[1])
        if code in (
            41.0,
            42.0,
        ):  # the radius of tool D, or of the tool in the spindle, from the table ncpp is told
            number = round(d[0]) if d is not None else self.radius_offset
            number = self.spindle_tool if number is None else number
            radius = self._radius_mm(number)
            self.comp_radius = None if radius is None else radius / (MM_PER_INCH if self.inch else 1.0)
            told = 0 if self.tools is None else self.tools.orientation(number)
            self.comp_orientation = self.set_orientations.get(number, told)
            if self.plane != 18 and self.comp_orientation not in (0, 9):
                self._fail(f"G{code:g} with lathe tool, but plane is not G18", block, item)
        self.cutter_comp = code

    def _radius_mm(self, number: int) -> float | None:
        """Tool (D offset) `number`'s radius in mm, as the program set it or the told table gives it
        (None: not known)."""
        if number in self.set_radii:
            radius = self.set_radii[number]
            return None if radius is None else abs(radius)
        return None if self.tools is None else self.tools.diameter(number) / 2

    def _radius_offset(self, block: Block, word: tuple, with_code: bool) -> int:
        """A modal D: a whole offset number, 0 for none (Fanuc's D00).  One without G40/G41/G42
        under compensation changes the radius (or, D0, ends it) from its block's end: not followed."""
        value, item = word
        if value < 0.0 or abs(value - round(value)) > 0.0001:
            self._fail("D word must be a whole number", block, item)
        if self.cutter_comp is not None and not with_code:
            raise _OutOfScope("a D word under cutter compensation (a new radius from its block's end)",
                              item.start + 1)  # fmt: skip
        return round(value)

    def _orientation(self, block: Block, code: float, word: tuple | None) -> int:
        """G41.1/G42.1's lathe tool orientation, its L word (0 without one): in G18 only, as
        rs274ngc checks it."""
        if word is None:
            return 0
        value, item = word
        if value != round(value):
            self._fail("Non integer value for integer", block, item)
        if self.plane != 18:
            self._fail(f"G{code:g} with L word, but plane is not G18", block, item)
        return int(value)

    def _cancels_nothing(self, code: float, block: Block) -> bool:
        """Whether `code`, one of `idle_cancels`, cancels nothing in `block` (a dialect whose cancel
        codes may be in effect, or mean something else in some blocks, tells it)."""
        return True

    def _check_scope(self, words: dict, gcodes: dict) -> None:
        for value, item in gcodes.values():
            if value == 50.0 and "S" in words:  # (a lathe's spindle limit, not a mill's scaling cancel)
                raise _OutOfScope(SPINDLE_LIMIT, item.start + 1)
            reason = OUT_OF_SCOPE_G.get(value) if value not in self.canned else None
            if (
                reason is not None
                and not (value == 43.2 and "H" in words)
                and not (value == RIGID_TAP and self.rigid_tapping)
            ):
                raise _OutOfScope(f"{reason} G{value:g}", item.start + 1)
        g10 = gcodes.get(0, (None,))[0] == 10.0
        l_number = words["L"][0] if g10 else None
        if l_number in (1.0, 10.0, 11.0) and not self.tool_table_g10:
            raise _OutOfScope("tool table change G10 L1/L10/L11", gcodes[0][1].start + 1)
        if (
            l_number in (2.0, 20.0)
            and words.get("R", (0.0,))[0] != 0.0
            and not (self.rotating_g10 and l_number == 2.0)
        ):
            raise _OutOfScope("coordinate system rotation G10 R", words["R"][1].start + 1)
        if self._rotation() is not None:
            self._check_turned(words, gcodes)
        elif l_number == 20.0 and self.rotating_g10:
            self._check_turned_zero(words, gcodes)
        turning = self._turns_again(words, gcodes) if self.centre.off_path else None
        if turning is not None:
            raise _OutOfScope("a rotation of the coordinate system before the move that ends cutter compensation",
                              turning.start + 1)  # fmt: skip
        if any(self.g92[:2]) and (self.rotations or (g10 and words.get("R", (0.0,))[0])):
            self._check_reframed(words, gcodes)

    def _turns_again(self, words: dict, gcodes: dict) -> Word | ExprWord | None:
        """The word of the block that changes the rotation in effect (None: none does): a G10 L2 R of
        the system in effect, or another system selected that is turned otherwise (the tool centre's
        offset from the path, in the old turned frame, would be carried into the new one: not followed)."""
        now = self.rotations.get(self.coord_system, 0.0)
        code, item = gcodes.get(0, (None, None))
        if (
            code == 10.0
            and self.rotating_g10
            and words["L"][0] == 2.0
            and round(words.get("P", (0.0,))[0]) in (0, self.coord_system)
            and words.get("R", (now,))[0] != now
        ):
            return item
        selected = _COORD_SYSTEM[gcodes[12][0]] if 12 in gcodes else None
        return gcodes[12][1] if selected is not None and self.rotations.get(selected, 0.0) != now else None

    def _check_reframed(self, words: dict, gcodes: dict) -> None:
        """rs274ngc puts the program position after a new zero or rotation of the system in effect (G10
        L2 of it, another system selected) as if no G92 offset were in effect: with one, where a rotation
        is in effect before or after, its position and the machine's part (not followed)."""
        code, item = gcodes.get(0, (None, None))
        if (
            code == 10.0
            and words["L"][0] in (2.0, 20.0)
            and round(words.get("P", (0.0,))[0]) in (0, self.coord_system)
        ):
            if self.rotations.get(self.coord_system) or words.get("R", (0.0,))[0]:
                raise _OutOfScope("G10 L2 of the system in effect under a rotation and a G92 offset",
                                  item.start + 1)  # fmt: skip
        selected = _COORD_SYSTEM[gcodes[12][0]] if 12 in gcodes else None
        if selected is not None and (self.rotations.get(self.coord_system) or self.rotations.get(selected)):
            raise _OutOfScope(f"G{gcodes[12][0]:g} under a coordinate system rotation and a G92 offset",
                              gcodes[12][1].start + 1)  # fmt: skip

    def _check_turned(self, words: dict, gcodes: dict) -> None:
        """What ncpp does not follow under a rotation of the coordinate system: an offset set from where
        the tool stands (its words would have to be turned with the correction: G92, G10 L20), and a G28 or
        G30 whose intermediate point names X or Y (the axes it places are the turned frame's); so a
        tool's offsets set from where it stands (G10 L10/L11: rs274ngc turns the point first)."""
        code, item = gcodes.get(0, (None, None))
        if code == 92.0 or (code == 10.0 and words["L"][0] == 20.0):
            raise _OutOfScope(f"G{code:g} under a coordinate system rotation", item.start + 1,
                              self._turned_setting(words, gcodes))  # fmt: skip
        if code == 10.0 and words["L"][0] in (10.0, 11.0):
            raise _OutOfScope(f"G10 L{words['L'][0]:g} under a coordinate system rotation", item.start + 1,
                              self._turned_setting(words, gcodes))  # fmt: skip
        letters = plane_letters(self._rotation_plane())
        if code in (28.0, 30.0) and any(letter in words for letter in letters):
            raise _OutOfScope(f"G{code:g} with {' or '.join(letters)} under a coordinate system rotation",
                              item.start + 1)  # fmt: skip

    def _check_turned_zero(self, words: dict, gcodes: dict) -> None:
        """A G10 L20 of another system that a G10 L2 R rotates: rs274ngc sets its zero from the current
        point turned into that system's frame, the plane's axes the block does not name kept there and
        every one turned back by the rotation (LinuxCNC's convert_setup), which ncpp does not follow."""
        number = round(words.get("P", (0.0,))[0])
        if number not in (0, self.coord_system) and self.rotations.get(number):
            raise _OutOfScope("G10 L20 of a rotated coordinate system", gcodes[0][1].start + 1,
                              self._turned_setting(words, gcodes))  # fmt: skip

    def _turned_setting(self, words: dict, gcodes: dict) -> Setting | None:
        """The offset a G92, G10 L10/L11 or G10 L20 sets from where the control stands in the turned
        frame, where it ends interpretation under a rotation (None: a G92 or G10 L20 under a rotation and
        a G92 offset, which rs274ngc places apart).  A block that reads the point in another frame (G10
        L11 G59.3's, G10 L20 of another system that system's) is written after a step back to the
        programmed point, in the program's G0 or G1 mode only (its values cannot be moved by the
        correction in that frame: None in another mode)."""
        l_number = words["L"][0] if gcodes[0][0] == 10.0 else None  # (None: G92)
        other = l_number == 11.0 or (
            l_number == 20.0 and round(words.get("P", (0.0,))[0]) not in (0, self.coord_system)
        )
        if other and (self.motion not in (0.0, 1.0) or not self.rotating_g10):  # (LinuxCNC's: from the point)
            return None
        if l_number != 10.0 and any(self.g92[:2]):
            return None
        values = tuple((i, words[letter][0]) for i, letter in enumerate("XYZ") if letter in words)
        context = self.context()
        return Setting(values, context, context.turned((self.pos[0], self.pos[1], self.pos[2])), leaves=True)

    # -- modal state -------------------------------------------------------------------------
    def _set(self, **changes) -> None:
        for name, value in changes.items():
            setattr(self, name, value)
        self._context = None

    def _set_units(self, inch: bool) -> None:
        if inch == self.inch:
            return
        scale = 1 / MM_PER_INCH if inch else MM_PER_INCH
        zeros = (*self.g5x.values(), *self.home.values())
        for vector in (self.pos, self.g92, self.g92_saved, self.tool, *zeros):
            for i in LINEAR:
                vector[i] *= scale
        if self.comp_radius is not None:
            self.comp_radius *= scale
        self.centre.scale(scale)
        self._set(inch=inch)

    def _shift(self, old: list[float], new: list[float]) -> None:
        """An offset changed from `old` to `new`: the program position moves the other way."""
        for i in range(9):
            self.pos[i] += old[i] - new[i]
            if self.unmoved is not None:
                self.unmoved[i] += old[i] - new[i]
        self._context = None

    def _base(self) -> list[float]:
        """Where a move's axes that its block does not name go: the program position, but after
        a tool change that applied a length (`_tool_length`) the one held before it."""
        if self.unmoved is None:
            return self.pos[:]
        base, self.unmoved = self.unmoved, None
        return base

    def _tool_length(
        self, code_item: tuple, words: dict, block: Block, changed: bool = False
    ) -> tuple[int, float] | None:
        """G43 [H]: the offsets of tool H (0 or none: the tool in the spindle); G43.2 H: those
        added; G43.1: the axis words; G49: none.  In program units, as the control applies them.
        Returns the tool in the spindle and its Z offset in mm where the block applies that
        tool's offsets from the told table (what the tool guard can check: LinuxCNC's #5400 and
        #5403 hold the spindle tool's, whatever H says), else None.

        The machine stays where it is and the program position moves the other way, but in a
        block that also changes the tool (`changed`, M6) rs274 keeps the program position for
        the axes the next move does not name, which so takes the machine by the difference
        (`T4 M6 G43` then `G0 X1` moves Z): `unmoved` holds it for that move (`_base`)."""
        code, item = code_item
        new = [0.0] * 9
        told = None
        if code == 43.1:  # the axes it names; the others keep their offset (rs274ngc)
            new = self.tool[:]
            given = [
                (AXIS_INDEX[letter], value) for letter, (value, _) in words.items() if letter in AXIS_INDEX
            ]
            for i, value in given:
                new[i] = value
            self._note_axes(given)
        elif code in (43.0, 43.2):
            number = self._tool_number(words["H"], block) if "H" in words else 0
            table = self._table_offsets(number or self.spindle_tool, words.get("H", (0, item))[1], block)
            if (
                self.spindle_tool
                and number in (0, self.spindle_tool)
                and self._length_known(self.spindle_tool)
            ):
                told = (self.spindle_tool, table[2])
            scale = 1 / MM_PER_INCH if self.inch else 1.0
            new = [value * scale if i in LINEAR else value for i, value in enumerate(table)]
            if code == 43.2:
                new = [old + added for old, added in zip(self.tool, new)]
        turned = PLANE_AXES[self._rotation_plane()][:2]
        if self._rotation() is not None and any(new[i] != self.tool[i] for i in turned):  # (not turned)
            letters = " or ".join(plane_letters(self._rotation_plane()))
            raise _OutOfScope(
                f"a tool offset in {letters} under a coordinate system rotation", item.start + 1
            )
        moved = next((i for i, _ in self.mirror if new[i] != self.tool[i]), None)  # (not mirrored)
        if moved is not None:
            raise _OutOfScope(f"a tool offset in {'XYZ'[moved]} under a mirror image", item.start + 1)
        held = self.pos[:] if changed else None
        self._shift(self.tool, new)
        self.tool = new
        if changed:
            self.unmoved = held
            self._fast = False
        return told

    def _tool_number(self, word: tuple, block: Block) -> int:
        value, item = word
        if value != int(value) or value < 0:
            self._fail(f"{item.letter} word is not a tool number", block, item)
        number = int(value)
        if not self._in_table(number):
            self._fail(f"Requested tool {number} not found in the tool table", block, item)
        return number

    def _in_table(self, number: int) -> bool:
        """Whether the control's tool table has tool (offset) `number`, as far as ncpp knows: any where
        ncpp is not told the table, else the told table's and those the program set."""
        if self.tools is None or self.tools.offset(number) is not None:
            return True
        return number in self.set_offsets or number in self.set_radii

    def _length_known(self, number: int) -> bool:
        """Whether ncpp knows tool `number`'s length: told in the table, or set by the program."""
        return self.tools is not None or 2 in self.set_offsets.get(number, {})

    def _table_offsets(self, number: int, item, block: Block) -> tuple[float, ...]:
        """Tool `number`'s offsets in mm, as the program set them over the told table's; zero where
        neither tells them (warned once where the length is not known)."""
        if not self._length_known(number):
            self.untold_lengths("G43", "tool.tbl", Location(self.file, block.line, item.start + 1))
        return self._offsets_mm(number)

    def _offsets_mm(self, number: int) -> tuple[float, ...]:
        """Tool `number`'s offsets in mm and degrees, as the program set them over the told table's."""
        told = (self.tools.offset(number) if self.tools is not None else None) or (0.0,) * 9
        changed = self.set_offsets.get(number)
        if not changed:
            return told
        return tuple(changed.get(i, value) for i, value in enumerate(told))

    def _tool_parameter(self, key: int) -> float | None:
        """LinuxCNC's #5400-#5413, the tool in the spindle's number, offsets X Y Z A B C U V W,
        diameter, front and back angles and orientation (G-code manual, "Numbered Parameters"), which
        rs274ngc sets from the tool table's entry at M6 and M61 and at a G10 L1/L10/L11 of that tool:
        in the machine's units (the table's) whatever G20/G21, as rs274 reads them.  Known after the
        program's own change to a tool of the told table; None for the other parameters the control
        keeps."""
        if not TOOL_PARAMETERS[0] <= key <= TOOL_PARAMETERS[-1]:
            return None
        if self.tools is None:
            raise OutOfScope(f"machine-state parameter #{key} of the tool in the spindle, without the tool "
                             "table (--tool-table)")  # fmt: skip
        if not self.tool_changed:  # (the control's tool, from before the program)
            raise OutOfScope(f"machine-state parameter #{key} of the tool in the spindle before the "
                             "program's first tool change (M6, M61)")  # fmt: skip
        number = self.spindle_tool
        if number == 0:
            raise OutOfScope(f"machine-state parameter #{key} with no tool in the spindle")
        if key == TOOL_PARAMETERS[0]:  # (the program's own M6 or M61 chose it)
            return float(number)
        value = self._table_parameter(number, key)
        self.tool_reads.append((number, key, value))  # (the tool guard checks the control's: `_with_reads`)
        return value

    def _table_parameter(self, number: int, key: int) -> float:
        """Tool `number`'s #5401-#5413 (`_tool_parameter`) from the told table and the program's G10 L1."""
        index = key - TOOL_PARAMETERS[1]
        if index < len(OFFSET_LETTERS):  # #5401-#5409
            value = self._offsets_mm(number)[index]
            return value / self.unit_mm if index in LINEAR else value
        if key == TOOL_DIAMETER:
            radius = self.set_radii.get(number)
            return (2 * radius if radius is not None else self.tools.diameter(number)) / self.unit_mm  # type: ignore[union-attr]
        if key == TOOL_ORIENTATION:
            return float(self.set_orientations.get(number, self.tools.orientation(number)))  # type: ignore[union-attr]
        letter = "IJ"[key - TOOL_DIAMETER - 1]  # the front and back angles, degrees
        return self.set_angles.get(number, {}).get(letter, self.tools.angle(number, letter))  # type: ignore[union-attr]

    def _warn_untold(self, number: int, block: Block, item) -> None:
        """Once per system: its zero is taken as the machine zero, which is likely wrong."""
        self.untold.discard(number)
        if self.warnings is not None:
            self.warnings.warn(
                f"{SYSTEMS[number - 1]} selects a work offset ncpp is not told: compensated as if its zero were "
                f"at the machine zero (give --work-offset {SYSTEMS[number - 1]}=X,Y,Z or --var-file)",
                Location(self.file, block.line, item.start + 1),
            )

    def _coordinate_system(self, number: int) -> None:
        if self.rotations.get(self.coord_system) or self.rotations.get(number):
            self._keeping_machine(lambda: setattr(self, "coord_system", number))
            return
        self._shift(self.g5x[self.coord_system], self.g5x[number])
        self.coord_system = number
        self._context = None

    def _keeping_machine(self, change: Callable[[], None]) -> None:
        """A zero or a rotation changes where one is in effect before or after: the machine stays where it
        is, and the program position is its point in the new frame, as rs274ngc keeps it (without a G92
        offset: `_check_reframed`)."""
        held = [self._to_machine(v) for v in (self.pos, self.unmoved) if v is not None]
        change()
        self.pos = self._from_machine(held[0])
        if self.unmoved is not None:
            self.unmoved = self._from_machine(held[1])
        self._context = None

    def _framed(self) -> bool:
        """Whether a rotation or a mirror image moves the program's points (`Context.framed`)."""
        return self._rotation() is not None or bool(self.mirror)

    def _to_machine(self, p: list[float]) -> list[float]:
        """The machine position (program units, all axes) of program point `p`: mirrored (`mirror`), the
        rotation's plane (X Y in G17) turned about its centre (`_rotation`), then G92, the system's zero and
        the tool length added."""
        q = list(p)
        mirror_axes(q, self.mirror)
        rotation = self._rotation()
        if rotation is not None:
            turn_in_plane(q, rotation, self._rotation_plane())
        return [v + g + z + t for v, g, z, t in zip(q, self.g92, self.g5x[self.coord_system], self.tool)]

    def _from_machine(self, m: list[float]) -> list[float]:
        """The program point of machine position `m` (`_to_machine`'s inverse)."""
        q = [v - g - z - t for v, g, z, t in zip(m, self.g92, self.g5x[self.coord_system], self.tool)]
        rotation = self._rotation()
        if rotation is not None:
            turn_in_plane(q, rotation, self._rotation_plane(), -1.0)
        mirror_axes(q, self.mirror)
        return q

    def _program_end(self) -> None:
        """M2/M30: rs274ngc resets some modes and stops reading the program."""
        self._coordinate_system(1)
        self._set(plane=17, absolute=True, inverse_time=False, per_revolution=False)
        self.motion = 1.0
        self.cutter_comp, self.comp_radius, self.arc_refused = None, None, False
        self.centre.reset()
        self.done = self.ended = True

    def _machine(self, i: int) -> float:
        if self._framed():
            return self._to_machine(self.pos)[i]
        return self.pos[i] + self.g5x[self.coord_system][i] + self.g92[i] + self.tool[i]

    def _non_modal(self, block: Block, words: dict, code: float) -> Event | tuple[Event, ...] | None:
        given = [(AXIS_INDEX[letter], value) for letter, (value, _) in words.items() if letter in AXIS_INDEX]
        self._note_axes(given)
        setting = None
        if code == 92.0 or (code == 10.0 and words["L"][0] == 20.0):  # set from the current point
            here = (self.pos[0], self.pos[1], self.pos[2])
            setting = Pass(
                block, setting=Setting(tuple((i, v) for i, v in given if i < 3), self.context(), here)
            )
        if code == 92.0:
            old = self.g92[:]
            for i, value in given:
                self.g92[i] = self.pos[i] + old[i] - value
            self.g92_saved = self.g92[:]
            self._shift(old, self.g92)
        elif code in (92.1, 92.2):
            old = self.g92[:]
            self.g92 = [0.0] * 9
            if code == 92.1:
                self.g92_saved = [0.0] * 9
            self._shift(old, self.g92)
        elif code == 92.3:
            old = self.g92[:]
            self.g92 = self.g92_saved[:]
            self._shift(old, self.g92)
        elif code == 52.0:
            old = self.g92[:]
            for i, value in given:
                self.g92[i] = value
            self._shift(old, self.g92)
        elif code == 10.0 and words["L"][0] not in (2.0, 20.0):
            return self._set_tool_offsets(block, words, given)
        elif code == 10.0:
            p = round(words.get("P", (0.0,))[0])
            number = self.coord_system if p == 0 else p
            old = self.g5x[number][:]
            added = self.incremental_zero_set and not self.absolute
            self._zero_set(number, {i for i, _ in given}, words["L"][0] == 20.0, added)
            self.told_zeros.discard(number)
            if {0, 1, 2} <= {i for i, _ in given}:  # the program says where it is
                self.untold.discard(number)
            angle = words["R"][0] if "R" in words and self.rotating_g10 else None
            if number == self.coord_system and (self.rotations.get(number) or angle):
                self._keeping_machine(lambda: self._set_zero(number, given, words["L"][0], added, angle))
                return setting
            self._set_zero(number, given, words["L"][0], added, angle)
            if number == self.coord_system:
                self._shift(old, self.g5x[number])
        elif code in (28.1, 30.1):
            self.home[int(code)] = [self._machine(i) for i in range(9)]
        elif code in (28.0, 30.0):
            return self._go_home(block, given, self.home[int(code)])
        return setting

    def _set_tool_offsets(self, block: Block, words: dict, given: list[tuple[int, float]]) -> Pass | None:
        """LinuxCNC's G10 L1/L10/L11 P<tool>: the tool's offsets in the control's tool table, for the
        axes the block names (LinuxCNC G-code manual, "G10 L1 Set Tool Table": the given values;
        "G10 L10 Set Tool Table": such that the current point, with the work offsets in effect and
        the new offset applied, reads them; "G10 L11 Set Tool Table": as L10, but as if G59.3 were
        in effect and no G92 offset), R its radius and Q its lathe orientation.  The offset in effect
        changes only at the next G43 (rs274 applies none at the G10).  L10 and L11 set the offset
        from where the control stands, which compensation moves: their `Setting` carries it."""
        l_number, (p, p_item) = words["L"][0], words.get("P", (0.0, words["L"][1]))
        number = round(p)
        if number <= 0:
            self._fail(f"P value out of range with G10 L{l_number:g}", block, p_item)
        if not self._in_table(number):
            self._fail(f"Requested tool {number} not found in the tool table", block, p_item)
        if not given and not words.keys() & set("RQIJ"):
            self._fail("G10 L1 without offsets has no effect", block, words["L"][1])  # (rs274's, for each L)
        if l_number != 1.0:
            self._check_from_here(block, words, given)
        scale = MM_PER_INCH if self.inch else 1.0
        entry = self.set_offsets.setdefault(number, {})
        for i, value in given:
            entry[i] = self._tool_offset_value(l_number, i, value) * (scale if i in LINEAR else 1.0)
        if "R" in words:
            self.set_radii[number] = words["R"][0] * scale
        if "Q" in words:
            self.set_orientations[number] = round(words["Q"][0])
        for letter in "IJ":
            if letter in words:
                self.set_angles.setdefault(number, {})[letter] = words[letter][0]
        if l_number == 1.0 or not given:
            return None
        here = (self.pos[0], self.pos[1], self.pos[2])
        return Pass(block, setting=Setting(tuple(given), self.context(), here))

    def _tool_offset_value(self, l_number: float, i: int, value: float) -> float:
        """Axis `i`'s tool offset (program units) that G10 L`l_number` sets from its word `value`."""
        if l_number == 1.0:
            return value
        here = self.pos[i] + self.tool[i]  # (the machine position less the work offsets in effect)
        if l_number == 10.0:
            return here - value
        return here + self.g5x[self.coord_system][i] + self.g92[i] - self.g5x[9][i] - value

    def _check_from_here(self, block: Block, words: dict, given: list[tuple[int, float]]) -> None:
        """G10 L10/L11 read where the tool stands: out of scope where ncpp does not know it (an axis
        no move has placed since the start, or one held over a tool change in its block, or under
        cutter compensation), and for axes past X Y Z (compensation moves them too)."""
        col = words["L"][1].start + 1
        name = f"G10 L{words['L'][0]:g}"
        if any(i >= 3 for i, _ in given):
            raise _OutOfScope(f"{name} of an axis other than X Y Z", col)
        unknown = [AXES[i] for i, _ in given if i in self.unpositioned]
        if unknown or self.unmoved is not None:
            what = f"{' '.join(unknown)} no move has put at a known position" if unknown else "a tool change"
            raise _OutOfScope(
                f"{name} after {what} (it sets the tool offset from where the tool stands)", col
            )
        if self._compensating():
            raise _OutOfScope(f"{name} under cutter compensation", col)

    def _set_zero(
        self, number: int, given: list[tuple[int, float]], l_number: float, added: bool, angle: float | None
    ) -> None:
        """G10 L2 / L20: system `number`'s zero from the given axes, and its rotation where R gives it."""
        old = self.g5x[number][:]
        for i, value in given:
            if l_number == 2.0:
                self.g5x[number][i] = value + (old[i] if added else 0.0)
            else:  # L20: the current point gets the given coordinates
                self.g5x[number][i] = self.pos[i] + self.g5x[self.coord_system][i] - value
        if angle is not None:
            if angle:
                self.rotations[number] = angle
            else:
                self.rotations.pop(number, None)

    def _zero_set(self, number: int, axes: set[int], l20: bool, added: bool) -> None:
        """Whether system `number`'s zero is known after a G10 of `axes` sets it (`zeros_set`): G10 L2
        giving X Y Z from the machine zero makes it known; G10 L20 sets it from where the tool
        stands, which may be where the operator jogged it: not known; other axes, or values added to
        it (G91 G10 L2 on Fanuc), leave it as known as it was (where the program did not set it
        before, as ncpp is told it)."""
        if l20:
            self.zeros_set[number] = False
        elif not added and {0, 1, 2} <= axes:
            self.zeros_set[number] = True

    def _go_home(self, block: Block, given: list[tuple[int, float]], home: list[float]) -> tuple[Event, ...]:
        """G28/G30: rapid to the (optional) intermediate point, then home the given axes (all if none).
        Both moves are the control's (`HOME`): compensation cannot reach into them.  In G90 the
        intermediate point puts the named axes at their words, in G91 it moves them by their words
        from where the control stands; the home move puts the homed axes at the home position."""
        named = cast(tuple[bool, bool, bool], tuple(any(i == axis for i, _ in given) for axis in range(3)))
        middle = self._ends(given, False)
        first = self._line(block, middle, True)
        first.fixed, first.placed = HOME, named if self.absolute else (False, False, False)
        axes = [i for i, _ in given] or range(9)
        second = self._line(block, self._at_machine(middle, [(i, home[i]) for i in axes]), True)
        second.fixed, second.placed = HOME, named if given else (True, True, True)
        return first, second

    # -- moves ---------------------------------------------------------------------------------
    def _note_axes(self, given) -> None:
        if not self.uses_extra_axes:
            self.uses_extra_axes = any(i >= 3 for i, _ in given)

    def _ends(self, given: list[tuple[int, float]], machine: bool) -> list[float]:
        end = self._base()
        if machine:  # G53: machine coordinates, always absolute
            return self._at_machine(end, given)
        if self.absolute:
            for i, value in given:
                end[i] = value
        else:
            for i, value in given:
                end[i] += value
        return end

    def _at_machine(self, end: list[float], given: list[tuple[int, float]]) -> list[float]:
        """Program point `end` with the given axes put at machine positions (G53, a G28/G30 home)."""
        if self._framed():
            at = self._to_machine(end)
            for i, value in given:
                at[i] = value
            return self._from_machine(at)
        end = end[:]
        for i, value in given:
            end[i] = value - (self.g5x[self.coord_system][i] + self.g92[i] + self.tool[i])
        return end

    def _line(self, block: Block, end: list[float], rapid: bool) -> Line:
        pos = self.pos
        context = self._context or self.context()
        turned = context.turned  # (under a rotation, the points where the control turns them)
        line = Line(
            turned((pos[0], pos[1], pos[2])),
            turned((end[0], end[1], end[2])),
            rapid,
            self.feed,
            block,
            context,
            tuple(end[3:]) if self.uses_extra_axes else (),
            extra_start=tuple(pos[3:]) if self.uses_extra_axes else (),
        )
        self.pos = end
        return line

    def _move_end(self, block: Block, words: dict) -> list[float]:
        """`_ends` of the block's axis words in program coordinates (what G0-G3 move to)."""
        end = self._base()
        absolute = self.absolute
        for letter, (value, _) in words.items():
            i = AXIS_INDEX.get(letter)
            if i is None:
                continue
            if absolute:
                end[i] = value
            else:
                end[i] += value
            if i >= 3:
                self.uses_extra_axes = True
        if "@" in words or "^" in words:
            self._polar_end(block, end, words)
        return end

    def _polar_end(self, block: Block, end: list[float], words: dict) -> None:
        """X and Y of a move given by polar words, about the program's XY zero (find_ends):
        in G90 `@` is the radius and `^` the angle (degrees, from +X counter-clockwise), each
        the current one's when not given; in G91 `@` adds to the radius, then `^` to the angle."""
        radius, theta = words.get("@"), words.get("^")
        x, y = end[0], end[1]
        if self.absolute:
            if radius is not None and theta is None and x == 0.0 and y == 0.0:
                self._fail("Must specify angle in polar coordinate if at the origin", block, radius[1])
            x, y = _about_zero(x, y, radius, theta)
        else:
            x, y = self._polar_added(
                block,
                x,
                y,
                radius,
                theta,
                "G91 motion with polar coordinates is indeterminate when at the origin",
            )
        end[0], end[1] = x, y

    def _polar_added(
        self, block: Block, x: float, y: float, radius, theta, at_origin: str
    ) -> tuple[float, float]:
        """(x, y) with the word `radius` added to their radius about XY zero, then the word
        `theta` (degrees) to their angle (None: not added), as rs274ngc adds them; refused at
        XY zero, where the angle is not defined (`at_origin`: the angle's message)."""
        if radius is not None:
            if x == 0.0 and y == 0.0:
                self._fail(
                    "Incremental motion with polar coordinates is indeterminate when at the origin",
                    block,
                    radius[1],
                )
            r, a = math.hypot(y, x) + radius[0], math.atan2(y, x)
            x, y = r * math.cos(a), r * math.sin(a)
        if theta is not None:
            if x == 0.0 and y == 0.0:
                self._fail(at_origin, block, theta[1])
            r, a = math.hypot(y, x), math.atan2(y, x) + math.radians(theta[0])
            x, y = r * math.cos(a), r * math.sin(a)
        return x, y

    def _check_rigid_tap(self, block: Block, words: dict, item) -> None:
        """rs274ngc's checks of a G33.1 block: its K (the pitch) given, no F (the spindle sets the feed)."""
        if "K" not in words:
            self._fail("K word missing with g33/g33.1", block, item)
        if "F" in words:
            self._fail("F word used with a g33/g33.1", block, words["F"][1])

    def _rigid_tap(self, block: Block, words: dict, item) -> tuple[Line, Line]:
        """G33.1: a tap to the block's point, synchronised with the spindle, and the control's own
        return to where it started, where the position is after the block (LinuxCNC G-code
        manual, G33.1: "an unsynchronized move back to the original coordinate"; rs274ngc prints
        one RIGID_TAP call and goes on from the start).  A tap that turns a rotary axis (rs274ngc
        drops its A B C), or under cutter compensation (rs274ngc offsets no tap), is out of scope."""
        if self.spindle == 0:
            self._fail("Spindle not turning in G33.1", block, item)
        turning = next((words[a][1] for a in ("A", "B", "C", "U", "V", "W") if a in words), None)
        if turning is not None:
            raise _OutOfScope("a rigid tap G33.1 with a rotary or parallel axis word", turning.start + 1)
        if self.cutter_comp is not None:
            raise _OutOfScope("a rigid tap G33.1 under cutter compensation", item.start + 1)
        start = list(self.pos)
        tap = self._line(block, self._move_end(block, words), False)
        back = self._line(block, start, False)
        tap.tap, back.tap = TAP_IN, TAP_OUT
        return tap, back

    def _straight(self, block: Block, words: dict, motion: float, machine: bool | None) -> Line:
        if motion == 1.0:
            self._check_feed(
                block, words, "Cannot do g1 with zero feed rate", "F word missing with inverse time g1 move"
            )
        if not machine:
            return self._line(block, self._move_end(block, words), motion == 0.0)
        given = [(AXIS_INDEX[letter], value) for letter, (value, _) in words.items() if letter in AXIS_INDEX]
        self._note_axes(given)
        return self._line(block, self._ends(given, True), motion == 0.0)

    def _cycle(
        self, block: Block, words: dict, motion: float, previous: float | None, item
    ) -> tuple[Event, ...]:
        """A canned cycle's moves (rs274ngc's convert_cycle and convert_cycle_xy, in any plane):
        `Line`s marked `fixed`: HOLE, one hole that apply_error_map compensates as a whole (its
        position in the plane, its R and bottom along the normal), or CYCLE, left as programmed;
        with --expand-cycles moves like any other (`_expanded`)."""
        if self._rotation() is not None:
            raise _OutOfScope(f"canned cycle G{motion:g} under a coordinate system rotation", item.start + 1)
        if self.mirror:  # (whether the control mirrors a cycle's shift, G76's and G87's, is not said)
            raise _OutOfScope(f"canned cycle G{motion:g} under a mirror image", item.start + 1)
        if motion == 87.0 and not self.back_bore_holes:
            return self._fanuc_back_bore(block, words, previous, item)
        first, second, normal = PLANE_AXES[self.plane]
        again = previous == motion  # the same cycle again: R, the normal-axis word, P and Q are sticky
        if previous not in self.canned:  # a new series: G98 retracts to where it started, no dwell yet
            self.cycle_il, self.cycle_p, self.cycle_p_word = self.pos[normal], 0.0, None
        aa, bb, step_a, step_b, r, bottom = self._cycle_geometry(block, words, again, item)
        repeats = self._repeats(block, words, motion)
        peck = self._cycle_word(block, words, motion, again, item)
        if repeats == 0:
            return self._stored_cycle(block, words, motion, previous, item)
        if motion in (74.0, 84.0) and self.plane != 17 and not self.taps_in_any_plane:
            raise _OutOfScope(f"canned cycle G{motion:g} outside the XY plane", item.start + 1)
        if motion in SPINDLE:
            self._check_spindle(block, motion, item)
        if self.expand_cycles and motion in UNEXPANDED:
            self._fail(
                f"--expand-cycles: G{motion:g} cannot be written as G0/G1 moves ({UNEXPANDED[motion]}); "
                "leave the option out, the cycle is then compensated or left as programmed", block, item,
            )  # fmt: skip
        if self.expand_cycles and "P" in words and not self._dwells_on_p(motion):
            self._fail(
                f"--expand-cycles: the P of G{motion:g}, a dwell its format has not, cannot be written as a G4 "
                "(whether the control dwells on it is not known); leave the option out, the cycle is then "
                "compensated with its P as written", block, words["P"][1],
            )  # fmt: skip
        self._check_cycle_size(block, words, repeats, (r - bottom) / peck if motion in PECKING else 0.0, item)
        if motion == 87.0:
            off_a, off_b, top = self._back_bore_words(block, words, again, item)
            middle = top if self.absolute else bottom + top
        pos = self.pos
        moves, level, clear = approach(
            (pos[first], pos[second], pos[normal]), self.cycle_il, r, self.retract_to_r
        )
        rapid_delta = RAPID_DELTA_INCH if self.inch else RAPID_DELTA_INCH * MM_PER_INCH
        polar = not self.absolute and ("@" in words or "^" in words)
        bottoms = []  # the moves at a hole's bottom (a dwell follows them: `expanded`)
        holes: list[tuple[int, float, float]] = []  # (its first move, aa, bb) of each repeat's hole
        for _ in range(repeats):
            aa, bb = aa + step_a, bb + step_b
            if polar:
                aa, bb = self._polar_step(block, words, aa, bb)
            holes.append((len(moves) if holes else 0, aa, bb))
            moves.append((aa, bb, level, True))
            if level != r:
                moves.append((aa, bb, r, True))
            if motion == 87.0:
                moves += back_bore(aa, bb, aa + off_a, bb + off_b, r, clear, middle, bottom)
            else:
                moves += hole(motion, aa, bb, r, clear, bottom, peck, rapid_delta)
                bottoms.append(len(moves) - 2)  # (the bottom, then out of the hole: `hole`)
            level = clear
        lines = tuple(self._fixed_line(block, (first, second, normal), move) for move in moves)
        if self.expand_cycles:
            self.cycle_holes = False
            dwells = motion in DWELLING or (self._dwells_on_p(motion) and self.cycle_p > 0.0)
            dwell = self._dwell_word(block, words.get("P", (0, item))[1]) if dwells else None
            return self._expanded(block, motion, lines, bottoms, dwell)
        # holes apply_error_map compensates: in any plane (polar words written as X Y, repeats as a
        # block each), the series' holes all such
        self.cycle_holes = (previous not in self.canned or self.cycle_holes) and (
            motion != 87.0 or self.back_bore_holes
        )
        series_start, self.series_stored = previous not in self.canned or self.series_stored, False
        if self.cycle_holes:
            ends = [k for k, _, _ in holes[1:]] + [len(lines)]
            offset, top_level = ((off_a, off_b), middle) if motion == 87.0 else ((0.0, 0.0), None)
            for n, ((k, hole_a, hole_b), end) in enumerate(zip(holes, ends)):
                drilled = Hole(motion, hole_a, hole_b, bottom, r, peck, rapid_delta, self.retract_to_r,
                               series_start and n == 0, n, len(holes),
                               plane=self.plane, offset=offset, top=top_level)  # fmt: skip
                for line in lines[k:end]:
                    line.fixed, line.hole = HOLE, drilled
        return lines

    def _stored_cycle(
        self, block: Block, words: dict, motion: float, previous: float | None, item
    ) -> tuple[Line]:
        """A cycle block of 0 repeats (`stores_cycle`): its R, depth, P and Q are kept for the holes the
        next blocks give, and nothing moves (cncci.com, "Two applications for L0": "sets up the canned
        cycle but does not drill a hole", the holes in a subprogram called after it).  Where the block
        also gives a hole position, or its cycle is written out as moves, it is out of scope."""
        first, second, _ = PLANE_AXES[self.plane]
        placed = next((words[k] for k in (AXES[first], AXES[second], "@", "^") if k in words), None)
        if placed is not None:
            raise _OutOfScope(
                f"canned cycle G{motion:g} of 0 repeats with a hole position", placed[1].start + 1
            )
        if self.expand_cycles:
            raise _OutOfScope(f"--expand-cycles: canned cycle G{motion:g} of 0 repeats", item.start + 1)
        self.cycle_holes = (previous not in self.canned or self.cycle_holes) and motion != 87.0
        self.series_stored = self.series_stored or previous not in self.canned
        # a cycle move of no length where the tool stands: where the holes after it are left as programmed
        # and a compensated move stands before it, their step to the programmed point (`apply_error_map.
        # _lead_in`) comes before this block, in the mode before it, not as a G0 amid the cycle's mode
        stay = self._line(block, self._base(), True)
        stay.fixed = CYCLE
        return (stay,)

    def _fanuc_back_bore(self, block: Block, words: dict, previous: float | None, item) -> tuple[Event, ...]:
        """Fanuc's back boring G87, compensated hole by hole as the other cycles (HOLE: `cycles.fanuc_back_bore`):
        to X Y, shifted by I J with the spindle oriented, down to R below the part, back over the hole, feed
        up to Z, shifted again, up to the level the series started at and back over the hole (Fanuc Series
        15i-MA operator's manual, "Back boring cycle (G87)": R the level below the part the cut starts from,
        Z its top, G99 not used; "Shift specification by I_J_"; G91: R from the initial level, Z from R).
        In the XY plane with the shift in I J (one not given is 0); its shift in Q or neither I nor J (the
        shift's direction a parameter of the control's), another plane (where I J K name the shift
        otherwise) or G99 are out of scope."""
        if not self.fanuc_back_bore:
            raise _OutOfScope("G87 on Haas (no Haas manual page in ncpp's reference set reads it as Fanuc's)",
                              item.start + 1)  # fmt: skip
        if "Q" in words:
            raise _OutOfScope("back boring G87 with its shift in Q", words["Q"][1].start + 1)
        if self.plane != 17:
            raise _OutOfScope("Fanuc's back boring G87 outside the XY plane", item.start + 1)
        if self.retract_to_r:
            raise _OutOfScope("Fanuc's back boring G87 in G99", item.start + 1)
        again = previous == 87.0
        if previous not in self.canned:
            self.cycle_il = self.pos[2]
        for letter in "RZ" if not again else ():
            if letter not in words:
                self._fail(f"{letter} word missing with G87", block, item)
        if not again and "I" not in words and "J" not in words:  # (its shift in Q, a parameter's direction)
            raise _OutOfScope("Fanuc's back boring G87 without I or J", item.start + 1)
        if not again and previous in self.canned and not ("I" in words and "J" in words):
            # (I J are modal in the cycle: the one not given may be another cycle's shift)
            raise _OutOfScope(
                "Fanuc's back boring G87 after another cycle without both I and J", item.start + 1
            )
        if self.feed == 0.0:
            self._fail("Cannot feed with zero feed rate", block, item)
        self._check_spindle(block, 87.0, item)
        if self.expand_cycles:
            self._fail(f"--expand-cycles: G87 cannot be written as G0/G1 moves ({UNEXPANDED[87.0]}); leave the "
                       "option out, the cycle is then compensated", block, item)  # fmt: skip
        r_word, z_word = (
            words[k][0] if k in words else kept for k, kept in (("R", self.cycle_r), ("Z", self.cycle_cc))
        )
        kept = self.cycle_ijk if again else (0.0, 0.0, 0.0)  # (a new series: an I or J not given is 0)
        shift = (words["I"][0] if "I" in words else kept[0], words["J"][0] if "J" in words else kept[1])
        self.cycle_r, self.cycle_cc, self.cycle_ijk = r_word, z_word, (shift[0], shift[1], 0.0)
        start = self.pos
        x, y = (words[k][0] if k in words else start[n] for n, k in enumerate("XY"))
        r, top = (
            (r_word, z_word) if self.absolute else (self.cycle_il + r_word, self.cycle_il + r_word + z_word)
        )
        step = (0.0, 0.0) if self.absolute else (words.get("X", (0.0,))[0], words.get("Y", (0.0,))[0])
        if not self.absolute:
            x, y = start[0], start[1]
        if r >= top:  # (not a back bore: the cut would go down)
            raise _OutOfScope("Fanuc's back boring G87 with R not below Z", item.start + 1)
        repeats = self._repeats(block, words, 87.0)
        if repeats == 0:
            raise _OutOfScope("Fanuc's back boring G87 of 0 repeats", item.start + 1)
        self._check_cycle_size(block, words, repeats, 0.0, item)
        self.cycle_holes = previous not in self.canned or self.cycle_holes
        lines: list[Line] = []
        for n in range(repeats):
            x, y = x + step[0], y + step[1]
            drilled = Hole(87.0, x, y, r, r, 0.0, 0.0, False, previous not in self.canned and n == 0, n, repeats,
                           offset=shift, top=top, fanuc_back=True)  # fmt: skip
            for move in fanuc_back_bore(
                (self.pos[0], self.pos[1], self.pos[2]), x, y, shift[0], shift[1], r, top, self.cycle_il
            ):
                line = self._fixed_line(block, (0, 1, 2), move)
                if self.cycle_holes:
                    line.fixed, line.hole = HOLE, drilled
                lines.append(line)
        return tuple(lines)

    def _cycle_geometry(self, block: Block, words: dict, again: bool, item) -> tuple[float, ...]:
        """(aa, bb, their step per repeat, R, bottom) of a cycle in plane coordinates; keeps the
        sticky R and normal-axis words.  X Y or polar `@` `^` (G91: increments, `_polar_step`),
        R (G91: from the series' start level) and the normal axis (G91: from R), as rs274ngc
        reads them."""
        first, second, normal = PLANE_AXES[self.plane]
        a_letter, b_letter, c_letter = "XYZ"[first], "XYZ"[second], "XYZ"[normal]
        plane = _PLANE_NAMES[
            self.plane
        ]  # (rs274ngc's messages: `Z value unspecified in xy plane`, `R less than z`)
        if self.feed == 0.0:
            self._fail("Cannot feed with zero feed rate", block, item)
        if self.inverse_time:
            self._fail("Cannot use inverse time feed with canned cycles", block, item)
        if "R" not in words and not again:
            self._fail("R clearance plane unspecified in cycle", block, item)
        if c_letter not in words and not again:
            self._fail(f"{c_letter} value unspecified in {plane} plane canned cycle", block, item)
        r_word = words["R"][0] if "R" in words else self.cycle_r
        c_word = words[c_letter][0] if c_letter in words else self.cycle_cc
        self.cycle_r, self.cycle_cc = r_word, c_word
        pos = self.pos
        if self.absolute:
            aa = words[a_letter][0] if a_letter in words else pos[first]
            bb = words[b_letter][0] if b_letter in words else pos[second]
            if "@" in words or "^" in words:  # (G17 only: `_check_polar`) the hole about XY zero
                aa, bb = _about_zero(aa, bb, words.get("@"), words.get("^"))
            step_a = step_b = 0.0
            r, bottom = r_word, c_word
        else:
            aa, bb = pos[first], pos[second]
            step_a = words[a_letter][0] if a_letter in words else 0.0
            step_b = words[b_letter][0] if b_letter in words else 0.0
            r = r_word + self.cycle_il
            bottom = r + c_word
        if r < bottom:
            self._fail(
                f"R less than {c_letter.lower()} in cycle in {plane} plane",
                block,
                words.get("R", (0, item))[1],
            )
        return aa, bb, step_a, step_b, r, bottom

    def _polar_step(self, block: Block, words: dict, x: float, y: float) -> tuple[float, float]:
        """The next hole of a G91 cycle with polar words (CYCLE_MACRO): as a G91 move's, but a
        zero word adds nothing, and one message at XY zero."""
        radius, theta = ((words[k] if words.get(k, (0.0,))[0] else None) for k in "@^")
        return self._polar_added(
            block,
            x,
            y,
            radius,
            theta,
            "Incremental motion with polar coordinates is indeterminate when at the origin",
        )

    def _expanded(
        self, block: Block, motion: float, lines: tuple[Line, ...], bottoms: list[int], dwell: str | None
    ) -> tuple[Event, ...]:
        """A cycle's moves to be written as G0/G1 blocks (--expand-cycles): moves like any other,
        after a `Pass` that tells the writer, with a dwell after each bottom of G82 G89 (Haas: after
        the last peck of G73 G83 with a P) (`dwell`: its G4's P word)."""
        events: list[Event] = [Pass(block, cycle=motion)]
        self.cycle_written_out = True
        dwells = set(bottoms) if dwell is not None else set()  # (P0 too: rs274 dwells 0 s)
        for k, line in enumerate(lines):
            line.fixed = ""
            events.append(line)
            if k in dwells:
                events.append(Pass(block, dwell=self.cycle_p, dwell_word=dwell))
        return tuple(events)

    def _dwells_on_p(self, motion: float) -> bool:
        """Whether the cycle dwells for its P at the bottom of the hole (G82 G86 G89; Haas: G73 G83)."""
        return motion in DWELLING or self.peck_dwell and motion in PECKING

    def _dwell_word(self, block: Block, item) -> str:
        """The P word of the G4 that dwells as long as the cycle's P (--expand-cycles): rs274ngc reads
        both in seconds (LinuxCNC G-code manual, "G4 Dwell" and "G82"), so the P's value, written as
        the program gave it where it is a number (grbl's flavour reads cycles as LinuxCNC, and its G4 P
        in seconds too: `motion_control.c`, `mc_dwell`).  `item`: where a refusal points (flavours
        refuse what they cannot tell)."""
        word = self.cycle_p_word
        return "P" + (word.number if type(word) is Word else number("P", self.cycle_p))

    def _fixed_line(
        self, block: Block, axes: tuple[int, int, int], move: tuple[float, float, float, bool]
    ) -> Line:
        """A cycle's move (plane coordinates) as a `Line` from the current position, marked `fixed`."""
        a, b, c, rapid = move
        end = self._base()
        end[axes[0]], end[axes[1]], end[axes[2]] = a, b, c
        line = self._line(block, end, rapid)
        line.fixed = CYCLE
        return line

    def _check_spindle(self, block: Block, motion: float, item) -> None:
        """Tapping wants the spindle turning its way (G84 M3, G74 M4), boring turning at all."""
        wanted, name = SPINDLE[motion], f"G{motion:g}"
        if self.spindle == 0:
            self._fail(f"Spindle not turning in {name}", block, item)
        if wanted and self.spindle != wanted:
            self._fail(
                f"Spindle turning {'counterclockwise' if wanted > 0 else 'clockwise'} in {name}", block, item
            )

    def _back_bore_words(self, block: Block, words: dict, again: bool, item) -> tuple[float, float, float]:
        """G87's offsets along the plane's first and second axis and the top of the bore along its
        normal, sticky within the cycle: each the word of its axis's letter (I for X, J for Y, K
        for Z: G17 I J K, G18 K I J, G19 J K I), as rs274ngc's convert_cycle_zx and _yz pass them."""
        values = []
        for letter, kept in zip("IJK", self.cycle_ijk):
            if letter not in words and not again:
                self._fail(f"{letter} word missing with G87", block, item)
            values.append(words[letter][0] if letter in words else kept)
        self.cycle_ijk = (values[0], values[1], values[2])
        first, second, normal = PLANE_AXES[self.plane]
        return values[first], values[second], values[normal]

    def _check_cycle_size(self, block: Block, words: dict, repeats: int, pecks: float, item) -> None:
        """Refuse a cycle block of more than MAX_CYCLE_MOVES moves before making them (`G81 ... L99999999`,
        `G83 ... Q0.0000001`: rs274ngc would drill for days; the moves of one block are held at once)."""
        pecks = max(pecks, 0.0)
        if (
            not repeats * (3 * pecks + 10) <= MAX_CYCLE_MOVES
        ):  # per hole: 3 moves a peck (G83), 10 more at most (G87)
            what = f"{repeats:,} hole(s)" + (f" of {pecks:,.0f} pecks each" if pecks >= 1 else "")
            self._fail(f"a canned cycle of {what}: ncpp takes {MAX_CYCLE_MOVES:,} moves in one block at most",
                       block, words.get("L", words.get("Q", (0, item)))[1])  # fmt: skip

    def _repeats(self, block: Block, words: dict, motion: float) -> int:
        """A cycle's L (Fanuc: or K, `repeat_letters`; not G87's K, the top of its cut there): how many
        times it runs (1 without)."""
        given = [letter for letter in self.repeat_letters
                 if letter in words and (letter != "K" or motion != 87.0 or not self.back_bore_holes)]  # fmt: skip
        if not given:
            return 1
        if len(given) > 1:
            raise _OutOfScope("a canned cycle with both K and L repeats", words[given[1]][1].start + 1)
        value, item = words[given[0]]
        if value != round(value):
            self._fail("Non integer value for integer", block, item)
        if value < 0:
            self._fail("Negative L word used", block, item)
        if value == 0 and not self.stores_cycle:
            self._fail("Cannot do zero repeats of cycle", block, item)
        return int(value)

    def _cycle_word(self, block: Block, words: dict, motion: float, again: bool, item) -> float:
        """The cycle's peck depth (G73 G83: Q, sticky); checks a dwelling cycle's P (sticky too)."""
        code = f"G{motion:g}"
        if motion in DWELLING and "P" not in words and not again:
            self._fail(f"Dwell time P word missing with {code}", block, item)
        if "P" in words:
            self.cycle_p, self.cycle_p_word = words["P"]
        if motion not in PECKING:
            return 0.0
        if "Q" not in words and not again:
            self._fail(f"Q word missing with {code}", block, item)
        peck = words["Q"][0] if "Q" in words else self.cycle_q
        if peck <= 0.0:
            self._fail("Negative or zero Q value used", block, words.get("Q", (0, item))[1])
        self.cycle_q = peck
        return peck

    def _check_feed(self, block: Block, words: dict, zero: str, missing: str) -> None:
        # A feed never set is not refused, unlike rs274ngc: program fragments often leave the feed
        # to the control (a default feed, or one set before the program runs).  One an F word set to 0
        # is (`zero`): the control stops there, rs274ngc as grbl (error 22, "Feed rate has not yet been
        # set or is undefined") and Fanuc (alarm PS0011 "FEED ZERO (COMMAND)", Fanuc Series 30i
        # specification A-91417, "Improvement of the feedrate command when G93/G94/G95 is changed").
        if self.inverse_time and "F" not in words:
            self._fail(missing, block, block.items[0])
        if self._zero_feed() and not self.inverse_time:
            self._fail(zero, block, words["F"][1] if "F" in words else block.items[0])

    def _arc(self, block: Block, words: dict, motion: float, motion_item, mode1_item) -> Arc | Pass:
        word = motion_item if motion_item is not None else next(item for _, item in words.values())
        plane = self.plane
        if plane != self._rotation_plane() and self._rotation() is not None:  # (turned off its plane)
            raise _OutOfScope(f"an arc in G{plane} under a coordinate system rotation", word.start + 1)
        first_letter, second_letter, normal_letter = _ARC_LETTERS[plane]
        radius = words.get("R")
        has_ijk = "I" in words or "J" in words or "K" in words
        if radius is None and not has_ijk:
            self._fail("R i j k words all missing for arc", block, word)
        if radius is not None and has_ijk:
            if not self.r_over_ijk:
                self._fail("Mixed radius ijk format for arc", block, word)
            words = {k: v for k, v in words.items() if k not in "IJK"}  # (R wins: the others are ignored)
        self._check_feed(
            block, words, "Cannot make arc with zero feed rate", "F word missing with inverse time arc move"
        )
        if normal_letter in words and not (self.arc_normal_offset_ignored and radius is None):
            self._fail(
                f"{normal_letter} word given for arc in {_PLANE_NAMES[plane]} plane",
                block,
                words[normal_letter][1],
            )
        end = self._move_end(block, words)
        a, b, c = PLANE_AXES[plane]
        start = self.pos
        if radius is not None and self.still_r_arc and list(end) == list(start) and self.cutter_comp is None:
            return Pass(block)  # (the block passes as it is: the modal G2/G3 and F it sets are kept)
        turns = round(words["P"][0]) if "P" in words else 1
        comp_radius = self.comp_radius  # (None: not known)
        if self.cutter_comp is not None and comp_radius and not self.centre.off_path:
            # (rs274ngc's convert_arc_comp1 checks the entry arc's chord before it finds the centre)
            if math.hypot(end[a] - start[a], end[b] - start[b]) <= comp_radius:
                self._fail(ENTRY_ARC_TOO_SHORT, block, block.items[0])
        if radius is not None:
            ca, cb = self._center_r(block, word, start[a], start[b], end[a], end[b], radius[0], motion)
        else:
            ia = words.get(first_letter)
            ib = words.get(second_letter)
            if self.arc_absolute:
                ca = start[a] if ia is None else ia[0]
                cb = start[b] if ib is None else ib[0]
            else:
                ca = start[a] + (0.0 if ia is None else ia[0])  # + 0.0 as before: -0.0 becomes 0.0
                cb = start[b] + (0.0 if ib is None else ib[0])
            self._check_radii(block, word, start[a], start[b], end[a], end[b], ca, cb)
        center = [0.0, 0.0, 0.0]
        center[a], center[b], center[c] = ca, cb, start[c]
        self.pos = end
        context = self._context or self.context()
        turned = context.turned  # (under a rotation, in G17: the points turned, an arc still)
        clockwise = (motion == 2.0) != context.reverses  # (mirrored in one axis: the other way round)
        return Arc(
            turned((start[0], start[1], start[2])),
            turned((end[0], end[1], end[2])),
            turned((center[0], center[1], center[2])),
            -turns if clockwise else turns,
            self.feed,
            block,
            context,
            (end[3], end[4], end[5], end[6], end[7], end[8]) if self.uses_extra_axes else (),
            extra_start=(start[3], start[4], start[5], start[6], start[7], start[8])
            if self.uses_extra_axes
            else (),
        )

    def _center_r(self, block, word, x0, y0, x1, y1, radius, motion) -> tuple[float, float]:
        """arc_data_r of rs274ngc: the centre of an R-format arc (negative R: the long way)."""
        if x1 == x0 and y1 == y0:
            self._fail("Current point same as end point of arc", block, word)
        r = abs(radius)
        mx, my = (x0 + x1) / 2, (y0 + y1) / 2
        half = math.hypot(mx - x1, my - y1)
        if half - r > RADIUS_TOLERANCE[self.inch]:
            self._fail("Arc radius too small to reach end point", block, word)
        if half / r > 1 - TINY:
            half = r  # a semicircle within tolerance
        direction = math.atan2(y1 - y0, x1 - x0)
        clockwise_short = (motion == 2.0) == (radius > 0)
        theta = direction - math.pi / 2 if clockwise_short else direction + math.pi / 2
        offset = r * math.cos(math.asin(half / r))
        return mx + offset * math.cos(theta), my + offset * math.sin(theta)

    def _check_radii(self, block, word, x0, y0, x1, y1, cx, cy) -> None:
        """arc_data_ijk of rs274ngc: start and end radius must agree (README.arc-radius-tolerance); a radius
        below convert_arc2's radius tolerance (0.00005 in, 0.00127 mm) is zero."""
        r1 = math.hypot(cx - x0, cy - y0)
        r2 = math.hypot(cx - x1, cy - y1)
        zero = RADIUS_TOLERANCE[self.inch]
        if r1 < zero or r2 < zero:
            self._fail("Zero-radius arc", block, word)
        abs_err = abs(r1 - r2)
        rel_err = abs_err / max(r1, r2)
        limit = CENTER_ARC_ABS[self.inch]
        if abs_err > 100 * limit or (abs_err > limit and rel_err > CENTER_ARC_REL):
            p, q = tuple(_PLANE_LETTERS[self.plane])  # (a message's letters)
            self._fail(
                "Radius to end of arc differs from radius to start: "
                f"start=({p}{x0:.4f},{q}{y0:.4f}) center=({p}{cx:.4f},{q}{cy:.4f}) end=({p}{x1:.4f},{q}{y1:.4f}) "
                f"r1={r1:.4f} r2={r2:.4f} abs_err={abs_err:.4g} rel_err={rel_err * 100:.4f}%",
                block,
                word,
            )

    # -- parameters -------------------------------------------------------------------------
    def _evaluate(self, expr: tuple, block: Block, item) -> float:
        try:
            return evaluate(expr, self.params)
        except ExpressionError as err:
            self._fail(str(err), block, item)
        except OutOfScope as err:
            raise _OutOfScope(str(err), item.start + 1) from None
        raise AssertionError("unreachable")

    def _assigned(self, key: int | str, expr: tuple, block: Block, item) -> float | str | None:
        """The value an assignment gives `key`: None for a vacant one, or, where the value is one ncpp
        cannot know (a system variable's), why, for `Parameters.set_unknown`: only a later read of
        `key` is then out of scope."""
        try:
            return None if vacant(expr, self.params) else evaluate(expr, self.params)
        except ExpressionError as err:
            self._fail(str(err), block, item)
        except OutOfScope as err:
            name = f"#{key}" if type(key) is int else f"#<{key}>"
            return f"{name}, which line {block.line} set from {err}"

    def _param_key(self, target: tuple, block: Block, item) -> int | str:
        try:
            return self.params.key(target[1], lambda e: evaluate(e, self.params))
        except ExpressionError as err:
            self._fail(str(err), block, item)
        except OutOfScope as err:
            raise _OutOfScope(str(err), item.start + 1) from None
        raise AssertionError("unreachable")

    def _system_parameter(self, name: str) -> float | None:
        """LinuxCNC's predefined read-only named parameters that follow from the modal state."""
        if len(name) == 2 and name[1] in "xyzabcuvw":
            return self.pos[AXIS_INDEX[name[1].upper()]]
        value = {
            "_metric": float(not self.inch),
            "_imperial": float(self.inch),
            "_absolute": float(self.absolute),
            "_incremental": float(not self.absolute),
            "_inverse_time": float(self.inverse_time),
            "_units_per_minute": float(not self.inverse_time),
            "_feed": self.feed,
            "_plane": self.plane * 10.0,
            "_motion_mode": 800.0 if self.motion is None else self.motion * 10,
            "_coord_system": _COORD_SYSTEM_CODE.get(self.coord_system),
            "_ccomp": 400.0 if self.cutter_comp is None else self.cutter_comp * 10,
        }.get(name)
        return value

    def _no_axes(self, block: Block, mode0: float) -> NoReturn:
        """G52 or G92 without axis words: refused, as rs274ngc does; where a G92 with S is a spindle
        speed clamp (`g92_speed_clamp`), the refusal says what it is."""
        words = [item for item in block.items if type(item) is Word or type(item) is ExprWord]
        if mode0 == 92.0 and self.g92_speed_clamp and any(w.letter == "S" for w in words):
            g92 = next(
                (w for w in words if type(w) is Word and w.letter == "G" and w.value == 92.0), words[0]
            )
            self._fail(G92_SPEED_CLAMP, block, g92)
        self._fail("All axes missing with g52 or g92", block, block.items[0])

    def _fail(self, message: str, block: Block, item) -> NoReturn:
        col = item.start + 1 if item is not None else None
        raise NcppError(message, Location(self.file, block.line, col))


# The warning at the first move before the program names any of G0-G3 (`Interpreter._held_move`)
HELD_MOVES = ("axis words before the program names G00, G01, G02 or G03: the control moves them in the motion "
              "mode it holds at the start (Fanuc: G00, or G01 with parameter 3402#0; Haas: G00), which this "
              "program leaves to it; these moves pass through as programmed, to their programmed points, "
              "up to the first G00-G03; LinuxCNC refuses them")  # fmt: skip
# The interpreter's attributes that are no state a loop's check compares (`_loop_state`): kept
# elsewhere (the parameters, the flow), only written or warned from, fixed for the run, or derived
# from the others (the context, the fast path)
_NOT_LOOP_STATE = frozenset(("params", "flow", "warnings", "untold_lengths", "expansion", "tools",
                             "file", "subroutine_path", "expand_cycles", "_context", "_fast",
                             "rounding", "once_runs", "main_program", "tool_reads", "checked_reads",
                             "guard_reads", "unchecked_lines", "held_told"))  # fmt: skip
# Fanuc lathes' maximum spindle speed clamp in G-code systems B and C (system A's G50 S), and Fanuc
# machining centres' under constant surface speed (their G code list: G92 "setting for workpiece
# coordinate system or clamp at maximum spindle speed"; `lathe.py`): no move, no offset
G92_SPEED_CLAMP = ("G92 with S and no axis words (a spindle speed clamp: Fanuc lathe G-code systems B "
                   "and C, or a machining centre's maximum speed under constant surface speed): ncpp "
                   "does not follow it")  # fmt: skip
_COORD_SYSTEM = {float(name[1:]): n for n, name in enumerate(SYSTEMS, 1)}  # 54.0: 1 ... 59.3: 9
_COORD_SYSTEM_CODE = {n: code * 10 for code, n in _COORD_SYSTEM.items()}
_PLANE_LETTERS = {17: "XY", 18: "ZX", 19: "YZ"}
# words a plain modal move may carry without the full checks
_AXIS_LETTERS_F = frozenset("XYZABCUVWFIJKR")
_F_ONLY = frozenset("F")
_XYZ_SLOT = {"X": (0, 1), "Y": (1, 2), "Z": (2, 4)}
_XYZF = frozenset("XYZF")
_PLAIN_LETTERS = {
    0.0: frozenset("XYZABCUVWF"),
    1.0: frozenset("XYZABCUVWF"),
    2.0: frozenset("XYZABCUVWFIJKR"),
    3.0: frozenset("XYZABCUVWFIJKR"),
    **{
        code: frozenset() for code in (*CANNED, 76.0)
    },  # a cycle's words are checked in full (Fanuc's G76 too)
    RIGID_TAP: frozenset(),  # a modal G33.1 block needs its K again (rs274ngc: "K word missing")
}


def _marked(events: Event | tuple[Event, ...] | None, marks: list[Pass]) -> Event | tuple[Event, ...]:
    """A block's events with the guards' marks (`Pass.offset_told`, `Pass.zero_told`, then
    `Pass.length_told`, which the tool guard looks for last) after them (the first event stays the
    one that says how the block is written)."""
    if events is None:
        return marks[0] if len(marks) == 1 else tuple(marks)
    return (*(events if type(events) is tuple else (events,)), *marks)


def _tape_mark(block: Block) -> bool:
    """Whether the block is a `%` line that is a tape mark: the last line the flow runs, it is the
    program's closing one, after which nothing runs, as after M2 (the NIST RS274NGC Interpreter,
    version 3, "File": "The useful contents of a file demarcated by percents stop after the second
    percent line"; LinuxCNC G-code overview, "File Requirements")."""
    return bool(block.items) and type(block.items[0]) is Statement and block.items[0].kind == "tape"


def _sets_offset(event: Event | tuple[Event, ...]) -> bool:
    """Whether the events set an offset from where the control stands (G92, G10 L10/L11/L20)."""
    events = event if type(event) is tuple else (event,)
    return any(type(ev) is Pass and ev.setting is not None for ev in events)


def _as_programmed(ev: Event, owner: Block | None) -> Event | None:
    """An event of a loop's or a subroutine's text (`Interpreter._in_flow`): a move left as
    programmed, belonging to `owner` where it runs out of the text's order; a text event kept
    in the text's place (None: not there)."""
    if type(ev) is Pass:
        ev.length_told = ev.tool_read = None  # (the text runs again, or elsewhere, perhaps with another tool)
        ev.zero_told = ev.offset_told = None  # (and perhaps after the program set the zero, or an offset)
        ev.zero_placed = None
        return ev if owner is None and not _expanding(ev) else None  # (a cycle there stays one)
    if ev.fixed in (HOLE, CYCLE):  # type: ignore[union-attr]
        # each run may need a correction of its own: the cycle is left as programmed; in a
        # body written in place it starts from where each run stands (a step to its
        # programmed start written there would run every time): a loop's move
        ev.fixed, ev.hole = (CYCLE if owner is not None else FLOW), None  # type: ignore[union-attr]
    ev.fixed = ev.fixed or FLOW  # type: ignore[union-attr]
    if owner is not None:
        ev.block = owner
    return ev


def _expanding(event: Event) -> bool:
    """Whether the event is one of those that write a canned cycle's block as its moves."""
    return type(event) is Pass and (event.cycle is not None or event.dwell is not None)


_PLACING: dict[str, tuple[int, ...] | None] = {}  # a plain block's signature -> its `_placing`


def _placing(block: Block, params: Parameters) -> tuple[int, ...] | None:
    """The X Y Z axes (0 1 2) a block's words name, or None where it stops the program (M0, M1,
    M60) or has a G code of group 0 other than G4 (or a G or M code from a variable)."""
    letters = set()
    for item in block.items:
        kind = type(item)
        if kind is not Word and kind is not ExprWord:
            continue
        word: Word | ExprWord = item  # type: ignore[assignment]  # (`kind` says so)
        letter = word.letter
        if letter == "G" or letter == "M":
            value = word.value if type(word) is Word else None
            if value is None or (
                value in (0.0, 1.0, 60.0) if letter == "M" else G_GROUP.get(value) == 0 and value != 4.0
            ):
                return None
        elif type(word) is Word or not vacant(word.expr, params):  # (a vacant one is no word)
            letters.add(letter)
    return tuple(i for i, letter in enumerate("XYZ") if letter in letters)


def _moves(event: Event | tuple[Event, ...]) -> bool:
    """Whether a block's events hold a move (a loop's block run out of order may have none)."""
    if type(event) is tuple:
        return any(type(e) is not Pass for e in event)
    return type(event) is not Pass


def _homes(block: Block) -> bool:
    """The block says G28 or G30 (its moves are not the straight move rs274ngc's rules ask for)."""
    return any(
        type(item) is Word and item.letter == "G" and item.value in (28.0, 30.0) for item in block.items
    )


def _warn_unreadable(block: Block, warnings: Warnings) -> None:
    """A line the grammar cannot read that does not run here (an uncalled subroutine, an untaken
    branch, the text after M2) passes through as it is, as LinuxCNC leaves it unread: a warning."""
    items = block.items
    if len(items) == 1 and type(items[0]) is Statement and items[0].kind == UNREADABLE:
        err = items[0].node[0]
        warnings.warn(f"{err.message}; the line does not run here and passes through as it is", err.where)


def _corner_word(words: dict, motion: float) -> tuple[str, float, Word | ExprWord] | None:
    """Fanuc corner rounding / chamfer at the end of a G1 move: `,R` `,C` or `R`."""
    for letter, kind in ((",R", "R"), (",C", "C"), ("R", "R")):
        if letter in words and (motion == 1.0 or letter != "R"):
            value, item = words[letter]
            return kind, value, item
    return None


_SIGNATURE = re.compile(r"(N?)(?:G(\d+\.?\d*|\.\d+))?([XYZABCUVWFIJKR]+)")
_XYZ_INDEX = {"X": 0, "Y": 1, "Z": 2}


_PLAIN_MOVES: dict[str | None, tuple | None] = {}  # what `_plain_move` said of the signatures seen


def _plain_move(signature: str | None) -> tuple[int, float | None, str, tuple[int, ...] | None] | None:
    """(number of words, G0-G3 code or None, letters after it, their XYZ indices when
    all are X Y Z) of a `Block.signature` like `N G01 X Y F`, when each letter is there
    once: what the interpreter's hot path reads; None for any other block."""
    move = _read_signature(signature)
    if len(_PLAIN_MOVES) < 4096:  # a program has few distinct signatures; the memory stays bounded
        _PLAIN_MOVES[signature] = move
    return move


def _read_signature(signature: str | None) -> tuple[int, float | None, str, tuple[int, ...] | None] | None:
    found = _SIGNATURE.fullmatch(signature or "")
    if found is None:
        return None
    n, number, letters = found.groups()
    code = None if number is None else float(number)
    if code not in (None, 0.0, 1.0, 2.0, 3.0) or len(set(letters)) < len(letters):
        return None
    if code is not None and not set(letters) <= _PLAIN_LETTERS[code]:
        return None
    xyz = tuple(_XYZ_INDEX[letter] for letter in letters) if set(letters) <= _XYZ_INDEX.keys() else None
    return len(n) + (number is not None) + len(letters), code, letters, xyz


def _about_zero(x: float, y: float, radius: tuple | None, theta: tuple | None) -> tuple[float, float]:
    """The point at the words `radius` and `theta` (degrees) about XY zero, G90's polar words;
    one not given (None) is that of (x, y)."""
    r = radius[0] if radius is not None else math.hypot(y, x)
    a = math.radians(theta[0]) if theta is not None else math.atan2(y, x)
    return r * math.cos(a), r * math.sin(a)


interpret = interpreting(Interpreter)  # LinuxCNC's rs274ngc reading
