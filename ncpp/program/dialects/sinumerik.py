"""Siemens Sinumerik 840D: items of an NC block.

Blocks map onto the common item classes:

* `X10` `G2` `N10` `F1000` are `Word`s (a letter and a number, nothing else);
* `X=R1+2` `X=AC(10)` `I=AC(5)` `CR=5` `I1=5` `TURN=2` `T="MILL"` are
  `ExprWord`s: an address (one letter, optionally with a numeric extension,
  or a multi-letter address of ADDRESSES) with an expression;
* `NAME = expr` for anything else (R parameters, user variables, `$` system
  variables, array elements) is an assignment `Statement`; an interpreter
  that knows a machine axis called `ELX` can treat ("param", "elx") as one;
* `;` comments are `Comment`s; parentheses are arithmetic.

Statement kinds and nodes (Sinumerik):
  assignment   (target, expr)             target ("param", "r1") | ("index", "feld", (exprs)); a value
                                          list `OSCTRL[Z]=(1,2)` has the expr ("list", (exprs))
  label        (NAME,)                    `LABEL_1:` (upper case, no colon)
  call         (NAME, args)               `CYCLE81(10,0,2,-5)`, `MSG("x")`, `SETAL(1)`, `BNAT`,
                                          `MATERIAL_UPDATE`: passed through; args tuple of exprs, None if
                                          empty; `CALL "PART2"` (an indirect call) is ("CALL", (expr,)),
                                          `EXTCALL "PART2"` ("EXTCALL", (expr,)); `PCALL/_N_WKS_DIR/SUB(1, R2)`
                                          ("PCALL", (("str", "/_N_WKS_DIR/SUB"), ("num", 1.0), ("param", "r2")))
  path         (NAME,)                    CIP CT ASPLINE BSPLINE CSPLINE POLY (words follow)
  frame        (NAME,)                    TRANS ATRANS ROT AROT SCALE ASCALE MIRROR AMIRROR ... (words follow)
  def          (type, length, vars)       `DEF STRING[8] A="x", B` -> ('STRING', ("num", 8.0), ((target, init|None), ...))
  proc         (NAME, params, attributes) params ((type, name, by_reference, dims|None), ...)
  if / while / until  (condition,)       block-structured; `IF c GOTOF L` is an `if` then a `goto` in one block
  else endif endwhile endfor repeat loop endloop   ()
  for          (target, start, end)       `FOR I=0 TO 10`
  goto         (KEYWORD, TARGET)          ('GOTOF' | 'GOTOB' | 'GOTOC' | 'GOTO', 'LABEL' | 'N100' | '90')
  case         (expr, branches, default)  branches ((value_expr, KEYWORD, TARGET), ...), default (KEYWORD, TARGET) | None
  program_name (text,)                    `%_N_PART_MPF`
  sync_action  (text,)                    `ID=7 EVERY $A_IN[7]<>0 DO $R1=1`, to the end of the line
A main block number `:10` is `Word(':', 10.0, '10')`.
Expressions: ("num", v) ("str", s) ("param", name) ("index", name, (exprs)) ("neg", x) ("not", x)
("bnot", x) ("bin", op, a, b) with op + - * / DIV MOD == <> < > <= >= AND OR XOR B_AND B_OR B_XOR <<,
("call", NAME, *args) for functions (SIN(30) in degrees, ATAN2(a, b), POT, ...), and the coordinate
modes ("ac", x) ("ic", x) ("dc", x) ("acp", x) ("acn", x) for `AC(...)` `IC(...)` ...  Names are
case-insensitive and kept lower case.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Iterator
from itertools import islice

from lark import Token, Transformer, v_args

from ncpp.program.blocks import Comment, ExprWord, Statement, Word
from ncpp.program.parser import Dialect, _word

# Multi-letter addresses that take `=`: interpolation and spline parameters, polar words, the
# chamfer / rounding and contour-angle words (Fundamentals, "Chamfer, rounding (CHF, CHR, RND, RNDM,
# FRC, FRCM)", "Contour definitions": ANG) and the measuring words (Job Planning, "Measurements with
# touch trigger probe (MEAS, MEAW)"), the programmable tool offsets and the sum offset (Fundamentals,
# "Programmable tool offset (TOFFL, TOFF, TOFFR)"; "Tool offsets": DL), the transition circle at
# outside corners and the smooth approach and retraction words (Fundamentals, "Compensation at the
# outside corners (G450, G451, DISC)", "Smooth approach and retraction": DISR, DISCL, DISRP, FAD),
# and the settings CAM posts write beside the path: the smoothing distance (ADIS, ADISPOS), the
# compressor's tolerances (CTOL, OTOL, ATOL, G0TOL, STOLF), overrides (OVR, OVRRAP), a spindle's
# positioning and speed limit (SPOSA, LIMS): words of the block, not user variables.
ADDRESSES = frozenset(
    {"CR", "TURN", "AR", "AP", "RP", "PW", "SD", "PL", "SF", "SPOS", "OFFN", "ACC", "SR", "SRA"}
    | {"CHF", "CHR", "RND", "RNDM", "ANG", "MEAS", "MEAW"}
    | {"TOFFL", "TOFFR", "DL", "DISC", "DISR", "DISCL", "DISRP", "FAD"}
    | {"ADIS", "ADISPOS", "CTOL", "OTOL", "ATOL", "G0TOL", "STOLF", "OVR", "OVRRAP", "SPOSA", "LIMS"}
)
COORDINATE_MODES = frozenset({"AC", "IC", "DC", "ACP", "ACN", "CAC", "CIC"})
_ADDRESS = re.compile(r"[A-QS-Za-qs-z]\d*|[Rr]")
_R_PARAMETER = re.compile(r"[Rr]\d+")


def _is_address(name: str) -> bool:
    return bool(_ADDRESS.fullmatch(name)) or name.upper() in ADDRESSES


class SinumerikBuilder(Transformer):
    """Turns a Lark tree of one Sinumerik block into items with spans."""

    def start(self, children):
        items = []
        for child in children:
            if isinstance(child, Token):
                text = str(child)
                if child.type == "MAIN_BLOCK":
                    number = text[1:].strip()
                    items.append(Word(":", float(number), number, child.start_pos, child.end_pos))
                else:  # BLOCK_DELETE
                    items.append(Statement("block_delete", (text,), child.start_pos, child.end_pos))
            else:
                items.append(child)
        return tuple(items)

    def word(self, children):
        (tok,) = children
        return _word(str(tok), tok.start_pos, tok.end_pos)

    def line_comment(self, children):
        (tok,) = children
        return Comment(str(tok)[1:], ";", tok.start_pos, tok.end_pos)

    @v_args(meta=True)
    def assign(self, meta, children):
        target, value = children
        if target[0] == "param" and _is_address(target[1]) and not _R_PARAMETER.fullmatch(target[1]):
            return ExprWord(target[1].upper(), value, meta.start_pos, meta.end_pos)
        return Statement("assignment", (target, value), meta.start_pos, meta.end_pos)

    @v_args(meta=True)
    def assign_list(self, meta, children):
        # A value list, `OSCTRL[Z]=(1+2,16+32+64)` (Function Manual Extended Functions, "Oscillation
        # (P5)": the set and the reset options): one ("list", exprs) value
        target, *values = children
        return Statement("assignment", (target, ("list", tuple(values))), meta.start_pos, meta.end_pos)

    # Helpers that build the rule methods, called in the class body: plain functions, not
    # methods, which mypy cannot tell (hence their `type: ignore[misc]`)
    def _statement(kind: str, shape):  # type: ignore[misc]
        @v_args(meta=True)
        def build(self, meta, children):
            return Statement(kind, shape(children), meta.start_pos, meta.end_pos)

        return build

    def _call(children: list) -> tuple:  # type: ignore[misc]
        return (str(children[0]).upper(), children[1] if len(children) > 1 else ())

    def _define(children: list) -> tuple:  # type: ignore[misc]
        (type_name, length), variables = children[1], children[2:]
        return (type_name, length, tuple(variables))

    def _proc(children: list) -> tuple:  # type: ignore[misc]
        name = str(children[1]).upper()
        params = tuple(c for c in children[2:] if isinstance(c, tuple))
        attributes = tuple(str(c).upper() for c in children[2:] if isinstance(c, Token))
        return (name, params, attributes)

    def _goto(children: list) -> tuple:  # type: ignore[misc]
        return (str(children[0]).upper(), str(children[1]).upper())

    def _case(children: list) -> tuple:  # type: ignore[misc]
        expr, rest = children[1], children[2:]
        branches = tuple(c for c in rest if isinstance(c, tuple))
        tokens = [c for c in rest if isinstance(c, Token) and c.type != "OF"]
        default = (str(tokens[1]).upper(), str(tokens[2]).upper()) if tokens else None
        return (expr, branches, default)

    call = _statement("call", _call)
    # `CALL "PART2"`, `CALL NAME_VARIABLE`, `EXTCALL ("PART2")`
    indirect_call = _statement("call", lambda c: (str(c[0]).upper(), (c[1],)))
    # `PCALL/_N_WKS_DIR/SUB(1, 2)`: the path a string argument before the parameters
    path_call = _statement("call", lambda c: ("PCALL", (("str", str(c[0])[5:].strip()), *(c[1:] and c[1]))))
    label = _statement("label", lambda c: (str(c[0])[:-1].upper(),))
    path = _statement("path", lambda c: (str(c[0]).upper(),))
    frame = _statement("frame", lambda c: (str(c[0]).upper(),))
    define = _statement("def", _define)
    proc = _statement("proc", _proc)
    if_ = _statement("if", lambda c: (c[1],))
    while_ = _statement("while", lambda c: (c[1],))
    until = _statement("until", lambda c: (c[1],))
    for_ = _statement("for", lambda c: (c[1], c[2], c[4]))
    goto = _statement("goto", _goto)
    case = _statement("case", _case)
    program_name = _statement("program_name", lambda c: (str(c[0]),))
    sync_action = _statement("sync_action", lambda c: (str(c[0]),))
    else_ = _statement("else", lambda c: ())
    endif = _statement("endif", lambda c: ())
    endwhile = _statement("endwhile", lambda c: ())
    endfor = _statement("endfor", lambda c: ())
    repeat = _statement("repeat", lambda c: ())
    loop = _statement("loop", lambda c: ())
    endloop = _statement("endloop", lambda c: ())
    del _statement, _call, _define, _proc, _goto, _case

    # -- parts -------------------------------------------------------------------
    def def_type(self, children):
        return (str(children[0]).upper(), children[1] if len(children) > 1 else None)

    def def_var(self, children):
        return (children[0], children[1] if len(children) > 1 else None)

    def proc_param(self, children):
        by_reference = isinstance(children[0], Token) and children[0].type == "VAR"
        rest = children[1:] if by_reference else children
        dims = rest[2] if len(rest) > 2 else None
        # The type comes from def_type: a STRING parameter carries its length (`STRING[32] NAME`).
        return (rest[0][0], str(rest[1]).lower(), by_reference, dims)

    def case_branch(self, children):
        value, keyword, target = children
        return (value, str(keyword).upper(), str(target).upper())

    def args(self, children):
        return () if children == [None] else tuple(children)

    def arg(self, children):
        return children[0] if children else None

    # -- expressions ---------------------------------------------------------------
    def var(self, children):
        return ("param", str(children[0]).lower())

    def index(self, children):
        name, args = children
        return ("index", str(name).lower(), args)

    def number(self, children):
        return ("num", float(str(children[0]).upper().replace("EX", "E")))

    def string(self, children):
        return ("str", str(children[0])[1:-1])

    def boolean(self, children):
        return ("num", 1.0 if str(children[0]).upper() == "TRUE" else 0.0)

    def func(self, children):
        name, args = str(children[0]).upper(), children[1]
        if name in COORDINATE_MODES and len(args) == 1:
            return (name.lower(), args[0])
        return ("call", name, *args)

    def to_string(self, children):
        # `<<R1` alone converts to STRING (Job Planning manual, "String operations"): the
        # concatenation with an empty string
        return ("bin", "<<", ("str", ""), children[1])

    def neg(self, children):
        return ("neg", children[0])

    def pos(self, children):
        return children[0]

    def not_(self, children):
        return ("not", children[1])

    def bnot(self, children):
        return ("bnot", children[1])

    def _binary(self, children):
        a, op, b = children
        return ("bin", str(op).upper(), a, b)

    compare = concat = lor = lxor = land = bor = bxor = band = sum = product = _binary


SINUMERIK = Dialect(
    "sinumerik",
    "sinumerik",
    SinumerikBuilder,
    fast_terminals=("WORD", "SEMI_COMMENT"),
    max_line=512,
    max_line_source="SINUMERIK 840D sl Programming Manual Fundamentals, block length: 512 characters",
)


# ---- writer ------------------------------------------------------------------------------

from ncpp.motion.segments import Arc, Event, Line, Pass  # noqa: E402  (the writer half of the module)
from ncpp.program.blocks import Block  # noqa: E402
from ncpp.program.dialects.editing import splice  # noqa: E402
from ncpp.program.dialects.iso import AXES, IsoWriter, new_block_key  # noqa: E402
from ncpp.program.numbers import NumberStyle  # noqa: E402
from ncpp.program.writer import edit_texts  # noqa: E402

_ARC_ONLY = ("CR", "TURN", "I1", "J1", "K1")
_MOTION_PATHS = ("CIP", "CT")


# A program's opening lines the header goes below: its name `%_N_PART_MPF`, a PROC definition
_NAME_LINE = re.compile(r"[ \t]*%")
_PROC = re.compile(r"[ \t]*(N\d+[ \t]*)?PROC\b", re.IGNORECASE)


class SinumerikWriter(IsoWriter):
    """ISO writer with Sinumerik spelling: `;` comments, `X=..` for words written as
    expressions, `CR=` arcs when the program wrote `CR=`, and `CIP` / `CT` blocks
    rewritten as G2/G3 with I/J/K (the modal `CIP` / `CT` restored for verbatim
    blocks that rely on it)."""

    comment_open, comment_close = "; ", ""

    @staticmethod
    def written_at_once(event: Event) -> bool:
        """A line that runs other blocks' moves after its text (a subprogram call, a loop's end, a
        jump), as the interpreter tells by the mode it runs in on the line's `Pass`: written from
        that alone, its runs' moves (left as programmed) not kept, so a loop or a subprogram of
        any length is written and verified (`ncpp.verify`) as it runs."""
        return type(event) is Pass and event.motion is not None and not event.skipped and event.cycle is None

    def _write_group(self, group: list[Event]) -> Iterable[str]:
        first = group[0]
        return (
            self._write_control(first.block, first)
            if self.written_at_once(first)
            else super()._write_group(group)
        )

    def _write_control(self, block: Block, first: Event) -> list[str]:
        """Its text, in the motion mode the program has there (the blocks it runs may rely on
        it); after it the mode and the position are the control's: the next edited block writes
        its motion word and every axis it knows."""
        mode = first.motion if type(first) is Pass else None
        restore = mode is not None and self.output_motion is not None and self.output_motion != mode
        if restore:
            self.program_motion = mode  # type: ignore[assignment]  # (a Sinumerik mode: a G code or CIP / CT)
        lines = [self._restore_mode_line(block), block.text] if restore else [block.text]
        self.program_motion = self.output_motion = None
        self._last_end = None
        return lines

    def with_header(self, lines: Iterable[str], header: str) -> Iterator[str]:
        """The header's comment lines first, after a `%_N_..` name line and after a `PROC`
        definition that opens the program: the Job Planning manual has the PROC statement
        as the subprogram's first block."""
        it = iter(lines)
        head = list(islice(it, 2))
        at = 1 if head and _NAME_LINE.match(head[0]) else 0
        if at < len(head) and _PROC.match(head[at]):
            at += 1
        eol = "\r\n" if head and head[0].endswith("\r\n") else "\n"
        yield from head[:at]
        yield from (self.comment(line) + eol for line in header.split("\n"))
        yield from head[at:]
        yield from it

    @staticmethod
    def _path(block: Block) -> str | None:
        return next(
            (
                i.node[0]
                for i in block.items
                if type(i) is Statement and i.kind == "path" and i.node[0] in _MOTION_PATHS
            ),
            None,
        )

    def _has_motion_word(self, block: Block) -> bool:
        return super()._has_motion_word(block) or self._path(block) is not None

    def _block_motion(self, block: Block):
        return self._path(block) or super()._block_motion(block)

    def _restore_mode_line(self, block: Block) -> str:
        self.output_motion = self.program_motion
        mode = self.program_motion
        return f"{mode if isinstance(mode, str) else f'G{mode}'}{block.eol}"

    @staticmethod
    def _uses_cr(block: Block) -> bool:
        return any(type(i) is ExprWord and i.letter == "CR" for i in block.items)

    def _texts(self, block: Block, segment: Line | Arc) -> dict[str, str]:
        texts = super()._texts(block, segment)
        if (
            type(segment) is Arc
            and self._uses_cr(block)
            and abs(segment.sweep()) < 2 * 3.141592653589793 - 1e-9
        ):
            for letter in "IJK":
                texts.pop(letter, None)
            radius = segment.radius() if abs(segment.sweep()) <= 3.141592653589793 else -segment.radius()
            texts["CR"] = self._format("CR", radius, segment)
        return texts

    # (`more`: a piece's own words, ISO's `_write_pieces`: the rotary axes' positions, `_piece_words`)
    def _edit_block(self, block: Block, segment: Line | Arc, more: dict[str, str] | None = None) -> str:
        facts = self._facts(block)
        if block.signature is not None and not facts.machine and facts.letters.isdisjoint(_ISO_ONLY):
            # one-letter words and comments only (`X10.5 Y2.25`): ISO's edit, by compiled plans, says the same
            return super()._edit_block(block, segment, more)
        return self._edit_in_general(block, segment, more)

    @staticmethod
    def _piece_number(piece: Line | Arc, i: int, style: NumberStyle) -> float:
        """Where the axis turns to, in G91 too: `_piece_words` writes it `=AC(..)`."""
        return piece.extra[i]

    def _piece_words(self, block: Block, pieces: list) -> list[dict[str, str]]:
        """ISO's, a position written `=AC(..)` in G91, where a plain word would be an increment (840D sl
        Programming Manual Fundamentals, "Absolute dimensions (G90, AC)")."""
        out = super()._piece_words(block, pieces)
        for words, piece in zip(out, pieces):
            if not piece.context.absolute:
                words.update((letter, f"=AC({text})") for letter, text in words.items() if letter in "ABC")
        return out

    def _edit_in_general(self, block: Block, segment: Line | Arc, more: dict[str, str] | None = None) -> str:
        words = {**self._texts(block, segment), **(more or {})}
        texts: dict[int, str | None] = {}
        for n, item in enumerate(block.items):
            if type(item) is ExprWord and item.letter in words:
                text = words.pop(item.letter)
                texts[n] = item.letter + text if text.startswith("=") else f"{item.letter}={text}"
            elif type(item) is ExprWord and item.letter in _ARC_ONLY + tuple("IJK") + tuple(AXES):
                texts[n] = None  # (an axis the block does not move after a change of units: `_bits_written`)
            elif type(item) is Statement and item.kind == "path" and item.node[0] in _MOTION_PATHS:
                texts[n] = None
        had_motion = self._has_motion_word(block)
        program_motion = self._block_motion(block)
        code = self._motion_code(segment)
        if texts:
            block = _reparse(Block(splice(block, texts), block.eol, (), block.line))
        drop = [letter for letter in "IJK" + AXES if letter not in words]
        raw = edit_texts(
            block, words, drop=drop, motion=code if code != self.output_motion or had_motion else None
        )
        if had_motion or code != self.output_motion:
            self.output_motion = code
        if had_motion:
            self.program_motion = program_motion
        self._remember_end(segment)
        return raw

    def _new_blocks(self, block: Block, segments: list, eol: str, more: list[dict[str, str]] | None = None
                    ) -> list[str]:  # fmt: skip
        return [
            self._new_block(block, segment, more[k] if more else None) + eol
            for k, segment in enumerate(segments)
        ]

    def _new_block(self, block: Block, segment: Line | Arc, more: dict[str, str] | None = None) -> str:
        inch = segment.context.inch
        units = self._resolved.get(inch) or self._units(inch)
        code = self._motion_code(segment)
        motion = code if code != self.output_motion else None
        sep = self._spelling(block)[0]  # packed blocks: new ones are spaced (`X1=...` needs it)
        sep = sep if sep and not sep.strip() else " "
        if units.plain and not more and (type(segment) is Line or not self._uses_cr(block)):
            # one template per letters written, motion and separator: `G1 X{0:z.4f} Y{1:z.4f}`
            bits = self._written_bits(self._facts(block), segment, units)
            templates = units.new_lines.setdefault(("sinumerik", sep), {})
            key = new_block_key(bits, motion)
            template = templates.get(key)
            if template is None:
                fields = [f"G{motion}"] if motion is not None else []
                template = templates[key] = sep.join(
                    fields + [letter + field for letter, field in units.fields(bits).items()]
                )
            text = template.format(*self._numbers(segment, units.places))
        else:
            words = {**self._texts(block, segment), **(more or {})}
            parts = [f"G{motion}"] if motion is not None else []
            parts += [
                f"{letter}={text}" if len(letter) > 1 else letter + text for letter, text in words.items()
            ]
            text = sep.join(parts)
        if motion is not None:
            self.output_motion = code
        self._remember_end(segment)
        return text


# Letters ISO's edit reads as its own (R, P: an arc's radius and turns, dropped when the arc
# changes) where Sinumerik means other things; G53 (ISO: machine coordinates) is `_Facts.machine`
_ISO_ONLY = frozenset({"R", "P"})
_PARSERS: dict[str, object] = {}


def _reparse(block: Block) -> Block:
    """A spliced block read again, so that its items' spans are right."""
    from ncpp.program.parser import LineParser

    parser = _PARSERS.get("sinumerik") or _PARSERS.setdefault("sinumerik", LineParser(SINUMERIK))
    return parser.parse(block.raw, block.eol, block.line)  # type: ignore[attr-defined]
