"""`--expand` for Sinumerik: loops, jumps back and subprogram calls written out as straight code.

What --expand does is ISO's (`ncpp.motion.expand`); the order the blocks run in is
`sinumerik_flow`'s, after the 840D sl Programming Manual, Job Planning ("Flexible NC
programming": "Program jumps and branches", "Control structures": WHILE, FOR, REPEAT, LOOP,
GOTOB, GOTO, IF ... GOTOx), and subprogram calls are `SinumerikInterpreter._call`'s (Fundamentals,
"Subprogram technique": `L100`, `MYSUB(...)`, `P` runs, to M17 or RET).  Every block a loop, a
jump's loop or a subprogram runs is written where it runs, for that run (`SinumerikExpansion.body`):
its words that read R parameters or variables as the numbers they have there (`X=R1` -> `X12.5`,
`X=AC(R2)` -> `X=AC(7)`, `CR=R3` -> `CR=5`), a call's arguments too (`CYCLE81(R1, ...)` ->
`CYCLE81(10, ...)`), the rest of the block as written; its assignments are left out, so its
moves are plain moves compensated like any other.

The control lines (WHILE, ENDWHILE, FOR, ENDFOR, REPEAT, UNTIL, LOOP, ENDLOOP, IF, ELSE, ENDIF,
GOTOx, CASE), the call lines, a subprogram's PROC, M17 and RET, and the text that does not run
(a branch not taken, a loop that runs no time, the blocks a jump goes over) are left out; the
subprograms' files are not touched (the written program no longer calls them).  A label stays
where its text stands and runs first (a jump passed through may need it), not again.  The
program's own lines, run once where they stand, are written as they are, and before the first
of them after a stretch written out the R parameters and the program's variables the stretch
changed are set to the values they have there (`R1=50`): their DEF lines stay where they are, at
the program's start (Job Planning, "Definition of user variables (DEF)": definitions come
before the program's statements), before any stretch.

Refused (`ncpp.motion.expand.refused`, `counted`): an out-of-scope construct inside a stretch
written out (its opening line is left out: the rest cannot pass through as it is), a DEF in the
main program's stretch, a call whose argument cannot be written as a number (a string's
concatenation, a variable holding a string), such a call in a block with an assignment, and
more than MAX_EXPANDED blocks written out.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable

import numpy as np

from ncpp.errors import Location, NcppError
from ncpp.motion.expand import counted, refused
from ncpp.motion.segments import Pass
from ncpp.program.blocks import AnyItem, Block, Comment, ExprWord, Statement, Word
from ncpp.program.dialects.editing import splice
from ncpp.program.dialects.sinumerik import _reparse

# Decimals a number is written with: a position to 1e-6 mm (or inch), finer than any control
# moves, not the 17 digits of a double; codes and counts as whole numbers
PLACES = 6
WHOLE_LETTERS = frozenset("GMTDHLPN")
# A variable's value set after a stretch: up to 15 significant digits (a REAL's precision)
DIGITS = 15
# Statements left out of a block written out: assignments (its words carry their values), a
# subprogram's opening and return, its name line
LEFT_OUT = frozenset(("assignment", "proc", "program_name"))
Evaluate = Callable[[tuple, Block, AnyItem], float]  # the interpreter's value of an expression


def reads_variable(node: object) -> bool:
    """Whether an expression reads an R parameter, a variable or an array element."""
    if type(node) is tuple:
        if len(node) >= 2 and node[0] in ("param", "index"):
            return True
        return any(reads_variable(part) for part in node)
    return False


def number(value: float, letter: str = "") -> str:
    """`value` as a Sinumerik word writes it: whole for codes (`WHOLE_LETTERS`), else to PLACES
    decimals, a point only where there are decimals, no exponent."""
    if letter.upper() in WHOLE_LETTERS and value == round(value):
        return str(int(value))
    return np.format_float_positional(round(value, PLACES) + 0.0, precision=PLACES, unique=True, trim="-")


def _variable_value(value: float | str) -> str:
    if type(value) is str:
        return '"' + value + '"'
    return np.format_float_positional(float(value) + 0.0, precision=DIGITS, unique=True,
                                      fractional=False, trim="-")  # fmt: skip


def _variable_name(key: str) -> str:
    """`r1` -> `R1`, `feld[0,1]` -> `FELD[0,1]`."""
    return key.upper()


class SinumerikExpansion:
    """What --expand does to one run of a Sinumerik program (`SinumerikInterpreter._run` asks it
    at each block of the program and of the subprograms it calls)."""

    def __init__(self, variables: Callable[[], dict], file: str):
        self.variables = variables  # the main program's variables now (R parameters among them)
        self.file = file
        self.started = False  # something was written out or left out: the rest cannot pass as text
        self.label_left_out = False  # a jump passed through could no longer find its label
        self.expanded = 0  # blocks written out of loops, jumps' loops and subprograms
        self.settled = True  # the written program's variables are the program's
        self.written: dict[str, float | str] = {}  # the written program's variables where they last were
        self.seen: dict[int, float] = {}  # the values of the block's words as it ran (by item id)

    # -- where the rest of the program could pass through as it is ------------------------------
    def refuses_leaving(self, inside: bool) -> bool:
        """Whether the rest cannot pass through as it is from a block `inside` a stretch written out
        (a loop, a jump's loop, a subprogram), or after a label of the main program was left out
        where its text stands (a jump in the rest could not find it)."""
        return self.started and (inside or self.label_left_out)

    def refuse(self, reason: str, where: Location, inside: bool) -> None:
        if self.refuses_leaving(inside):
            raise refused(reason, where)

    # -- text that does not run here ------------------------------------------------------------
    def text(self, done: bool, block: Block) -> tuple[Pass, ...] | None:
        """A line the flow does not run here: None where it is left out (a control line, text that
        does not run), else the assignments to write before it (after the program's end or where
        the rest passes through uninterpreted: the variables its text may read)."""
        if done:
            return self.settle(block)
        self.left_out(block)
        return None

    def left_out(self, block: Block) -> None:
        """A line left out (a control line, a call, text that does not run)."""
        self._unsettle()
        self.label_left_out = self.label_left_out or any(_is_label(i) for i in block.items)

    # -- blocks that run ---------------------------------------------------------------------------
    def start_body(self, block: Block) -> None:
        """A block of a stretch written out is about to run: its words' values are recorded as it
        runs (`seen`)."""
        self._unsettle()
        self.expanded = counted(self.expanded, Location(self.file, block.line, 1))
        self.seen = {}

    def body(self, block: Block, value: Evaluate, main: bool, first: bool) -> Block | None:
        """A block of a stretch written out, after it ran: the block as this run writes it, None
        where it writes nothing (assignments only, and their comments).  `main`: a block of the
        main program (else a subprogram's), `first`: run where its text stands (its label stays).
        Raises NcppError where it cannot be written."""
        # (a call's arguments are read after the block ran: with an assignment beside it they may differ)
        assigns = any(type(i) is Statement and i.kind in ("assignment", "def") for i in block.items)
        texts: dict[int, str | None] = {}
        for index, item in enumerate(block.items):
            text = self._text(item, block, value, main, first, assigns)
            if text != block.raw[item.start : item.end]:
                texts[index] = text
        kept = [item for index, item in enumerate(block.items) if texts.get(index, "") is not None]
        if None in texts.values() and all(type(i) is Comment or (type(i) is Word and i.letter in "N:")
                                          for i in kept):  # fmt: skip
            return None
        if not texts:  # (a block of its own for each run: the writer and the summary tell them apart)
            return dataclasses.replace(block)
        return _reparse(Block(splice(block, texts), block.eol, (), block.line))

    def _text(self, item: AnyItem, block: Block, value: Evaluate, main: bool, first: bool,
              assigns: bool) -> str | None:  # fmt: skip
        """An item's text in the block of this run (None: left out)."""
        raw = block.raw[item.start : item.end]
        where = Location(self.file, block.line, item.start + 1)
        if type(item) is ExprWord:
            if not reads_variable(item.expr):
                return raw
            return _word(item, self._value(item, block, value))
        if type(item) is Word:
            return None if not main and item.letter == "M" and item.value == 17.0 else raw
        if type(item) is not Statement:
            return raw
        if item.kind == "assignment" and item.node[0] == ("param", "rpl") and _framed(block):
            # (`ROT RPL=30`: the frame's address, no variable; its value as the block ran)
            expr = item.node[1]
            return raw if not reads_variable(expr) else f"RPL={number(value(expr, block, item))}"
        if item.kind in LEFT_OUT or (item.kind == "call" and item.node[0] == "RET"):
            return None
        if item.kind == "label":  # (run again, its text was written where it stands, or left out there)
            return raw if main and first else None
        if item.kind == "def":
            if main:
                raise NcppError("--expand: DEF inside a loop or a jump's loop cannot be written out (a "
                                "definition stands at the program's start); leave --expand out", where)  # fmt: skip
            return None  # (a subprogram's own variables: its words carry their values)
        if item.kind == "call" and reads_variable(item.node[1]):
            if assigns:
                raise NcppError(f"--expand: {item.node[0]} with an assignment in its block cannot be "
                                "written with numbers; leave --expand out", where)  # fmt: skip
            return _call(item, block, value, where)
        return raw

    def _value(self, item: ExprWord, block: Block, value: Evaluate) -> float:
        """The word's value as the block ran (`seen`), or now."""
        seen = self.seen.get(id(item))
        if seen is not None:
            return seen
        expr = item.expr[1] if item.expr[0] in ("ac", "ic", "dc") else item.expr
        return value(expr, block, item)

    # -- the variables the written program has ----------------------------------------------------
    def _unsettle(self) -> None:
        """A stretch written out starts (or goes on): the written program's variables are the
        program's now, before any of its blocks runs."""
        if self.settled:
            self.written = dict(self.variables())
            self.settled = False
        self.started = True

    def settle(self, block: Block) -> tuple[Pass, ...]:
        """Assignments that give the written program the variables the program has before `block`
        (none when nothing was written out since they were the same)."""
        if self.settled:
            return ()
        self.settled = True
        now = self.variables()
        changed = [key for key, v in now.items() if type(v) in (float, str) and self.written.get(key) != v]
        return tuple(Pass(_assignment(key, now[key], block)) for key in sorted(changed, key=_in_order))


def _in_order(key: str) -> tuple[int, str, int]:
    """R parameters first, by number, then the variables by name."""
    digits = key[1:]
    if key[0] == "r" and digits.isdigit():
        return 0, "", int(digits)
    return 1, key, 0


def _is_label(item: AnyItem) -> bool:
    return type(item) is Statement and item.kind == "label"


def _word(item: ExprWord, value: float) -> str:
    """`X12.5`, `X=AC(7)`, `C=DC(0)`, `CR=5`: the word with its value, in the block's own form."""
    mode = item.expr[0]
    if mode in ("ac", "ic", "dc"):
        return f"{item.letter}={mode.upper()}({number(value)})"
    if len(item.letter) == 1:
        return item.letter + number(value, item.letter)
    return f"{item.letter}={number(value, item.letter)}"


def _call(item: Statement, block: Block, value: Evaluate, where: Location) -> str:
    """`CYCLE81(10,0,2,-5)`: a call with its arguments as numbers (a string as it is)."""
    name, args = item.node
    texts = []
    for arg in args:
        if arg is None:
            texts.append("")
        elif arg[0] == "str":
            texts.append('"' + arg[1] + '"')
        elif arg[0] == "bin" and arg[1] == "<<":
            raise NcppError(f"--expand: {name} with a string made of variables cannot be written with "
                            "numbers; leave --expand out", where)  # fmt: skip
        else:
            texts.append(number(value(arg, block, item)))
    return f"{name}({','.join(texts)})"


def _framed(block: Block) -> bool:
    """Whether the block is a frame instruction's (`ROT`, `AROT` ...), whose `RPL=` is its address."""
    return any(type(i) is Statement and i.kind == "frame" for i in block.items)


def _assignment(key: str, value: float | str, block: Block) -> Block:
    """`R1=12.5` before `block` (at its line)."""
    return _reparse(Block(f"{_variable_name(key)}={_variable_value(value)}", block.eol, (), block.line))


__all__ = ["SinumerikExpansion", "number", "reads_variable"]
