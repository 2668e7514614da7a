"""Lathe programs: refused when ncpp is to compensate them.

ncpp's machine model is a machining centre's X Y Z.  A lathe program's X is a diameter (Fanuc
and Haas lathes, LinuxCNC in G7, a TNC in turning mode, Sinumerik in DIAMON) along the cross
slide and its Z the spindle axis, so the corrections of a mill's axes would be applied to the
wrong machine: the program is refused before any block goes on (`refuse_lathe`), at the first
construct only a lathe (or the turning part of a mill-turn) program has.  Without a machine file
nothing is read and a lathe program passes through unchanged, as every program does.

The constructs, each one a milling program of the same dialect does not write:

* Fanuc and Haas: G70, G71 or G72 with both P and Q, the multiple repetitive cycles that rough or
  finish the contour between blocks N(P) and N(Q) (Fanuc lathe G-code system A, "G71 P(ns) Q(nf)
  U W F", "G70 P(ns) Q(nf)"; Haas Lathe Operator's Manual, "G70 Finishing Cycle", "G71 O.D./I.D.
  Stock Removal Cycle", "G72 End Face Stock Removal Cycle").  Fanuc mills have no G70-G72; Haas
  mills' G70-G72 are bolt-hole patterns with I J K L and no P or Q, which may share a block with the
  drilling cycle they repeat (whose G83 takes a P and a Q): a block with a cycle of G73-G89 is
  not taken for a lathe's.
* Every ISO dialect: G50 with S, a lathe's spindle speed limit (Haas Lathe Operator's Manual "G50
  Spindle Speed Limit"; Fanuc lathes "G50 S_", the maximum speed under constant surface speed).
  On mills G50 cancels scaling and takes no word (Haas Mill Operator's Manual 96-8000, "G50 Cancel
  Scaling (Group 11)"; Fanuc's scaling cancel `G50 ;`; PathPilot writes it in its safety line);
  LinuxCNC and grbl have no G50.
* LinuxCNC: G7, "Lathe Diameter Mode", which "enter[s] the diameter mode for axis X on a lathe";
  G70, G71, G72 and their .1/.2 forms with a Q (the subroutine with the profile), the "Lathe
  finishing cycle" and "Lathe roughing cycles", an error unless the ZX plane is selected
  (LinuxCNC G-code manual).  The Q tells them from the inch/metric G70/G71 of other controls' ISO
  programs.
* grbl, read with LinuxCNC's grammar: the same codes, none of which grbl 1.1 has ("List of
  Supported G-Codes in Grbl v1.1", its README): grbl stops at them with error 20, "Unsupported or
  invalid g-code command found in block" (grbl's doc/csv/error_codes_en_US.csv); the message says so.
* Heidenhain Klartext (TNC 640 mill-turning): `FUNCTION MODE TURN`, which switches the control to
  turning, X then a diameter, and the turning cycles 810-872 and 882-883 (contour, shoulder,
  plunge, thread and recess turning, simultaneous roughing and finishing), which the TNC 640
  runs in turning mode only (TNC 640 User's Manual, "Mill-turning", "Cycles for turning").
  A turning tool's `TOOL CALL` looks like any tool's: not a marker.
* Sinumerik: `DIAMON` and `DIAM90`, diameter programming of the transverse axis, which a
  channel has only where a transverse axis is defined ($MC_DIAMETER_AX_DEF: a lathe's X, or a
  mill-turn's in its turning part); and the turning cycles CYCLE92-CYCLE99, CYCLE930, CYCLE940,
  CYCLE950-CYCLE952 (parting, grooving, undercuts, stock removal, threads, contour turning:
  SINUMERIK 840D Programming Guide Cycles, "Turning Cycles"; 840D sl Operating Manual Turning,
  "Contour turning"; its milling manual names them for milling/turning machines, whose turning
  part is still turning).  Milling cycles (CYCLE800 swivel, CYCLE832, CYCLE81-89, CYCLE60-79)
  share the prefix only.

Not markers, since mills write them too: U and W words (Fanuc lathes' incremental X and Z, but
additional axes named U V W parallel to X Y Z on a mill; LinuxCNC's U V W axes), four-digit T words
(T0101: a lathe's tool and offset, a mill's tool 101), G96/G97 (constant surface speed on mills
too; Sinumerik's LIMS with them, which limits G97's speed as well), G18, G33 and G76 (LinuxCNC
threads on mills with them; Fanuc mills' G76 is fine boring), G73-G75 (mills' drilling and tapping
cycles); Sinumerik's DIAMOF (a mill's reset may write it).  `G92 S_`, the maximum speed clamp of
Fanuc lathe G-code systems B and C (where system A writes G50 S; the Generic FANUC Turning post of
HSMWorks writes `G92 S` for its types B and C), is Fanuc's machining centres' clamp too: their G code
list names G92 "Setting for workpiece coordinate system or clamp at maximum spindle speed", the
constant surface speed control of the M series.  LinuxCNC's G8, "Lathe Radius Mode", is its
default, and mill configurations write it (`RS274NGC_STARTUP_CODE = G8 G17 G20 G90`, probing
scripts' `G17 G8 G21 G40 ...` reset).  A lathe program with none of the markers (LinuxCNC in
radius mode without its lathe cycles) cannot be told from a mill's program in G18.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from itertools import islice

from ncpp.errors import Location, NcppError
from ncpp.program.blocks import Block, ExprWord, Item, Statement, Word

# Blocks read before any goes on, as the interpreter's flow reads ahead (`motion/flow.py`)
HEAD = 4096
SCOPE = (
    "ncpp compensates milling programs (a machining centre's X Y Z) only; without a machine file the "
    "program passes through unchanged"
)
# What a lathe's G50 S is, where the motion interpreter meets it (`ncpp motion`, no machine file)
SPINDLE_LIMIT = "G50 with S, a lathe's spindle speed limit (a lathe program: ncpp reads milling programs),"

_FANUC_CYCLES = frozenset((70.0, 71.0, 72.0))
_LINUXCNC_CYCLES = frozenset((70.0, 71.0, 71.1, 71.2, 72.0, 72.1, 72.2))
_FANUC_CYCLE_WORDS = frozenset("PQ")  # the contour's first and last sequence numbers
_LINUXCNC_CYCLE_WORDS = frozenset("Q")  # the profile's subroutine
_DIAMETER_MODE = 7.0  # LinuxCNC's G7
_SPINDLE_LIMIT = 50.0  # G50 with S
_GRBL_UNSUPPORTED = (
    'is not a grbl 1.1 command (grbl stops at it with error 20, "Unsupported or invalid g-code command found '
    'in block")'
)
_TURNING = ": a turning program"  # (a lathe's, or a mill-turn program's turning part)
_TURN_MODE = ("FUNCTION", "MODE", "TURN")
_HEIDENHAIN_TURNING_CYCLES = frozenset((*range(810, 873), 882, 883))
_SINUMERIK_DIAMETER = frozenset(("DIAMON", "DIAM90"))
_SINUMERIK_TURNING_CYCLES = frozenset(
    (*(f"CYCLE{n}" for n in range(92, 100)), "CYCLE930", "CYCLE940", "CYCLE950", "CYCLE951", "CYCLE952")
)

# A block's lathe construct: the item that is it and what it is, as the refusal says it
Construct = tuple[Item, str]


@dataclass(frozen=True)
class _Rules:
    """The lathe constructs of one dialect of the ISO family (module docstring)."""

    cycles: frozenset[float]  # the G codes of its lathe cycles
    cycle_words: frozenset[str]  # the words that make them a lathe's
    diameter_mode: bool  # whether G7 is LinuxCNC's diameter mode
    grbl: bool = False  # grbl 1.1 has none of the codes: the refusal says so

    def construct(self, block: Block) -> Construct | None:
        """The block's lathe construct, or None."""
        signature = block.signature
        if block.verbatim or (signature is not None and "G5" not in signature and "G7" not in signature):
            return None  # (most blocks: no G5x or G7x code, G50 and G7-G72 among them)
        words = [item for item in block.items if type(item) is Word or type(item) is ExprWord]
        codes = [w for w in words if type(w) is Word and w.letter == "G"]
        letters = {w.letter for w in words}
        for code in codes:
            said = self._what(code.value, letters, codes)
            if said is not None:
                what, on_grbl = said
                what = f"{_GRBL_UNSUPPORTED}; {on_grbl}" if self.grbl else what
                return code, f"G{code.number} {what}: a lathe program"
        return None

    def _what(self, value: float, letters: set[str], codes: list[Word]) -> tuple[str, str] | None:
        """What the code is in this block, and what it is where grbl refuses it (it has none of them)."""
        if value == _DIAMETER_MODE and self.diameter_mode:
            return (
                "is LinuxCNC's lathe diameter mode (X words are diameters)",
                "in LinuxCNC it is the lathe diameter mode (X words are diameters)",
            )
        if value == _SPINDLE_LIMIT and "S" in letters:
            return (
                "with S is a lathe's spindle speed limit (a mill's G50 cancels scaling and takes no S)",
                "with S it is a lathe's spindle speed limit",
            )
        if value in self.cycles and self.cycle_words <= letters and not _drilling(codes):
            words = " and ".join(sorted(self.cycle_words))
            kind = "finishing" if value == 70.0 else "roughing"
            return (
                f"with {words} is a lathe's {kind} cycle",
                f"with {words} it is LinuxCNC's lathe {kind} cycle",
            )
        return None


def _drilling(codes: list[Word]) -> bool:
    """A drilling cycle's code (G73-G89) among the block's: a Haas mill's bolt-hole pattern may share it."""
    return any(73.0 <= code.value <= 89.0 and code.value != 80.0 for code in codes)


def _heidenhain(block: Block) -> Construct | None:
    """The Klartext block's turning construct: `FUNCTION MODE TURN` or a turning cycle's `CYCL DEF`."""
    if block.signature is not None:  # (words and comments only)
        return None
    for item in block.items:
        if type(item) is not Statement:
            continue
        if item.kind == "keyword" and tuple(w.upper() for w in item.node[:3]) == _TURN_MODE:
            return item, f"FUNCTION MODE TURN switches the TNC to turning (X words are diameters){_TURNING}"
        number = item.node[0] if item.kind == "cycle_def" else ""
        if number.isdigit() and int(number) in _HEIDENHAIN_TURNING_CYCLES:
            return item, f"CYCL DEF {number} is a turning cycle, run in turning mode only{_TURNING}"
    return None


def _sinumerik(block: Block) -> Construct | None:
    """The Sinumerik block's turning construct: diameter programming or a turning cycle's call."""
    if block.signature is not None:  # (words and comments only)
        return None
    for item in block.items:
        if type(item) is not Statement or item.kind != "call":
            continue
        name = item.node[0].upper()
        if name in _SINUMERIK_DIAMETER:
            return item, f"{name} is diameter programming (X words are diameters){_TURNING}"
        if name in _SINUMERIK_TURNING_CYCLES:
            return item, f"{name} is a turning cycle{_TURNING}"
    return None


RULES: dict[str, Callable[[Block], Construct | None]] = {
    "fanuc": _Rules(_FANUC_CYCLES, _FANUC_CYCLE_WORDS, diameter_mode=False).construct,
    "haas": _Rules(_FANUC_CYCLES, _FANUC_CYCLE_WORDS, diameter_mode=False).construct,
    "iso": _Rules(_LINUXCNC_CYCLES, _LINUXCNC_CYCLE_WORDS, diameter_mode=True).construct,
    "grbl": _Rules(_LINUXCNC_CYCLES, _LINUXCNC_CYCLE_WORDS, diameter_mode=True, grbl=True).construct,
    "heidenhain": _heidenhain,
    "sinumerik": _sinumerik,
}


def lathe_construct(block: Block, dialect: str) -> Construct | None:
    """The block's construct only a lathe (or turning) program of `dialect` has, with what it is, or None."""
    rules = RULES.get(dialect)
    return None if rules is None else rules(block)


def refuse_lathe(blocks: Iterable[Block], dialect: str, file: str) -> Iterator[Block]:
    """The blocks, after the first HEAD are looked at (none goes on before), each checked: a
    lathe construct stops the run with an error at its place.  It comes before the errors the
    interpreter would find in earlier lines, which are often a lathe's words read as a mill's
    (`G72 W1. R0.5`); a line the parser refuses before it comes first (nothing is read past it)."""
    rules = RULES.get(dialect)
    blocks = iter(blocks)
    if rules is None:
        yield from blocks
        return
    head: list[Block] = []
    fault: NcppError | None = None
    try:
        head.extend(islice(blocks, HEAD))  # (the blocks before a line the parser refuses stay)
    except NcppError as error:
        fault = error
    for block in head:
        _refuse(rules, block, file)
    yield from head
    head.clear()  # (not held while the rest streams)
    if fault is not None:  # (after the head's blocks: an earlier error of a later stage comes first)
        raise fault
    for block in blocks:
        _refuse(rules, block, file)
        yield block


def _refuse(rules: Callable[[Block], Construct | None], block: Block, file: str) -> None:
    found = rules(block)
    if found is not None:
        item, what = found
        raise NcppError(f"{what}, and {SCOPE}", Location(file, *block.place(item.start + 1)))
