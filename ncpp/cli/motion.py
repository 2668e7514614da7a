"""`ncpp motion FILE [--format rs274|json]`: a program's motion as the interpreter reads it.

`--format rs274` (default) prints one line per move, exactly as LinuxCNC's
`rs274` prints its canonical motion calls (numbers `%.4f`, program units,
program coordinates):

    STRAIGHT_TRAVERSE(x, y, z, a, b, c)
    STRAIGHT_FEED(x, y, z, a, b, c)
    ARC_FEED(first_end, second_end, first_axis, second_axis, rotation, axis_end_point, a, b, c)
    RIGID_TAP(x, y, z)

Only these four calls are printed (no feed, unit, plane or spindle calls; nothing for a
rigid tap's return, as rs274 prints nothing for it), so the output compares line by line with
`rs274 FILE | grep -oE '(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|RIGID_TAP)\\(.*\\)'`.

`--format json` prints one JSON object per move (JSON Lines): source line,
kind (traverse / feed / arc / rigid tap / rigid tap return), start, end, centre and turn of
arcs, feed, plane, inch, the work offset (machine minus program position), the tool length
offset, why compensation leaves a move as programmed or writes it its own way ("fixed": a
canned cycle, a drilling cycle, a hole pattern, a loop or subroutine, cutter compensation, a
G28/G30 return, a machine-coordinate move, a Fanuc or Haas move before the program names G00-G03),
where it does, and under cutter compensation that
ncpp follows where the tool centre stands off the move's start and end ("centre_shift").
Under a rotation of the coordinate system (LinuxCNC's G10 L2 R, Fanuc's and Haas's G68) a
record's points are where the control turns the program's to (machine position minus "offset"),
and "rotation" gives the turn: degrees counter-clockwise and its centre's coordinates in program
coordinates, in the plane "rotation_plane" says (17: X Y; G68 in 18: Z X, in 19: Y Z, the plane's
first axis first); under Fanuc's mirror image (G51.1) they are where the control mirrors them to, an
arc's "turn" the way it runs there, and "mirror" gives each mirrored axis the coordinate it is mirrored
about; `--format rs274` prints the program's own coordinates, as rs274 does.

`--var-file linuxcnc.var` / `--work-offset [G5x=]X,Y,Z` start the
interpreter from the control's zeros, as `rs274 -v FILE` does (default: all
zero, rs274's default parameter file), and `--tool-table` from its tool
table (`rs274 -t`).  Heidenhain and Sinumerik programs print the same records (`--dialect`, or
detected from the content).

Under cutter compensation (G41/G42 or RL/RR, to the first move after G40 or R0) that ncpp
follows (the radius known: G41.1/G42.1's D, or the `--tool-table`'s; see the guide) `--format
rs274` prints where the tool centre runs, as rs274 does: each move offset by the radius, an arc
about an outside corner, moves cut back to where they cross at an inside one (an entry arc, which
rs274 bends to a centre of its own, keeps its programmed centre).  Where ncpp does not follow it (the
radius unknown, the moves of a loop or a cycle), and in `--format json`, the moves are the programmed
contour, the JSON records with where the tool centre stands off their ends ("centre_shift"); a
warning names the line where each such series starts (`--strict` refuses it).
"""

from __future__ import annotations

import argparse
from collections.abc import Iterable, Iterator

from ncpp.cli.compensate import add_placement_arguments, work_offsets
from ncpp.cli.io import add_dialect_argument
from ncpp.errors import Location, Warnings
from ncpp.motion.segments import COMP, TAP_IN, Arc, Event, Line


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "motion",
        help="print a program's motion as rs274 canonical calls or JSON lines",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("input", nargs="?", metavar="FILE", help="NC program (default: standard input)")
    parser.add_argument("--format", choices=("rs274", "json"), default="rs274")
    parser.add_argument(
        "--strict", action="store_true", help="refuse constructs outside the interpreter's scope"
    )
    add_dialect_argument(parser)
    add_placement_arguments(parser)
    parser.set_defaults(func=run)


def interpreted(
    stream, name: str, dialect: str | None, warnings: Warnings, offsets
) -> tuple[str, Iterable[Event]]:
    """A program's dialect and its motion events as the interpreter reads it (the guards of a
    compensated program left out: they move nothing)."""
    from ncpp.guard import without_guard
    from ncpp.pipeline import dialect_tools
    from ncpp.program.dialects import parse_program

    found, blocks = parse_program(stream, name, dialect)
    interpret, _ = dialect_tools(found)
    return found, interpret(without_guard(blocks), file=name, warnings=warnings, offsets=offsets)


def run(args: argparse.Namespace) -> int:
    import json
    import sys

    from ncpp.cli.io import open_input
    from ncpp.motion.canon import format_event
    from ncpp.motion.centre_path import on_centre

    warnings = Warnings(strict=args.strict)
    offsets = (
        work_offsets(args)
        if args.work_offset or args.var_file or args.tool_table or args.subroutine_path
        else None
    )
    out = sys.stdout
    with open_input(args.input) as (stream, name):
        _, events = interpreted(stream, name, args.dialect, warnings, offsets)
        if args.format == "rs274":  # (under cutter compensation ncpp follows: the tool centre's moves)
            events = on_centre(events)
        for event in warn_off_path(
            events,
            warnings,
            name,
            "printed as programmed (rs274 prints the tool centre, offset by the radius)",
            followed=args.format == "rs274",
        ):
            if type(event) is not Line and type(event) is not Arc:
                continue
            if args.format == "rs274":
                text = format_event(event)
                if text is not None:  # (None: a rigid tap's return, which rs274 does not print)
                    out.write(text + "\n")
                continue
            record: dict[str, object] = {
                "line": event.block.line,
                "kind": "arc" if type(event) is Arc else ("traverse" if event.rapid else "feed"),
                "start": event.start,
                "end": event.end,
                "feed": event.feed,
                "plane": event.context.plane,
                "inch": event.context.inch,
                "offset": event.context.offset,
                "tool": event.context.tool,
            }
            if type(event) is Arc:
                record["center"] = event.center
                record["turn"] = event.turn
            if event.extra:
                record["extra"] = event.extra
            if event.context.rotation is not None:  # (the points are in the turned frame)
                record["rotation"] = event.context.rotation
                record["rotation_plane"] = event.context.rotation_plane
            if event.context.mirror:  # (the points, and an arc's turn, are in the mirrored frame)
                record["mirror"] = {"XYZ"[axis]: centre for axis, centre in event.context.mirror}
            if (
                event.fixed
            ):  # why compensation leaves it as programmed (a canned cycle, cutter compensation, ...)
                record["fixed"] = event.fixed
            if event.centre_shift is not None:  # under cutter compensation ncpp follows
                record["centre_shift"] = event.centre_shift
            if type(event) is Line and event.tap:  # a rigid tap's (G33.1) tap or return
                record["kind"] = "rigid tap" if event.tap == TAP_IN else "rigid tap return"
            out.write(json.dumps(record) + "\n")
    warnings.finish()
    return 0


def warn_off_path(
    events: Iterable[Event], warnings: Warnings, file: str, consequence: str, followed: bool = False
) -> Iterator[Event]:
    """Pass events through; warn where a series of moves under cutter compensation starts
    (`COMP`: the tool centre is off the programmed contour), saying `consequence`; `followed`: but
    for the moves whose tool centre is followed (`centre_shift`), which are given where it runs."""
    off = False
    for event in events:
        if (type(event) is Line or type(event) is Arc) and _off_path(event, followed) != off:
            off = not off
            if off:
                warnings.warn(f"cutter compensation: up to the first move after it is off (G40, R0) the tool centre is off the programmed contour; its moves are {consequence}",
                              Location(file, event.block.line, 1))  # fmt: skip
        yield event


def _off_path(move: Line | Arc, followed: bool) -> bool:
    """Whether a move is under cutter compensation and given as programmed: left so (`COMP`), or
    followed (`centre_shift`) but not `followed` here, or with its radius unknown (no shift at all)."""
    shift = move.centre_shift
    if shift is None:
        return move.fixed == COMP
    return not followed or not (any(shift[1]) or any(shift[0] or ()))
