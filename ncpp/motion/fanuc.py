"""Fanuc and Haas: where their reading of G code differs from LinuxCNC's.

The ISO interpreter (`interpreter.py`) already reads what Fanuc and LinuxCNC share, Fanuc's
corner rounding and M98/M99 subprograms among it.  These flavours add the settings that
Fanuc and Haas posts write on lines of their own and that move no axis, where LinuxCNC
reads the same codes otherwise (G5.1 is a spline there, G8 lathe radius mode):

* Fanuc (0i-MF / 30i operator's manuals): `G05.1 Q1` / `Q0`, AI contour control on and off;
  `G08 P1` / `P0`, advanced preview control on and off.  `G54.1 P1`-`P48` selects an
  additional work offset, whose zero ncpp is not told: it ends interpretation with a warning.
* Haas (Mill Operator's Manual, "G-codes"): also `G187 P1-P3 [E..]`, the smoothness level and
  corner tolerance; `G103 P..`, the limit of blocks looked ahead.  `G154 P1-P99` selects one
  of Haas's additional work offsets, whose zero ncpp is not told, and `M97 P..` runs a local
  subprogram at a sequence number: both end interpretation with a warning.

A setting code written with other words in its block is out of scope too: a block that
both sets and moves is not one these controls' posts write.
"""

from __future__ import annotations

from ncpp.motion.interpreter import Interpreter, _OutOfScope, interpreting
from ncpp.motion.segments import Event, Pass
from ncpp.program.blocks import Block, Comment, Word

# G code -> the words it takes, for the settings each flavour reads past
FANUC_SETTINGS: dict[float, frozenset[str]] = {5.1: frozenset("Q"), 8.0: frozenset("P")}
HAAS_SETTINGS = {**FANUC_SETTINGS, 187.0: frozenset("PE"), 103.0: frozenset("P")}
# Codes of the flavour that need what ncpp is not told (a zero, a sequence number's block):
# Fanuc's additional work offsets `G54.1 P1`-`P48`, Haas's `G154 P1`-`P99`
FANUC_UNFOLLOWED = {("G", 54.1): "G54.1 (an additional work offset ncpp is not told)"}
HAAS_UNFOLLOWED = {**FANUC_UNFOLLOWED, ("G", 154.0): "G154 (an additional work offset ncpp is not told)",
                   ("M", 97.0): "M97 (a local subprogram at a sequence number)"}  # fmt: skip


class FanucInterpreter(Interpreter):
    settings: dict[float, frozenset[str]] = FANUC_SETTINGS
    unfollowed: dict[tuple[str, float], str] = FANUC_UNFOLLOWED
    rigid_tapping = False  # (Fanuc taps rigidly with M29 and G84: G33.1 is LinuxCNC's)

    def block(self, block: Block) -> Event | tuple[Event, ...]:
        signature = block.signature
        if signature is not None and "G" not in signature and "M" not in signature:
            return super().block(block)  # axis words only (the most): no setting, nothing unfollowed
        words = [item for item in block.items if type(item) is Word]
        for word in words:
            reason = self.unfollowed.get((word.letter, word.value))
            if reason is not None:
                raise _OutOfScope(reason, word.start + 1)
        setting = next((w for w in words if w.letter == "G" and w.value in self.settings), None)
        if setting is None:
            return super().block(block)
        allowed = self.settings[setting.value] | {"N"}
        if any(type(item) is not Comment and item is not setting and not (type(item) is Word and item.letter in allowed)
               for item in block.items):  # fmt: skip
            raise _OutOfScope(f"G{setting.number} with other words in its block", setting.start + 1)
        return Pass(block)


class HaasInterpreter(FanucInterpreter):
    settings = HAAS_SETTINGS
    unfollowed = HAAS_UNFOLLOWED


interpret = interpreting(FanucInterpreter)
interpret_haas = interpreting(HaasInterpreter)
