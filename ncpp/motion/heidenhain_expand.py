"""`--expand` for Klartext: subprograms, program-section repeats and jumps written out as straight code.

What --expand does is ISO's (`ncpp.motion.expand`); the order the blocks run in is
`heidenhain_flow`'s, after the TNC 640 Klartext manual ("Subprograms and program section
repeats": `CALL LBL n` runs the blocks after `LBL n` up to `LBL 0`, `CALL LBL n REP k` the section
from `LBL n` to the call k more times; "If-then decisions with Q parameters": FN 9-12 jump to a
label when the comparison holds; "Calling any program as a subprogram": `CALL PGM` runs another
program's blocks from its BEGIN PGM to its END PGM).  Every block a subprogram, a repeated section,
a jump's loop or a called program runs is written where it runs, for that run (`KlartextExpansion.body`): its Q parameters in words as the numbers
they have there (`L X+Q1` -> `L X+12.5`), its Q parameter assignments (`Q1 = ...`, FN 0-8 and 13)
left out, so its moves are plain moves compensated like any other.  A cycle definition's own
parameters (`Q200=+2` in `CYCL DEF 200`) stay, as numbers, since the cycle reads them there.

The control lines, `CALL LBL`, `CALL PGM` and FN 9-12, are left out, and so is the text a jump
goes over; so are a called program's BEGIN PGM and END PGM lines and its labels (its file is not
touched: the written program no longer calls it).  A
`LBL` line stays where its text stands (a label nothing calls any more is harmless, and a call
passed through after an out-of-scope line may still need it); run again away from it (a jump
back to it), it is not written again.  The subprograms after the program's end stay as text.
The program's own lines, run once where they stand, are written as they are, and before the
first of them after a stretch written out the Q parameters the stretch changed are set to the
values they have there (`FN 0: Q1 = +12.5`, the manual's "Basic arithmetic" FN 0 ASSIGN), as a line there (or a program it calls) may read
them.  The written program's blocks are numbered afresh (the writer's `renumber`).

Refused (`ncpp.motion.expand.refused`, `counted`): an out-of-scope construct inside a stretch
written out or anywhere in a called program, a called program in other units than its caller's
(its numbers would be written in its own), a statement whose Q parameter cannot be written as a number (`TOOL
CALL Q5`, `PATTERN DEF` with Q words) inside one, and more than MAX_EXPANDED blocks written out.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ncpp.errors import Location, NcppError
from ncpp.motion.expand import counted, rewritten
from ncpp.motion.heidenhain_flow import JUMPS, KlartextFlow
from ncpp.motion.segments import Pass
from ncpp.program.blocks import AnyItem, Block, Comment, ExprWord, Statement, Word

# Decimals the TNC takes in a word (TNC 640 user's manual, "Input format and unit of TNC
# functions": positions, radii, angles, tool deltas 4 after the point, feed rates and spindle
# speeds 3), in inch programs 5 for lengths (as the writer writes them); a Q parameter's value up
# to 15 digits ("Programming notes": 15 or 16 by software version)
PLACES = 4
INCH_PLACES = 5
RATE_PLACES = 3
RATES = frozenset(("F", "S"))
LENGTHS = frozenset(("X", "Y", "Z", "IX", "IY", "IZ", "R", "PR", "IPR", "DL", "DR"))
Q_DIGITS = 15
# FN functions that set a Q parameter (TNC 640 Klartext manual, "Basic arithmetic", "Angle
# functions"): left out of a body written out, as its words read no parameter once written as numbers
ARITHMETIC_FN = frozenset((0, 1, 2, 3, 4, 5, 6, 7, 8, 13))
UNSIGNED = frozenset(("F", "S", "M"))  # letters the TNC writes without a sign (`F200`, `S800`, `M3`)
Evaluate = Callable[[tuple, Block, AnyItem], float]  # the interpreter's value of an expression


def head(block: Block) -> Statement | None:
    """The block's statement (a Klartext block has one at most that leads it; a block delete `/` before
    its number is none)."""
    return next((i for i in block.items if type(i) is Statement and i.kind != "block_delete"), None)


def is_control(block: Block) -> bool:
    """`CALL LBL`, `CALL PGM` and FN 9-12: lines that only steer the flow (left out where --expand
    writes runs)."""
    item = head(block)
    return item is not None and (
        item.kind in ("call_label", "call_program") or (item.kind == "fn" and item.node[0] in JUMPS)
    )


def is_label(block: Block) -> bool:
    item = head(block)
    return item is not None and item.kind == "label"


def number(letter: str, value: float, inch: bool = False) -> str:
    """`value` as a Klartext word writes it: signed (`X+12.5`) but F, S, M; to the decimals the TNC
    takes there (a Q parameter's, `letter` "Q", to Q_DIGITS digits); no exponent, a decimal point
    only where there are decimals."""
    if letter == "Q":
        digits = np.format_float_positional(value + 0.0, precision=Q_DIGITS, unique=True,
                                            fractional=False, trim="-")  # fmt: skip
    else:
        places = RATE_PLACES if letter in RATES else INCH_PLACES if inch and letter in LENGTHS else PLACES
        digits = np.format_float_positional(
            round(value, places) + 0.0, precision=places, unique=True, trim="-"
        )
    return digits if letter in UNSIGNED or digits.startswith("-") else "+" + digits


def parameter_name(name: str) -> str:
    """`q1` -> `Q1`, `ql3` -> `QL3`."""
    return name.upper()


class KlartextExpansion:
    """What --expand does to one run of a Klartext program (`HeidenhainInterpreter._run_flow` asks
    it at each block that runs, a called program's too)."""

    def __init__(self, q: dict[str, float], file: str):
        self.q = q  # the interpreter's Q parameters (the same dict: read where asked)
        self.file = file
        self.started = False  # something was written out or left out: the rest cannot pass as text
        self.expanded = 0  # blocks written out of subprograms, repeats and loops
        self.settled = True  # the written program's Q parameters are the program's
        self.written: dict[str, float] = {}  # the written program's Q parameters where they last were

    # -- where the rest of the program could pass through as it is ------------------------------
    def refuses_leaving(self, flow: KlartextFlow) -> bool:
        """Whether the rest of the program cannot pass through as it is from the block the flow
        runs: a subprogram, a repeated section or a jump's loop is under way whose call or jump
        line was left out."""
        here = flow.current
        return self.started and (bool(flow.frames) or any(a <= here <= b for a, b in flow.again))

    # -- text that does not run here ------------------------------------------------------------
    def text(self, skipped: bool, block: Block) -> tuple[Pass, ...] | None:
        """A line the flow does not run here: None where it is left out (text a jump goes over,
        but a label), else the assignments to write before it (after the program's end or where
        the rest passes through uninterpreted: the Q parameters its text may read)."""
        if not skipped:
            return self.settle(block)
        self._unsettle()
        return () if is_label(block) else None

    # -- blocks that run ---------------------------------------------------------------------------
    def in_place(self, block: Block) -> tuple[Pass, ...]:
        """A program line run once where it stands, written as it is: the assignments before it."""
        return self.settle(block)

    def control(self) -> None:
        """A call or jump line, run (it steers the flow) and left out."""
        self._unsettle()

    def body(self, block: Block, value: Evaluate, inch: bool) -> Block | None:
        """A block of a stretch written out, before it runs: the block as this run writes it (its
        Q parameters' values now, `inch` or mm), None where it writes nothing (assignments only, and
        their comments).  Raises NcppError where it cannot be written."""
        self._unsettle()
        self.expanded = counted(self.expanded, Location(self.file, block.line, 1))
        cycle = any(type(i) is Statement and i.kind == "cycle_def" for i in block.items)
        texts = [self._text(item, block, value, cycle, inch) for item in block.items]
        written = rewritten(block, texts)
        if None in texts and all(type(i) is Comment or (type(i) is Word and i.letter == "N")
                                 for i in written.items):  # fmt: skip
            return None
        return written

    def _text(self, item: AnyItem, block: Block, value: Evaluate, cycle: bool, inch: bool) -> str | None:
        """An item's text in the block of this run (None: left out)."""
        raw = block.raw[item.start : item.end]
        if type(item) is ExprWord:
            return item.letter + number(item.letter, value(item.expr, block, item), inch)
        if type(item) is Word or type(item) is Comment:
            return raw
        assert type(item) is Statement
        if item.kind == "assignment":
            target, expr = item.node
            if expr[0] in ("str", "feed"):  # (a QS string, a cycle's `Q208= MAX`: it stays, set in each run)
                return raw
            if not cycle:
                return None
            self.written[target[1]] = value(expr, block, item)  # (the written program sets it too)
            if not _reads_parameter(expr):
                return raw
            return f"{parameter_name(target[1])}={number('Q', self.written[target[1]])}"
        if item.kind == "fn" and item.node[0] in ARITHMETIC_FN:
            return None
        if item.kind in ("program_begin", "program_end"):  # (a called program's: its blocks are the caller's)
            return None
        if _reads_parameter(item.node):
            raise NcppError(
                "--expand: a Q parameter in this statement cannot be written as a number inside a "
                "subprogram, a repeated section or a jump's loop; leave --expand out",
                Location(self.file, block.line, item.start + 1),
            )
        return raw

    # -- the Q parameters the written program has ------------------------------------------------
    def _unsettle(self) -> None:
        """A stretch written out starts (or goes on): the written program's Q parameters are the
        program's now, before any of its blocks runs."""
        if self.settled:
            self.written = dict(self.q)
            self.settled = False
        self.started = True

    def settle(self, block: Block) -> tuple[Pass, ...]:
        """`FN 0` lines that give the written program the Q parameters the program has before
        `block` (none when nothing was written out since they were the same)."""
        if self.settled:
            return ()
        self.settled = True
        changed = sorted((name for name, v in self.q.items() if self.written.get(name) != v), key=_in_order)
        return tuple(Pass(_assignment(name, self.q[name], block)) for name in changed)


def _in_order(name: str) -> tuple[str, int]:
    """`q12` -> ("q", 12): Q parameters by kind and number."""
    digits = name.lstrip("qlrs")
    return name[: len(name) - len(digits)], int(digits) if digits.isdigit() else -1


def _reads_parameter(node: object) -> bool:
    """Whether an expression or a statement's node reads a Q parameter."""
    if type(node) is tuple:
        if len(node) == 2 and node[0] == "param":
            return True
        return any(_reads_parameter(part) for part in node)
    return False


def _assignment(name: str, value: float, block: Block) -> Block:
    """`0 FN 0: Q1 = +12.5` before `block` (numbered by the writer, at `block`'s line)."""
    body = f"{parameter_name(name)} = {number('Q', value)}"
    text = f"0 FN 0: {body}"
    items = (Word("N", 0.0, "0", 0, 1), Statement("fn", (0, body), 2, len(text)))
    return Block(text, block.eol, items, block.line)


__all__ = ["KlartextExpansion", "is_control", "is_label", "number"]
