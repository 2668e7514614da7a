"""rs274's canonical-call text for motion events, and a reader for rs274's output.

LinuxCNC's stand-alone interpreter (`rs274 -g FILE`) prints one canonical
call per line, numbers as `%.4f`, positions in program coordinates and
program units:

    STRAIGHT_TRAVERSE(x, y, z, a, b, c)
    STRAIGHT_FEED(x, y, z, a, b, c)
    ARC_FEED(first_end, second_end, first_axis, second_axis, rotation, axis_end_point, a, b, c)
    RIGID_TAP(x, y, z)

(rs274 prints no call for a rigid tap's return to its start: neither does `format_event`.)

`format_event` prints a `Line` or `Arc` the same way (None for a `Pass`), so
`ncpp motion FILE --format rs274` can be compared with
`rs274 FILE | grep -oE '(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|RIGID_TAP)\\(.*\\)'`
line by line.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from ncpp.motion.segments import PLANE_AXES, TAP_IN, Arc, Event, Line

MOTION_CALLS = ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED", "ARC_FEED", "RIGID_TAP")
_CALL = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|RIGID_TAP)\(([^)]*)\)")


def _rotary(extra: tuple[float, ...]) -> tuple[float, float, float]:
    return (extra[0], extra[1], extra[2]) if extra else (0.0, 0.0, 0.0)


@dataclass(frozen=True, slots=True)
class CanonCall:
    """One motion call read from rs274 output (or from `format_event`)."""

    name: str
    args: tuple[float, ...]

    @property
    def end(self) -> tuple[float, ...]:
        """The end point as rs274 orders it (x y z for lines; first, second, normal for arcs)."""
        if self.name == "ARC_FEED":
            return (self.args[0], self.args[1], self.args[5])
        return self.args[:3]

    @property
    def center(self) -> tuple[float, float] | None:
        return (self.args[2], self.args[3]) if self.name == "ARC_FEED" else None

    @property
    def rotation(self) -> int | None:
        return int(self.args[4]) if self.name == "ARC_FEED" else None


def read_canon(text: str) -> list[CanonCall]:
    """The motion calls of rs274 output (other calls and messages are skipped)."""
    calls = []
    for m in _CALL.finditer(text):
        calls.append(CanonCall(m.group(1), tuple(float(v) for v in m.group(2).split(","))))
    return calls


def canon_call(event: Event) -> CanonCall | None:
    """The rs274 canonical call of a motion event, at full precision; None for a Pass (and for a
    rigid tap's return).  Under a rotation of the coordinate system or a mirror image its points are the
    program's, as rs274 prints them (the control turns them: `Context.turned`)."""
    if type(event) is Line:
        end = event.context.turned(event.end, -1.0)
        if event.tap:
            return CanonCall("RIGID_TAP", end) if event.tap == TAP_IN else None
        return CanonCall(
            "STRAIGHT_TRAVERSE" if event.rapid else "STRAIGHT_FEED", (*end, *_rotary(event.extra))
        )
    if type(event) is Arc:
        a, b, n = PLANE_AXES[event.context.plane]
        e, c = event.context.turned(event.end, -1.0), event.context.turned(event.center, -1.0)
        turn = -event.turn if event.context.reverses else event.turn  # (as the program turns it)
        return CanonCall("ARC_FEED", (e[a], e[b], c[a], c[b], float(turn), e[n], *_rotary(event.extra)))
    return None


def format_event(event: Event) -> str | None:
    """The rs274 text of a motion event (`%.4f` numbers, integer rotation); None for a Pass."""
    call = canon_call(event)
    if call is None:
        return None
    values = [f"{v:.4f}" for v in call.args]
    if call.name == "ARC_FEED":
        values[4] = str(int(call.args[4]))
    return f"{call.name}({', '.join(values)})"
