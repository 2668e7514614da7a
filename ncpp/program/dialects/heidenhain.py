"""Heidenhain Klartext (TNC 530 / 640): items of a conversational block.

Blocks map onto the common item classes so that interpreters and writers
handle every dialect alike:

* the block number `15` is `Word('N', 15.0, '15')` (its span has no letter);
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
  feed           ('FMAX' | 'FAUTO',)     `F200` is a Word
  rotation       ('+' | '-',)            `DR+` counter-clockwise, `DR-` clockwise
  tool_call      (tool, axis)            `TOOL CALL 1 Z S800`: tool int | float | "name" | ("param", q)
                                         | None, axis 'X' | 'Y' | 'Z' | None; S F DL DR words follow
  tool_def       (tool,)                 `TOOL DEF 5 L+0 R+5`
  label          (label,)                `LBL 1` -> 1, `LBL "name"` -> 'name' (`LBL 0` ends a subprogram)
  call_label     (label, repeat)         `CALL LBL 1 REP 2/2` -> (1, 2); repeat 0 without REP
  call_program   (path,)                 `CALL PGM TNC:\\Plan.h`
  cycle_def      (number, words)         `CYCL DEF 200 BOHREN` -> ('200', ('BOHREN',)); its Q200=...
                                         parameters (continuation lines) follow as assignments
  cycle_call     (variant,)              `CYCL CALL` None, `CYCL CALL POS` 'POS'
  fn             (number, text)          `FN 9: IF +Q1 EQU +0 GOTO LBL "x"` -> (9, 'IF +Q1 ...'), passed through
  assignment     (("param", "q1950"), expr)  `Q1950 = Q1804 - Q1805`; a string ("str", text) for QS
  keyword        (words...)              anything else led by keywords (`STOP`, `PLANE ...`), passed through
Expressions: ("num", v) ("param", "q12"|"ql1"|"qr1"|"qs1") ("neg", x) ("bin", op, a, b) with op in
+ - * / ** (`^`), ("call", NAME, x) for SIN COS TAN ASIN ACOS ATAN SQRT SQ LN LOG ABS INT FRAC NEG SGN.
"""

from __future__ import annotations

import math

from lark import Token, Transformer, v_args

from ncpp.program.blocks import Comment, ExprWord, Statement, Word
from ncpp.program.parser import Dialect

_ADDRESS_END = "+-0123456789.,Q"


def number_value(text: str) -> float:
    """`+10,5` -> 10.5; `- 200` -> -200.0 (sign, blanks and decimal comma as written)."""
    return float(text.replace(" ", "").replace("\t", "").replace(",", "."))


def _split_address(text: str) -> tuple[str, str]:
    """`IX-5` -> ('IX', '-5'); `DR2+0` -> ('DR2', '+0'); `RQ1832` -> ('R', 'Q1832')."""
    if text[:3].upper() == "DR2" and len(text) > 3 and text[3] in "+-":
        return "DR2", text[3:]
    end = 0
    while end < len(text) and text[end] not in _ADDRESS_END:
        end += 1
    return text[:end].upper(), text[end:]


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
            if isinstance(child, Token):  # the block number
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
    def _statement(kind: str, shape):  # type: ignore[misc]
        @v_args(meta=True)
        def build(self, meta, children):
            return Statement(kind, shape(children), meta.start_pos, meta.end_pos)

        return build

    def _text(children, skip: int = 1) -> tuple:  # type: ignore[misc]
        return tuple(str(c) for c in children[skip:])

    def _pgm(children) -> tuple:  # type: ignore[misc]
        name = str(children[1])
        return (name, str(children[2]).upper() if len(children) > 2 else None)

    def _blk(children) -> tuple:  # type: ignore[misc]
        return (str(children[1]), str(children[2]).upper() if len(children) > 2 else None)

    def _tool_call(children) -> tuple:  # type: ignore[misc]
        tool, axis = None, None
        for c in children[1:]:
            if isinstance(c, Token) and c.type == "AXIS":
                axis = str(c).upper()
            else:
                tool = _tool_ref(c)
        return (tool, axis)

    def _call_label(children) -> tuple:  # type: ignore[misc]
        ints = [c for c in children[2:] if isinstance(c, Token) and c.type == "INT"]
        return (_tool_ref(children[1]), int(ints[0]) if ints else 0)

    def _cycle_def(children) -> tuple:  # type: ignore[misc]
        return (str(children[1]), tuple(str(c).strip() for c in children[2:]))

    def _cycle_call(children) -> tuple:  # type: ignore[misc]
        words = str(children[0]).split()
        return (words[2].upper() if len(words) > 2 else None,)

    def _fn(children) -> tuple:  # type: ignore[misc]
        number = int("".join(ch for ch in str(children[0]) if ch.isdigit()))
        return (number, str(children[1]).strip() if len(children) > 1 else "")

    def _path(children) -> tuple:  # type: ignore[misc]
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
    fn = _statement("fn", _fn)
    keyword = _statement("keyword", lambda c: tuple(str(t).upper() for t in c))
    radius_comp = _statement("radius_comp", lambda c: (str(c[0]).upper(),))
    feed = _statement("feed", lambda c: (str(c[0]).upper(),))
    rotation = _statement("rotation", lambda c: (str(c[0])[-1],))
    del _statement, _text, _pgm, _blk, _tool_call, _call_label, _cycle_def, _cycle_call, _fn, _path

    @v_args(meta=True)
    def assignment(self, meta, children):
        target, value = children
        if isinstance(value, Token):  # a string for a QS parameter
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


HEIDENHAIN = Dialect("heidenhain", "heidenhain", HeidenhainBuilder, fast_terminals=(), continuation="~")
