"""Pass: moves that turn a rotary axis (A, B, C), whose kinematics ncpp does not model.

ncpp's error model is the three linear axes'.  The programmed X Y Z are those axes'
positions unless the control runs tool-centre-point kinematics (LinuxCNC G43.4/G43.5 or
a kinematics a user M code switches on, Heidenhain M128 / FUNCTION TCPM, Sinumerik
TRAORI), where they are the tool tip's in the turned workpiece and the linear axes go
elsewhere.  So a move to be compensated that turns A, B or C is compensated only where
the machine file says the programmed X Y Z are axis positions (`[compensation]
rotary_xyz_are_axis_positions = true`), else refused; the pieces it is split into each
turn their share (`share_rotation`).  A tool-centre-point mode, which the interpreters
leave as out of their scope, is refused when compensating, and so is an arc that turns
a rotary axis (its pieces would not be given their share).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator
from itertools import chain

from ncpp.errors import Location, NcppError
from ncpp.motion.segments import EXTRA_AXES, PLANE_AXES, Arc, Event, Line, Pass
from ncpp.passes.context import PassContext
from ncpp.passes.geometry import chunked
from ncpp.program.blocks import Block, Statement, Word

ROTARY = "ABC"
# Klartext's FUNCTION TCPM, Sinumerik's TRAORI (their statements' first two parts), by name
_TCP_STATEMENTS = ((("FUNCTION", "TCPM"), "FUNCTION TCPM"), (("TRAORI", ()), "TRAORI"))
# The least part of a G93 move's time a piece of it is given (a µm reversal step): its F stays finite
LEAST_SHARE = 1e-4


def refuse_rotary(events: Iterable[Event], ctx: PassContext) -> Iterator[Event]:
    """The events; refuses a tool-centre-point mode, an arc that turns a rotary axis, and a move
    that does on a machine whose file does not say its X Y Z are axis positions."""
    return chain.from_iterable(_lists(events, ctx))  # a chunk at a time, handed on in C


def _lists(events: Iterable[Event], ctx: PassContext) -> Iterator[list[Event]]:
    for chunk in chunked(events):
        yield from _checked(chunk, ctx)


def _checked(chunk: list[Event], ctx: PassContext) -> Iterator[list[Event]]:
    """The chunk, or its events before the first it refuses, then the refusal."""
    allowed = ctx.rotary_xyz_are_axis_positions
    for k, event in enumerate(chunk):
        kind = type(event)
        try:
            if kind is Line or kind is Arc:
                if ctx.kinematics_m_codes:  # (a move's block may switch them too: only looked at where told)
                    _refuse_tool_centre_point(event.block, ctx.file, ctx.kinematics_m_codes)
                if event.extra_start and not event.fixed and event.extra[:3] != event.extra_start[:3]:  # type: ignore[union-attr]
                    if kind is Arc or not allowed:
                        _refuse_turn(event, kind is Arc, ctx.file)  # type: ignore[arg-type]
            elif kind is Pass:
                _refuse_tool_centre_point(event.block, ctx.file, ctx.kinematics_m_codes)
        except NcppError:
            yield chunk[:k]
            raise
    yield chunk


def _refuse_turn(move: Line | Arc, arc: bool, file: str) -> None:
    turned = [letter for letter, a, b in zip(ROTARY, move.extra_start, move.extra) if a != b]
    word = next(
        (i for i in move.block.items if type(i) is not Statement and getattr(i, "letter", None) in turned),
        None,
    )
    where = Location(file, move.block.line, 1 if word is None else word.start + 1)
    what = " and ".join(turned)
    if arc:
        raise NcppError(f"this arc turns {what}: ncpp compensates arcs of the linear axes only "
                        "(it would not give each piece of the arc its share of the rotation)", where)  # fmt: skip
    raise NcppError(
        f"this move turns {what}, and ncpp models the linear axes only: it compensates such moves where the "
        "machine file says the programmed X Y Z are the linear axes' positions (no tool-centre-point "
        "kinematics): [compensation] rotary_xyz_are_axis_positions = true",
        where,
    )


def _refuse_tool_centre_point(block: Block, file: str, kinematics: tuple[int, ...] = ()) -> None:
    """G43.4 / G43.5 (LinuxCNC), M128 and FUNCTION TCPM (Heidenhain), TRAORI (Sinumerik), and the
    M codes the machine file says switch the control's kinematics (a LinuxCNC remap, as M428)."""
    name: str | None
    for item in block.items:
        kind = type(item)
        if kind is Word:
            code = (item.letter, item.value)  # type: ignore[union-attr]
            if code not in (("G", 43.4), ("G", 43.5), ("M", 128.0)) and not (
                code[0] == "M" and code[1] in kinematics
            ):
                continue
            name = f"{item.letter}{item.value:g}"  # type: ignore[union-attr]
        elif kind is Statement and item.node and item.node[0] in ("FUNCTION", "TRAORI"):  # type: ignore[union-attr]
            name = next((name for key, name in _TCP_STATEMENTS if item.node[:2] == key), None)  # type: ignore[union-attr]
            if name is None:
                continue
        else:
            continue
        raise NcppError(f"{name} turns tool-centre-point control on: the programmed X Y Z are then the tool tip's, "
                        "not the linear axes' positions, and ncpp does not model the rotary axes' kinematics; "
                        "such a program cannot be compensated", Location(file, block.line, item.start + 1))  # fmt: skip


def interpolated(start: tuple[float, ...], end: tuple[float, ...], t: float) -> tuple[float, ...]:
    """The positions of the axes beyond X Y Z (`Line.extra`) a part `t` of the way from `start` to `end`."""
    if t >= 1.0:
        return end
    return tuple(a + (b - a) * t for a, b in zip(start, end))


def turns(move: Line | Arc) -> bool:
    """Whether the move moves an axis beyond X Y Z (a rotary axis, U V W) as far as it says
    (a piece made without `extra_start` says nothing)."""
    return bool(move.extra_start) and move.extra != move.extra_start


def time_shares(pieces: list[Line | Arc]) -> list[float]:
    """The part of one move's time each of its pieces takes (G93: the control runs the move at one
    speed along its path): by their lengths, or where the linear axes hardly move, by how far
    the other axes turn; each at least LEAST_SHARE."""
    lengths = [_length(p) for p in pieces]
    if sum(lengths) < 1e-6:
        lengths = [
            sum(abs(b - a) for a, b in zip(p.extra_start, p.extra)) if turns(p) else 0.0 for p in pieces
        ]
    total = sum(lengths)
    shares = [max(length / total, LEAST_SHARE) if total > 0 else 1.0 for length in lengths]
    scale = sum(shares)
    return [share / scale for share in shares]


def _length(piece: Line | Arc) -> float:
    if type(piece) is Line:
        return piece.length()
    a, b, n = PLANE_AXES[piece.context.plane]
    return math.hypot(piece.radius() * piece.sweep(), piece.end[n] - piece.start[n])


__all__ = ["EXTRA_AXES", "interpolated", "refuse_rotary", "time_shares", "turns"]
