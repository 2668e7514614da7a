"""What a block does besides moving: its actions, as text two programs can be compared by.

The verifier compares a program's motion between two actions (`ncpp.verify`); the interpreter
looks for one before a construct it may step back in front of (`ncpp.motion.entries`).
"""

from __future__ import annotations

from ncpp.program.blocks import Block, ExprWord, Statement, Word

# G codes whose block is an action: dwell, tool length offsets
ACTION_G = {4.0, 43.0, 43.1, 43.2, 49.0}
# Word letters that are actions wherever they stand: M functions, tools, spindle speed,
# length and radius offset numbers
ACTION_LETTERS = {"M", "T", "S", "H", "D"}
# M functions that act after the block's motion (RS274/NGC 3 "order of execution"; the
# Heidenhain and Sinumerik manuals place program stops and ends at the block's end too; Klartext's
# M99 calls its cycle where the block's move ends, and ends a subprogram after the move in ISO)
AFTER_MOTION = {0.0, 1.0, 2.0, 30.0, 60.0, 99.0}
# Statements that are actions: Klartext's TOOL CALL, CYCL CALL and END PGM
ACTION_STATEMENTS = {"tool_call", "cycle_call", "program_end"}


def actions_of(block: Block) -> tuple[list[str], list[str]]:
    """The actions of a block: (before its motion, after it), each as normalised text."""
    before: list[str] = []
    after: list[str] = []
    dwell = False
    for item in block.items:
        kind = type(item)
        if kind is Word or kind is ExprWord:
            letter = item.letter.upper()  # type: ignore[union-attr]
            value = item.value if kind is Word else None  # type: ignore[union-attr]
            if letter == "G" and value in ACTION_G:
                dwell |= value == 4.0
                before.append(f"G{value:g}")
            elif letter in ACTION_LETTERS:
                text = f"{letter}{value:g}" if value is not None else f"{letter}{block.source(item).upper()}"
                (after if letter == "M" and value in AFTER_MOTION else before).append(text)
        elif kind is Statement and item.kind in ACTION_STATEMENTS:  # type: ignore[union-attr]
            # (`CYCL CALL POS` runs its cycle where its own move ends, as M99 does)
            at_end = item.kind == "cycle_call" and item.node[0] == "POS"  # type: ignore[union-attr]
            (after if at_end else before).append("".join(block.source(item).upper().split()))
    if dwell:  # the dwell's time: P (ISO), F or S (Sinumerik); X would be an axis of the block's move
        before.extend(f"{w.letter.upper()}{w.value:g}" for w in block.words() if w.letter.upper() in "PFS")
    return before, after
