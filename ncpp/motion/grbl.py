"""grbl 1.1: where its reading of G code differs from LinuxCNC's.

grbl reads a subset of rs274ngc (its wiki page "G-code commands" and `grbl/gcode.c`,
`gc_execute_line`); the differences a program meets are rules of `GrblInterpreter`:

* an arc in offset mode takes I, J and K whatever the plane, and uses the plane's two
  (`gc_execute_line`, "Arc Center Format Offset Mode": all of I J K are cleared as used),
  so FreeCAD's grbl post writes `G2 X.. Y.. I.. J.. K0.000` in G17;
* a line that starts with `$` is a system command for grbl's own settings and states
  (`protocol.c` hands it to `system_execute_line`, never to the G-code parser): it passes
  through untouched; `$H` (homing) and `$J=` (jogging) move the machine where ncpp does not
  follow, so the state is unknown from there, as with any construct out of scope;
* G33.1, LinuxCNC's rigid tap, is out of scope: grbl has no spindle-synchronised motion;
* the parser starts in G0 (`gcode.h`: "MOTION_MODE_SEEK 0 // G0 (Default: Must be zero)", the state
  `gc_init` clears), so axis words before any motion code are a rapid, where rs274ngc refuses them;
* M2 and M30 end no reading: they reset the modes of groups 1, 2, 3, 5, 7 and 12 and stop the
  spindle and coolant, and grbl runs the lines a sender streams after them (`gc_execute_line`,
  "[21. Program flow]": the resets, then `program_flow = PROGRAM_FLOW_RUNNING`), so a file of
  several jobs one after another is compensated to its end;
* grbl reads no tape marks (`protocol.c`: "Program start-end percent sign NOT SUPPORTED"; its
  parser answers a `%` line with error 1 and changes nothing): a `%` line passes through, and
  the lines after a second one run as any others (the dialect's `tape_marks`);
* `?`, `~` and `!` are realtime commands (status report, cycle start, feed hold) that grbl
  picks out of the stream as they arrive (`serial.c`), never G code: a line of them
  passes through untouched.
"""

from __future__ import annotations

import re

from ncpp.motion.interpreter import Interpreter, _OutOfScope, interpreting
from ncpp.motion.segments import Event, Pass
from ncpp.program.blocks import STRAY_TAPE, Block, Statement

# A line of realtime commands, perhaps with a comment
_REALTIME = re.compile(r"[?~!]+[ \t]*(;.*|\(.*)?\r?\n?$")
# grbl's system commands that move the machine
_MOVING = {"$H": "grbl homing ($H)", "$J=": "a grbl jog ($J=)"}


class GrblInterpreter(Interpreter):
    arc_normal_offset_ignored = True
    rigid_tapping = False  # (grbl has no spindle-synchronised motion)
    rotating_g10 = False  # (grbl's G10 L2 takes no R)
    tool_table_g10 = False  # (grbl has no tool table: G43.1 gives the offset itself)
    start_motion = 0.0  # (grbl's parser starts in G0)

    def _program_end(self) -> None:
        """M2/M30: rs274ngc's resets (G1 G17 G90 G94 G40 G54), the spindle stopped, and read on."""
        super()._program_end()
        self.spindle = 0
        self.done = self.ended = False

    def block(self, block: Block) -> Event | tuple[Event, ...]:
        signature = block.signature
        if signature is not None and signature[:1] != "$":  # a plain block (the most): G code
            return super().block(block)
        text = block.text.lstrip()
        if _REALTIME.match(text) or _stray_tape_mark(block):
            return Pass(block)
        if text.startswith("$"):
            for start, what in _MOVING.items():
                if text[: len(start)].upper() == start:
                    raise _OutOfScope(f"{what}, a move ncpp cannot follow", 1)
            return Pass(block)
        return super().block(block)


def _stray_tape_mark(block: Block) -> bool:
    return bool(block.items) and type(block.items[0]) is Statement and block.items[0].kind == STRAY_TAPE


interpret = interpreting(GrblInterpreter)
