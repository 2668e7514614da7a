"""Heidenhain Klartext (TNC 530 / 640): items of a conversational block.

Blocks map onto the common item classes so that interpreters and writers
handle every dialect alike:

* the block number `15` is `Word('N', 15.0, '15')` (its span has no letter); a `/` before it,
  which hides the block (`/ 16 STOP`), is `Statement('block_delete', ('/',))`, as ISO's;
* `X+10,5` `IX-5` `PA+30` `IPA+90` `PR+50` `R+5` `F200` `S800` `M3` `DL+0.1`
  are `Word`s: the letter as written upper-cased (`IX`, `PA`, ...), the value
  a float, the number text as written (sign and decimal comma kept);
* `X+Q1932` `FQ1820` `RQ108` are `ExprWord`s with `("param", "q1932")`
  (`("neg", ...)` for `X-Q108`);
* keywords and constructs are `Statement`s (kinds below); a path function
  comes first and the words after it are its coordinates;
* `;` and `*` comments are `Comment`s with style ';' or '*'.

Statement kinds and nodes (Heidenhain):
  program_begin  (name, unit)            `BEGIN PGM Plan MM`; unit 'MM' | 'INCH' | None
  program_end    (name, unit)            `END PGM Plan MM`
  blk_form       (index, axis)           `BLK FORM 0.1 Z` ('0.1', 'Z'); words follow (min/max point)
  path           (function,)             L LP LN C CP CR CRP CT CTP CC RND FL FLT FC FCT FPOL
                                         FSELECT 'APPR LT' 'DEP LCT' ...; words follow
                 ('CHF', length)         `CHF 2` chamfer with its length
  radius_comp    ('R0' | 'RL' | 'RR',)
  feed           ('FMAX' | 'FAUTO',)     `F200` is a Word; `F MAX` is 'FMAX' too
  rotation       ('+' | '-',)            `DR+` counter-clockwise, `DR-` clockwise
  retract        (distance | 'MAX',)     M140's `MB 50` -> (50.0,), `MB MAX` -> ('MAX',)
  contour_label  (label,)                cycle 14's further subprograms: `LABEL1 /2 /3` -> (2,), (3,)
  tool_call      (tool, axis)            `TOOL CALL 1 Z S800`: tool int | float | "name" | ("param", q)
                                         | None, axis 'X' | 'Y' | 'Z' | None; S F DL DR words follow
  tool_def       (tool,)                 `TOOL DEF 5 L+0 R+5`
  label          (label,)                `LBL 1` -> 1, `LBL "name"` -> 'name' (`LBL 0` ends a subprogram)
  call_label     (label, repeat)         `CALL LBL 1 REP 2/2` -> (1, 2); repeat 0 without REP, a Q
                                         parameter tuple for `REPQ9` -> (1, ('param', 'q9'))
  call_program   (path,)                 `CALL PGM TNC:\\Plan.h`
  cycle_def      (number, words)         `CYCL DEF 200 BOHREN` -> ('200', ('BOHREN',)); its Q200=...
                                         parameters (continuation lines) follow as assignments
  cycle_call     (variant,)              `CYCL CALL` None, `CYCL CALL POS` 'POS', `CYCL CALL PAT` 'PAT'
  touch_probe    (number, words)         `TCH PROBE 412 DATUM INSIDE CIRCLE` -> ('412', ('DATUM', ...));
                                         its Q parameters follow as assignments, as a cycle_def's
  pattern_def    (shapes...)             `PATTERN DEF` with `POS1 (X+25 Y+33.5 Z+0)` on a continuation line ->
                                         (('POS', 1, (('X', ("num", 25.0)), ('Y', ...), ('Z', ...))),)
  fn             (number, text)          `FN 9: IF +Q1 EQU +0 GOTO LBL "x"` -> (9, 'IF +Q1 ...'), passed through
  assignment     (("param", "q1950"), expr)  `Q1950 = Q1804 - Q1805`; a string ("str", text) for QS;
                                         a cycle's feed `Q208= MAX` -> ("feed", "MAX") ('AUTO' for `=AUTO`)
  keyword        (words...)              anything else led by keywords (`STOP`), passed through; a PLANE
                                         function's words as written (`PLANE SPATIAL SPA+0 ... STAY`)
Expressions: ("num", v) ("param", "q12"|"ql1"|"qr1"|"qs1") ("neg", x) ("bin", op, a, b) with op in
+ - * / ** (`^`), ("call", NAME, x) for SIN COS TAN ASIN ACOS ATAN SQRT SQ LN LOG ABS INT FRAC NEG SGN.
"""

from __future__ import annotations

import functools
import math
import re

from lark import Token, Transformer, v_args

from ncpp.program.blocks import Comment, ExprWord, Statement, Word
from ncpp.program.parser import Dialect

_ADDRESS_END = "+-0123456789.,Q"


def number_value(text: str) -> float:
    """`+10,5` -> 10.5; `- 200` -> -200.0 (sign, blanks and decimal comma as written)."""
    return float(text.replace(" ", "").replace("\t", "").replace(",", "."))


def _retract_distance(text: str) -> float | str:
    """`MB 50` -> 50.0, `MB MAX` -> 'MAX'."""
    value = text[2:].strip()
    return "MAX" if value.upper() == "MAX" else number_value(value.replace(" ", "").replace("\t", ""))


def _split_address(text: str) -> tuple[str, str]:
    """`IX-5` -> ('IX', '-5'); `DR2+0` -> ('DR2', '+0'); `RQ1832` -> ('R', 'Q1832'); `RADIUS 16` ->
    ('RADIUS', '16')."""
    if text[:3].upper() == "DR2" and len(text) > 3 and text[3] in "+-":
        return "DR2", text[3:]
    end = 0
    while end < len(text) and text[end] not in _ADDRESS_END:
        end += 1
    return text[:end].upper().rstrip(" \t"), text[end:]


def _tool_ref(tok) -> object:
    if isinstance(tok, Token):
        if tok.type == "STRING":
            return str(tok)[1:-1]
        if tok.type == "QPARAM":
            return ("param", str(tok).lower())
        value = number_value(tok)
        return int(value) if value.is_integer() and "," not in tok and "." not in tok else value
    return tok


class HeidenhainBuilder(Transformer):
    """Turns a Lark tree of one Heidenhain block into items with spans."""

    def start(self, children):
        items = []
        for child in children:
            if isinstance(child, Token) and child.type == "BLOCK_DELETE":
                items.append(Statement("block_delete", (str(child),), child.start_pos, child.end_pos))
            elif isinstance(child, Token):  # the block number
                items.append(Word("N", float(child), str(child), child.start_pos, child.end_pos))
            else:
                items.append(child)
        return tuple(items)

    # -- comments ----------------------------------------------------------------
    def block_comment(self, children):
        (tok,) = children
        return Comment(str(tok)[1:], str(tok)[0], tok.start_pos, tok.end_pos)

    def comment(self, children):
        (tok,) = children
        return Comment(str(tok)[1:], ";", tok.start_pos, tok.end_pos)

    # -- words -------------------------------------------------------------------
    def word(self, children):
        (tok,) = children
        letter, number = _split_address(str(tok))
        return Word(letter, number_value(number), number, tok.start_pos, tok.end_pos)

    def qword(self, children):
        (tok,) = children
        letter, ref = _split_address(str(tok))
        expr = ("param", ref.lstrip("+-").lower())
        if ref.startswith("-"):
            expr = ("neg", expr)
        return ExprWord(letter, expr, tok.start_pos, tok.end_pos)

    # -- statements --------------------------------------------------------------
    # Helpers that build the rule methods, called in the class body: plain functions, not
    # methods, which mypy cannot tell (hence their `type: ignore[misc]`)
    def _statement(kind: str, shape):  # type: ignore[misc]
        @v_args(meta=True)
        def build(self, meta, children):
            return Statement(kind, shape(children), meta.start_pos, meta.end_pos)

        return build

    def _text(children: list, skip: int = 1) -> tuple:  # type: ignore[misc]
        return tuple(str(c) for c in children[skip:])

    def _pgm(children: list) -> tuple:  # type: ignore[misc]
        name = str(children[1])
        return (name, str(children[2]).upper() if len(children) > 2 else None)

    def _blk(children: list) -> tuple:  # type: ignore[misc]
        return (str(children[1]), str(children[2]).upper() if len(children) > 2 else None)

    def _tool_call(children: list) -> tuple:  # type: ignore[misc]
        tool, axis = None, None
        for c in children[1:]:
            if isinstance(c, Token) and c.type == "AXIS":
                axis = str(c).upper()
            else:
                tool = _tool_ref(c)
        return (tool, axis)

    def _call_label(children: list) -> tuple:  # type: ignore[misc]
        ints = [c for c in children[2:] if isinstance(c, Token) and c.type == "INT"]
        counts = [_tool_ref(c) for c in children[2:] if isinstance(c, Token) and c.type == "QPARAM"]
        return (_tool_ref(children[1]), counts[0] if counts else int(ints[0]) if ints else 0)

    def _cycle_def(children: list) -> tuple:  # type: ignore[misc]
        return (str(children[1]), tuple(str(c).strip() for c in children[2:]))

    def _cycle_call(children: list) -> tuple:  # type: ignore[misc]
        words = str(children[0]).split()
        return (words[2].upper() if len(words) > 2 else None,)

    def _pattern_def(children: list) -> tuple:  # type: ignore[misc]
        return tuple(children[1:])

    def _fn(children: list) -> tuple:  # type: ignore[misc]
        number = int("".join(ch for ch in str(children[0]) if ch.isdigit()))
        return (number, str(children[1]).strip() if len(children) > 1 else "")

    def _path(children: list) -> tuple:  # type: ignore[misc]
        return (" ".join(str(children[0]).split()).upper(),)

    program_begin = _statement("program_begin", _pgm)
    program_end = _statement("program_end", _pgm)
    blk_form = _statement("blk_form", _blk)
    path = _statement("path", _path)
    chamfer = _statement("path", lambda c: ("CHF", number_value(c[1])))
    tool_call = _statement("tool_call", _tool_call)
    tool_def = _statement("tool_def", lambda c: (_tool_ref(c[1]),))
    label = _statement("label", lambda c: (_tool_ref(c[1]),))
    call_label = _statement("call_label", _call_label)
    call_program = _statement("call_program", lambda c: (str(c[1]).strip('"'),))
    cycle_def = _statement("cycle_def", _cycle_def)
    cycle_call = _statement("cycle_call", _cycle_call)
    touch_probe = _statement("touch_probe", _cycle_def)
    pattern_def = _statement("pattern_def", _pattern_def)
    fn = _statement("fn", _fn)
    keyword = _statement("keyword", lambda c: tuple(str(t).upper() for t in c))
    plane = _statement("keyword", lambda c: tuple(str(c[0]).upper().split()))
    radius_comp = _statement("radius_comp", lambda c: (str(c[0]).upper(),))
    feed = _statement("feed", lambda c: ("".join(str(c[0]).split()).upper(),))
    rotation = _statement("rotation", lambda c: (str(c[0])[-1],))
    retract = _statement("retract", lambda c: (_retract_distance(str(c[0])),))
    contour_label = _statement("contour_label", lambda c: (int(str(c[0]).lstrip("/ \t")),))
    del (
        _statement,
        _text,
        _pgm,
        _blk,
        _tool_call,
        _call_label,
        _cycle_def,
        _cycle_call,
        _pattern_def,
        _fn,
        _path,
    )

    def pattern_shape(self, children):
        head, *words = children
        name, number = _split_address(str(head))
        shape = []
        for token in words:
            letter, value = _split_address(str(token))
            if token.type == "QWORD":
                param = ("param", value.lstrip("+-").lower())
                shape.append((letter, ("neg", param) if value.startswith("-") else param))
            else:
                shape.append((letter, ("num", number_value(value))))
        return (name, int(number_value(number)), tuple(shape))

    @v_args(meta=True)
    def assignment(self, meta, children):
        target, value = children
        if (
            isinstance(value, Token) and value.type == "FEED_VALUE"
        ):  # `Q208= MAX`: rapid, `=AUTO` the tool's feed
            value = ("feed", str(value).upper().lstrip("F"))
        elif isinstance(value, Token):  # a string for a QS parameter
            value = ("str", str(value)[1:-1])
        return Statement("assignment", (("param", str(target).lower()), value), meta.start_pos, meta.end_pos)

    # -- expressions ---------------------------------------------------------------
    def number(self, children):
        return ("num", number_value(children[0]))

    def param(self, children):
        return ("param", str(children[0]).lower())

    def pi(self, children):
        return ("num", math.pi)

    def call(self, children):
        name, arg = children
        return ("call", str(name).upper(), arg)

    def neg(self, children):
        return ("neg", children[0])

    def pos(self, children):
        return children[0]

    def _binary(self, children):
        a, op, b = children
        return ("bin", "**" if op == "^" else str(op), a, b)

    sum = product = power = _binary


# The TNC manuals give no block length: ncpp's bound is a block of many `~`-continued lines
# (a cycle definition of one Q parameter a line) with room to spare.
HEIDENHAIN = Dialect(
    "heidenhain",
    "heidenhain",
    HeidenhainBuilder,
    fast_terminals=(),
    continuation="~",
    max_line=4096,
    max_line_source="ncpp's bound for Klartext, whose manuals state none",
)


# ---- writer ------------------------------------------------------------------------------

from collections.abc import Iterable, Iterator  # noqa: E402
from dataclasses import replace  # noqa: E402

from ncpp.motion.segments import DRILLED, FLOW, PLANE_AXES, Arc, Event, Line, Pass  # noqa: E402
from ncpp.passes.rotary import ROTARY, turns  # noqa: E402
from ncpp.program.blocks import Block  # noqa: E402
from ncpp.program.dialects.editing import splice  # noqa: E402
from ncpp.program.dialects.iso import (  # noqa: E402
    ChecksAfter,
    ChecksBefore,
    IsoWriter,
    _Units,
    as_written,
    written_apart,
)
from ncpp.program.numbers import NumberStyle, format_number, style_pattern  # noqa: E402

_AXES = "XYZ"
# a PATTERN DEF's single position `POS1 (X+25 Y+33.5 Z+0)`, and its X and Y words
_POSITION = re.compile(r"POS\d+\s*\([^)]*\)", re.IGNORECASE)
_PLANE_WORD = re.compile(r"\b([XY])\s*([+-]?(?:\d+[.,]?\d*|[.,]\d+))", re.IGNORECASE)
_POLAR_WORDS = frozenset(("R", "PR", "PA", "IPR", "IPA"))
_JUMPS = frozenset((9, 10, 11, 12))  # FN 9-12: IF ... GOTO LBL
_POLE_FUNCTIONS = frozenset(("C", "CP", "LP", "CTP", "CRP"))  # path functions that use the pole
_BLOCK_NUMBER = re.compile(r"([ \t]*(?:/[ \t]*)?)(\d+)(?![\d.,])")  # (a `/` may hide the block)
ANGLE_STYLE = NumberStyle(decimals=7, plus_sign=True)


def _function(block: Block) -> tuple[int, str] | tuple[None, None]:
    for n, item in enumerate(block.items):
        if type(item) is Statement and item.kind == "path":
            return n, item.node[0]
    return None, None


class HeidenhainWriter(IsoWriter):
    """Klartext writer.  Every block after an inserted one is renumbered (the
    number plus the blocks inserted so far), `END PGM` included.  A changed
    line edits its block (X/Y/Z absolute, IX/IY/IZ incremental as written; `LP`
    becomes `L`); a changed arc writes its own `CC` and then `C ... DR±` (`CP
    IPA ... IZ ... DR±` for a helix), and a verbatim block that relies on the
    program's pole gets that pole back in a `CC` block first.  An `RND`/`CHF`
    block after an edited line (which then ends at the tangent point) becomes
    `CC` + `C ... DR±` or an `L` to the end of its fillet or chamfer."""

    @staticmethod
    def written_at_once(event: Event) -> bool:
        """A line that runs other blocks after its text (CALL LBL, CALL PGM, a jump FN 9-12), written
        from its `Pass` alone: the moves of its runs are left as programmed and not kept (the poles
        they set are followed, `_ran`), so a loop or a called program of any length is written and
        verified (`ncpp.verify`) as it runs."""
        if type(event) is not Pass or event.skipped:
            return False
        head = next((i for i in event.block.items if type(i) is Statement and i.kind != "block_delete"), None)
        return head is not None and (
            head.kind in ("call_label", "call_program") or (head.kind == "fn" and head.node[0] in _JUMPS)
        )

    comment_open, comment_close = "; ", ""

    def __init__(self, mm_decimals: int = 4, inch_decimals: int = 5):
        super().__init__(mm_decimals, inch_decimals)
        self.shift = 0  # blocks inserted so far: added to every later block number
        self.last_number = -1
        self.header: str | None = None
        self.program_pole: tuple | None = None  # (centre, plane) as the program set it
        self.output_pole: tuple | None = None  # what the output's last CC says
        self.changed_any = False
        self.eol = "\n"
        self.restore_feed = False  # an edited corner block's F: the next move gets the program's feed back
        self.edited_last = False  # the last block was written edited (an RND/CHF after it must be too)
        self._lessons: dict[tuple[str, str], tuple] = {}  # by (letter, number pattern): see `_learn_styles`
        # every block numbered one after the last written (--expand: blocks written out where they
        # run, lines left out), the TNC's numbering, rather than its number shifted
        self.renumber = False
        self.placed = False  # a subprogram's run was written to stand at its text (`_AtDefinition`)

    def write(
        self,
        events: Iterable[Event],
        after: ChecksAfter | None = None,
        before: ChecksBefore | None = None,
    ) -> Iterator[str]:
        """`IsoWriter.write`; where a subprogram's run is written at its text, the blocks from it on
        are numbered in the order they stand (`_in_order`)."""
        lines = super().write(events, after, before)
        return lines if self.once_runs is None else self._in_order(lines)

    def _in_order(self, lines: Iterable[str]) -> Iterator[str]:
        """The written lines, each block's number one after the last once a subprogram's run was
        written to stand at its text, after M30 (its blocks were numbered as they ran, before the
        main program's blocks after its call): numbered one after another, as the TNC numbers."""
        last = -1
        for text in lines:
            found = _BLOCK_NUMBER.match(text)
            if found is not None:
                if self.placed:
                    text = f"{text[: found.start(2)]}{last + 1}{text[found.end(2) :]}"
                    last += 1
                else:
                    last = int(found.group(2))
            yield text

    def _ran(self, event: Event) -> None:
        """A pole the runs of a call or jump line set (their CC blocks): the program's and the
        output's pole after them."""
        from ncpp.motion.heidenhain import Pole

        if type(event) is Pole:
            self.program_pole = self.output_pole = (event.center, event.plane)

    def with_header(self, lines, header: str):
        """The header goes after `BEGIN PGM` as a numbered comment block (set before writing)."""
        self.header = header
        return lines

    # -- numbering ------------------------------------------------------------------------
    def _numbered(self, block: Block, raw: str) -> str:
        """`raw` (the block's text, edited or not) with the block's number shifted."""
        number = next((i for i in block.items if type(i) is Word and i.letter == "N"), None)
        if number is None:
            return raw + block.eol
        self.last_number = self.last_number + 1 if self.renumber else int(number.value) + self.shift
        if self.shift or self.renumber:
            raw = raw[: number.start] + str(self.last_number) + raw[number.end :]
        return raw + block.eol

    def _inserted(self, text: str) -> str:
        self.shift += 1
        self.last_number += 1
        return f"{self.last_number} {text}{self.eol}"

    # -- the stream -----------------------------------------------------------------------
    def _write_group(self, group):
        from ncpp.motion.heidenhain import Pole, Positions

        block = group[0].block
        self.eol = block.eol or self.eol
        if self.once_runs is not None and id(block) in self.once_runs.blocks:
            self.placed = True
        if (
            self.header is not None
            and self.last_number < 0
            and not any(type(i) is Statement and i.kind == "program_begin" for i in block.items)
        ):
            yield from self._header_first(block, self.header)
        self._learn_styles(block)
        # (under Cycle 10's rotation in the program's own frame, which the control turns: ISO's `as_written`)
        motion = [as_written(e) for e in group if type(e) is Line or type(e) is Arc]
        self._settle_plane(block, motion)
        pole = next((e for e in reversed(group) if type(e) is Pole), None)  # (a call's: its last)
        _, function = _function(block)
        edited_before = self.edited_last
        if motion:
            self.edited_last = False
        # a corner piece follows the line before it: that line's output ends at the corner
        # itself (RND/CHF verbatim) or, edited, at the tangent point (the piece written out)
        corner = function in ("RND", "CHF")
        # (a CYCL CALL POS's F is for its own move: the next move still gets the program's back)
        restores = motion and not corner and _position_call(block) is None
        feed = self._restored_feed(block, motion) if restores else ""
        if (not corner and not any(e.changed for e in motion)) or (corner and not (motion and edited_before)):
            # a subprogram or loop a call or jump line runs uses the pole as the program has it there
            at_once = self.written_at_once(group[0])
            calls = function is None and (at_once or any(m.fixed == FLOW for m in motion))
            if (
                (function in _POLE_FUNCTIONS or calls)
                and self.program_pole
                and self.output_pole != self.program_pole
                and not all(isinstance(e, Pass) and e.skipped for e in group)  # (text not run here)
            ):
                yield self._inserted(self._cc_text(*self.program_pole))
                self.output_pole = self.program_pole
            if pole is not None:
                self.program_pole = self.output_pole = (pole.center, pole.plane)
                incremental = any(type(i) is Word and i.letter in ("IX", "IY", "IZ") for i in block.items)
                if incremental and self.changed_any and not pole.again:  # relative to a position moved
                    yield self._inserted_replacing(block, self._cc_text(pole.center, pole.plane))
                    return
            yield self._numbered(block, splice(block, {}, feed) if feed else block.raw)
            if self.header is not None and any(
                type(i) is Statement and i.kind == "program_begin" for i in block.items
            ):
                for line in self.header.split("\n"):
                    yield self._inserted(self.comment(line))
                self.header = None
            for segment in motion:
                self._remember_end(segment)
            if at_once:  # (where its runs leave the tool is the control's)
                self._last_end = None
            return
        self.changed_any = self.edited_last = True
        self._tell_unpositioned(block, motion)
        if _position_call(block) is not None:
            yield from self._position_call(block, motion)
            return
        positions = next((e for e in group if type(e) is Positions), None)
        if positions is not None and positions.pattern is not None:
            yield from self._pattern_call(block, positions.pattern, motion)
            return
        if corner and any(type(i) in (Word, ExprWord) and i.letter == "F" for i in block.items):
            self.restore_feed = True  # `RND R5 F200`: F200 holds for the fillet only, a C block's F is modal
        # the block itself says the first segment of its own kind; steps before and pieces after are new blocks
        own_kind = Line if function in ("L", "LP", "CHF") else Arc
        own = next((n for n, e in enumerate(motion) if type(e) is own_kind), 0)
        # M99 calls its cycle after the block's move: with the move in pieces, on the last piece's block
        call, last_piece = _called_on(block, motion, own)
        rotary = self._rotary_words(block, motion, own)
        for n, segment in enumerate(motion):
            if (
                n > own and segment.fixed
            ):  # the control's own move after the block's (M140 MB): the text says it
                self._remember_end(segment)
                continue
            if type(segment) is Arc:
                centre_plane = (segment.center, segment.context.plane)
                yield self._inserted(self._cc_text(*centre_plane))
                self.output_pole = centre_plane
            if n == own:
                dropped = () if call is None else (call,)
                yield self._numbered(block, self._edit(block, segment, feed, dropped, rotary[n]))
            else:
                word = block.items[call] if n == last_piece and call is not None else None
                moved = "" if word is None else " " + block.raw[word.start : word.end]
                # (the block's F holds from its start: a step before its own move feeds at it)
                if n < own and not feed and not segment.rapid and _sets_feed(block):
                    feed = self._feed_word(segment)
                yield self._inserted(self._fresh(segment, rotary[n]) + feed + moved)
            feed = ""  # on the first block written
            self._remember_end(segment)

    def _rotary_words(self, block: Block, motion: list, own: int) -> list[dict[str, str]]:
        """Per move of a block that turns a rotary axis in pieces: the absolute rotary words
        (`A+22.5`) each piece writes, as ISO's `_piece_words`: the block's own piece those its words
        name that it does not turn to their end, every other piece those it turns."""
        if len(motion) < 2 or not any(type(m) is Line and turns(m) for m in motion):
            return [{}] * len(motion)
        named = {i.letter[-1] for i in block.items
                 if isinstance(i, (Word, ExprWord)) and i.letter.lstrip("I") in ROTARY and len(i.letter) <= 2}  # fmt: skip
        final = motion[-1].extra
        out = []
        for n, piece in enumerate(motion):
            axes = (range(len(piece.extra)) if type(piece) is Line and turns(piece) else ()) if n != own else [
                k for k, letter in enumerate(ROTARY) if letter in named and piece.extra[k] != final[k]]  # fmt: skip
            out.append({ROTARY[k]: self._word(ROTARY[k], piece.extra[k], piece) for k in axes
                        if n == own or piece.extra[k] != piece.extra_start[k]})  # fmt: skip
        return out

    def _position_call(self, block: Block, motion: list):
        """`CYCL CALL POS` whose move in the plane is compensated: its X and Y say where that move
        ends (its Z, the cycle's datum shift, and the cycle's moves stay as written); the move's
        pieces before the last are `L` blocks before it, each with the call's feed."""
        call = _position_call(block) or 0
        pieces = [e for e in motion if not e.fixed]
        style = self.styles.get("F") or NumberStyle(decimals=3)
        for piece in pieces[:-1]:
            feed = "" if piece.rapid else " F" + format_number(piece.feed, style)
            yield self._inserted(self._fresh(piece) + feed)
            self._remember_end(piece)
            self.restore_feed = self.restore_feed or not piece.rapid  # (the call's feed is for its move only)
        if pieces:
            last = pieces[-1]
            texts = {n: self._word(item.letter, last.end[_AXES.index(item.letter)], last)
                     for n, item in enumerate(block.items)
                     if n > call and isinstance(item, (Word, ExprWord)) and item.letter in ("X", "Y")}  # fmt: skip
            yield self._numbered(block, splice(block, texts))
        else:
            yield self._numbered(block, block.raw)
        for segment in motion[len(pieces) - 1 if pieces else 0 :]:
            self._remember_end(segment)

    def _pattern_call(self, block: Block, pattern: Block, motion: list):
        """`CYCL CALL PAT` at single positions whose moves to the holes are compensated: the PATTERN
        DEF written again just before it, each POS's X and Y where the move to its hole ends (a
        PATTERN DEF holds until the next: the call runs the one before it), the call as read, and
        the PATTERN DEF as the program has it after the call, for whatever else calls it."""
        moves = iter(e for e in motion if not e.fixed)

        def corrected(shape: re.Match) -> str:
            move = next(moves)
            return _PLANE_WORD.sub(lambda w: self._word(w[1].upper(), move.end["XY".index(w[1].upper())], move),
                                   shape[0])  # fmt: skip

        statement = next(i for i in pattern.items if type(i) is Statement and i.kind == "pattern_def")
        programmed = pattern.raw[statement.start : statement.end]
        text = _POSITION.sub(corrected, programmed)
        assert next(moves, None) is None  # (one rapid to each POS: `ncpp.motion.heidenhain.Positions`)
        yield self._inserted(text)
        yield self._numbered(block, block.raw)
        yield self._inserted(programmed)
        for segment in motion:
            self._remember_end(segment)

    def _feed_word(self, segment: Line | Arc) -> str:
        return " F" + format_number(segment.feed, self.styles.get("F") or NumberStyle(decimals=3))

    def _restored_feed(self, block: Block, motion: list) -> str:
        """` F500` for the first move after an edited `RND ... F`, unless it sets its own feed."""
        if not self.restore_feed:
            return ""
        feeds = [i for i in block.items if (isinstance(i, (Word, ExprWord)) and i.letter == "F") or (
            type(i) is Statement and i.kind == "feed")]  # fmt: skip
        if any(type(i) is Statement and i.node[0] == "FMAX" for i in feeds):
            return ""  # a rapid: the feed comes back with the move after it
        self.restore_feed = False
        if feeds:
            return ""
        return self._feed_word(motion[0])

    def _header_first(self, block: Block, header: str) -> list[str]:
        self.last_number = -1
        lines = [self._inserted(self.comment(text)) for text in header.split("\n")]  # 0..: the program shifts
        self.header = None
        return lines

    def _inserted_replacing(self, block: Block, text: str) -> str:
        number = next((i for i in block.items if type(i) is Word and i.letter == "N"), None)
        if self.renumber:
            self.last_number += 1
        else:
            self.last_number = (
                int(number.value) if number is not None else self.last_number + 1
            ) + self.shift
        return f"{self.last_number} {text}{block.eol}"

    # -- text -----------------------------------------------------------------------------
    def _style(self, letter: str, segment: Line | Arc | _Units) -> NumberStyle:
        # resolved once per letter and units, as IsoWriter's (`_learn_style` empties `_resolved`)
        key = (letter, segment.context.inch)
        style = self._resolved.get(key)
        if style is None:
            base = letter[-1] if letter.startswith("I") and len(letter) == 2 else letter
            style = (
                self.styles.get(letter)
                or self.styles.get(base)
                or self.styles.get("X")
                or NumberStyle(decimals=3)
            )
            style = self._resolved[key] = _signed(
                style.at_least(self.inch_decimals if key[1] else self.mm_decimals)
            )
        return style

    def _word(self, letter: str, value: float, segment: Line | Arc) -> str:
        return letter + format_number(value, self._style(letter, segment))

    def _increment(self, letter: str, n: int, segment: Line | Arc) -> float:
        """The increment along axis `n` an `I` word (IX, IZ) writes: the difference of the end and the
        start as written with its decimals, so that the control, adding them up, stands where the
        absolute positions would put it (rounded one by one, a run of increments drifts by their sum)."""
        places = self._style(letter, segment).decimals
        return round(segment.end[n], places) - round(segment.start[n], places)

    def _cc_text(self, centre, plane: int) -> str:
        a, b, _ = PLANE_AXES[plane]
        first, second = sorted((a, b))
        # two digits more than coordinates: a rounded pole would move the end of a CP helix off the exact point
        # (kept with the resolved styles: X's styles that resolve alike at mm and inch places do so here too)
        style = self._resolved.get("CC")
        if style is None:
            style = self._resolved["CC"] = _signed(
                (self.styles.get("X") or NumberStyle(decimals=3)).at_least(self.mm_decimals + 2)
            )
        return f"CC {_AXES[first]}{format_number(centre[first], style)} {_AXES[second]}{format_number(centre[second], style)}"

    def _is_helix(self, segment: Arc) -> bool:
        n = PLANE_AXES[segment.context.plane][2]
        return self._increment("I" + _AXES[n], n, segment) != 0.0

    def _fresh(self, segment: Line | Arc, rotary: dict[str, str] | None = None) -> str:
        """A new block for a further piece of a changed block (with its `rotary` words)."""
        if isinstance(segment, Arc):
            return self._arc_text(segment)
        # the axes that moved in the output (`_moved`, with the units' places read once per line)
        (last, last_places), inch, end = (
            self._last_seen_from(segment.context),
            segment.context.inch,
            segment.end,
        )
        units = self._resolved.get(inch) or self._units(inch)
        places, styles = units.places, units.styles
        words = [
            axis + format_number(end[n], styles[axis])
            for n, axis in enumerate(_AXES)
            if last is None or written_apart(end[n], places[n], last[n], last_places[n])
        ]
        return "L " + " ".join(words + list((rotary or {}).values())) + (" FMAX" if segment.rapid else "")

    def _arc_text(self, segment: Arc) -> str:
        rotation = "DR+" if segment.turn > 0 else "DR-"
        a, b, n = PLANE_AXES[segment.context.plane]
        if self._is_helix(segment):
            sweep = format_number(segment.sweep() * 180 / 3.141592653589793, ANGLE_STYLE)
            return f"CP IPA{sweep} {self._word('I' + _AXES[n], self._increment('I' + _AXES[n], n, segment), segment)} {rotation}"
        first, second = sorted((a, b))
        return f"C {self._word(_AXES[first], segment.end[first], segment)} {self._word(_AXES[second], segment.end[second], segment)} {rotation}"

    def _edit(self, block: Block, segment: Line | Arc, feed: str = "", dropped: tuple[int, ...] = (),
              rotary: dict[str, str] | None = None) -> str:  # fmt: skip
        """The block's raw text made to say `segment` (its other words, F, M, comments kept,
        but the items at `dropped`; `feed` added; its rotary words those of `rotary`, where it names them)."""
        index, function = _function(block)
        assert index is not None  # a block that moves has its path function
        arc = segment if isinstance(segment, Arc) else None
        helix = arc is not None and self._is_helix(arc)
        texts: dict[int, str | None]
        if arc is not None and (helix or function not in ("C",)):
            # another arc form (CR, CT, CP, a helix): the block becomes C/CP, its words replaced
            texts = {n: None for n, i in enumerate(block.items)
                     if (isinstance(i, (Word, ExprWord))
                         and (i.letter in _POLAR_WORDS or i.letter.lstrip("I") in _AXES))
                     or (type(i) is Statement and i.kind == "rotation")}  # fmt: skip
            texts[index] = self._arc_text(arc)
            return splice(block, texts, feed)
        texts = dict.fromkeys(dropped)
        if arc is None and function != "L":  # LP, or a line where the program had an arc: the block becomes L
            texts[index] = "L"
            texts.update({n: None for n, i in enumerate(block.items)
                          if (isinstance(i, (Word, ExprWord)) and i.letter in _POLAR_WORDS)
                          or (type(i) is Statement and i.kind == "rotation")})  # fmt: skip
        plane_axes = PLANE_AXES[segment.context.plane][:2] if arc is not None else ()
        written = set()
        anchor = block.items[index] if index is not None else None
        for n, item in enumerate(block.items):
            if (
                isinstance(item, (Word, ExprWord))
                and item.letter.lstrip("I") in _AXES
                and len(item.letter) <= 2
            ):
                axis = _AXES.index(item.letter[-1])
                incremental = item.letter.startswith("I")
                value = self._increment(item.letter, axis, segment) if incremental else segment.end[axis]
                texts[n] = self._word(item.letter, value, segment)
                written.add(axis)
                anchor = item
            elif type(item) is Statement and item.kind == "rotation" and arc is not None:
                texts[n] = "DR+" if arc.turn > 0 else "DR-"
            elif rotary and isinstance(item, (Word, ExprWord)) and item.letter.lstrip("I") in rotary:
                texts[n] = rotary[item.letter.lstrip("I")]  # (`IA+90` too: a piece writes where it ends)
        extra = [self._word(_AXES[k], segment.end[k], segment) for k in range(3) if k not in written and (
            k in plane_axes or (_AXES[k] in self.known_axes and self._moved(_AXES[k], segment.end[k], segment)))]  # fmt: skip
        if arc is not None and not any(type(i) is Statement and i.kind == "rotation" for i in block.items):
            extra.append("DR+" if arc.turn > 0 else "DR-")
        return splice(block, texts, "".join(" " + w for w in extra) + feed, after=anchor)

    def _learn_styles(self, block: Block) -> None:
        """The number styles of the block's words, and the axes it positions (`known_axes`): those of
        a block that moves, not of the blank, a pole or a datum shift (`_positions`)."""
        lessons = self._lessons
        positions = _positions(block)
        for item in block.items:
            if type(item) is Word:
                # (letter, the number's signs, point and zeros): the style it teaches, and whether it is an axis
                key = (item.letter, style_pattern(item.number))
                lesson = lessons.get(key)
                if lesson is None:
                    if len(lessons) >= 4096:  # zeros and ones make the patterns: keep memory flat
                        lessons.clear()
                    lesson = lessons[key] = _lesson(item.letter, item.number)
                if lesson is not _NO_LESSON:
                    # by `_learn_style`: a new style drops the resolved ones (the decimal places the
                    # output's position is remembered with), else they stay those of the first move
                    letter, style, axis = lesson
                    self._learn_style(letter, style)
                    if axis and positions:
                        self.known_axes.add(axis)
            elif (
                positions and type(item) is ExprWord and item.letter[-1:] in _AXES
                and item.letter.lstrip("I") == item.letter[-1]
            ):  # fmt: skip
                self.known_axes.add(item.letter[-1])  # `X+Q1932` positions X as a number does


def _positions(block: Block) -> bool:
    """Whether the block's axis words say where the tool goes: a path function's but the pole's
    (`CC`: "the tool does not move", TNC 640 Klartext manual, "Circle center CC"), or `CYCL CALL POS`'s;
    the blank's (`BLK FORM`) and a datum shift's (`CYCL DEF 7.1 X..`) move no axis."""
    return any(
        type(i) is Statement
        and ((i.kind == "path" and i.node[0] != "CC") or (i.kind == "cycle_call" and i.node[0] == "POS"))
        for i in block.items
    )


def _sets_feed(block: Block) -> bool:
    """Whether the block programs a feed (`F1000`, `FQ53`, `FAUTO`), not FMAX."""
    return any((isinstance(i, (Word, ExprWord)) and i.letter == "F")
               or (type(i) is Statement and i.kind == "feed" and i.node[0] == "FAUTO")
               for i in block.items)  # fmt: skip


def _position_call(block: Block) -> int | None:
    """The index of a `CYCL CALL POS` in the block, if it is one."""
    return next((n for n, i in enumerate(block.items)
                 if type(i) is Statement and i.kind == "cycle_call" and i.node[0] == "POS"), None)  # fmt: skip


def _called_on(block: Block, motion: list, own: int) -> tuple[int | None, int | None]:
    """(the index of the block's M99, the piece it goes to) where the block's own move, in pieces
    after `own`, calls a drilling cycle; (None, None) where the M99 stays in the block."""
    if not any(e.fixed == DRILLED for e in motion):
        return None, None
    after = [n for n, e in enumerate(motion) if n > own and not e.fixed]
    call = next((n for n, i in enumerate(block.items)
                 if type(i) is Word and i.letter == "M" and i.value == 99.0), None)  # fmt: skip
    return (call, after[-1]) if after and call is not None else (None, None)


_NO_LESSON = ()


def _lesson(letter: str, number: str) -> tuple:
    """What a word teaches `_learn_styles`: (letter, style, its axis or ''), or nothing."""
    if letter in ("M", "N", "S", "PA", "IPA"):
        return _NO_LESSON
    style = NumberStyle.of(number)
    axis = letter[-1] if letter[-1] in _AXES and letter.lstrip("I") == letter[-1] else ""
    return (letter, style if letter == "F" else _signed(style), axis)


@functools.lru_cache(maxsize=1024)
def _signed(style: NumberStyle) -> NumberStyle:
    """The style with its plus sign: every letter but F (written as read) is written
    signed (`_style`), so `X+1.5` and `X-1.5` teach one style, and the styles
    resolved from it stay."""
    return replace(style, plus_sign=True)
