"""Lathe programs in the ISO family: refused when ncpp is to compensate them.

ncpp's machine model is a machining centre's X Y Z.  A lathe program's X is a diameter (Fanuc
and Haas lathes, LinuxCNC in G7) along the cross slide and its Z the spindle axis, so the
corrections of a mill's axes would be applied to the wrong machine: the program is refused before
any block goes on (`refuse_lathe`), at the first construct only a lathe program has.  Without a
machine file nothing is read and a lathe program passes through unchanged, as every program does.

The constructs, each one a mill program of the same dialect does not write:

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
* LinuxCNC (and grbl, read with LinuxCNC's grammar; grbl 1.1 has none of these codes): G7, "Lathe
  Diameter Mode", which "enter[s] the diameter mode for axis X on a lathe"; G70, G71, G72 and
  their .1/.2 forms with a Q (the subroutine with the profile), the "Lathe finishing cycle" and
  "Lathe roughing cycles", an error unless the ZX plane is selected (LinuxCNC G-code manual).  The
  Q tells them from the inch/metric G70/G71 of other controls' ISO programs.

Not markers, since mills write them too: U and W words (Fanuc lathes' incremental X and Z, but
additional axes named U V W parallel to X Y Z on a mill; LinuxCNC's U V W axes), four-digit T words
(T0101: a lathe's tool and offset, a mill's tool 101), G96/G97 (constant surface speed on mills
too), G18, G33 and G76 (LinuxCNC threads on mills with them; Fanuc mills' G76 is fine boring),
G73-G75 (mills' drilling and tapping cycles).  A lathe program with none of the markers (LinuxCNC
in radius mode, G8, without its lathe cycles) cannot be told from a mill's program in G18.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator
from dataclasses import dataclass
from itertools import islice

from ncpp.errors import Location, NcppError
from ncpp.program.blocks import Block, ExprWord, Word

# Blocks read before any goes on, as the interpreter's flow reads ahead (`motion/flow.py`)
HEAD = 4096
SCOPE = (
    "ncpp compensates milling programs (a machining centre's X Y Z) only; without a machine file the "
    "program passes through unchanged"
)

_FANUC_CYCLES = frozenset((70.0, 71.0, 72.0))
_LINUXCNC_CYCLES = frozenset((70.0, 71.0, 71.1, 71.2, 72.0, 72.1, 72.2))
_FANUC_CYCLE_WORDS = frozenset("PQ")  # the contour's first and last sequence numbers
_LINUXCNC_CYCLE_WORDS = frozenset("Q")  # the profile's subroutine
_DIAMETER_MODE = 7.0  # LinuxCNC's G7
_SPINDLE_LIMIT = 50.0  # G50 with S


@dataclass(frozen=True)
class _Rules:
    """The lathe constructs of one dialect (module docstring)."""

    cycles: frozenset[float]  # the G codes of its lathe cycles
    cycle_words: frozenset[str]  # the words that make them a lathe's
    diameter_mode: bool  # whether G7 is LinuxCNC's diameter mode

    def construct(self, block: Block) -> tuple[Word, str] | None:
        """The block's lathe construct (its G word and what it is), or None."""
        signature = block.signature
        if block.verbatim or (signature is not None and "G5" not in signature and "G7" not in signature):
            return None  # (most blocks: no G5x or G7x code, G50 and G7-G72 among them)
        words = [item for item in block.items if type(item) is Word or type(item) is ExprWord]
        codes = [w for w in words if type(w) is Word and w.letter == "G"]
        letters = {w.letter for w in words}
        for code in codes:
            value = code.value
            if value == _DIAMETER_MODE and self.diameter_mode:
                return code, "is LinuxCNC's lathe diameter mode (X words are diameters)"
            if value == _SPINDLE_LIMIT and "S" in letters:
                return (
                    code,
                    "with S is a lathe's spindle speed limit (a mill's G50 cancels scaling and takes no S)",
                )
            if value in self.cycles and self.cycle_words <= letters and not _drilling(codes):
                said = " and ".join(sorted(self.cycle_words))
                return code, f"with {said} is a lathe's {'finishing' if value == 70.0 else 'roughing'} cycle"
        return None


def _drilling(codes: list[Word]) -> bool:
    """A drilling cycle's code (G73-G89) among the block's: a Haas mill's bolt-hole pattern may share it."""
    return any(73.0 <= code.value <= 89.0 and code.value != 80.0 for code in codes)


RULES = {
    "fanuc": _Rules(_FANUC_CYCLES, _FANUC_CYCLE_WORDS, diameter_mode=False),
    "haas": _Rules(_FANUC_CYCLES, _FANUC_CYCLE_WORDS, diameter_mode=False),
    "iso": _Rules(_LINUXCNC_CYCLES, _LINUXCNC_CYCLE_WORDS, diameter_mode=True),
    "grbl": _Rules(_LINUXCNC_CYCLES, _LINUXCNC_CYCLE_WORDS, diameter_mode=True),
}


def lathe_construct(block: Block, dialect: str) -> tuple[Word, str] | None:
    """The block's construct only a lathe program of `dialect` has, with what it is, or None."""
    rules = RULES.get(dialect)
    return None if rules is None else rules.construct(block)


def refuse_lathe(blocks: Iterable[Block], dialect: str, file: str) -> Iterator[Block]:
    """The blocks, after the first HEAD are looked at (none goes on before), each checked: a
    lathe construct stops the run with an error at its G word.  It comes before the errors the
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


def _refuse(rules: _Rules, block: Block, file: str) -> None:
    found = rules.construct(block)
    if found is not None:
        code, what = found
        raise NcppError(f"G{code.number} {what}: a lathe program, and {SCOPE}",
                        Location(file, block.line, code.start + 1))  # fmt: skip
