"""`ncpp motion FILE [--format rs274|json]`: a program's motion as the interpreter reads it.

`--format rs274` (default) prints one line per move, exactly as LinuxCNC's
`rs274` prints its canonical motion calls (numbers `%.4f`, program units,
program coordinates):

    STRAIGHT_TRAVERSE(x, y, z, a, b, c)
    STRAIGHT_FEED(x, y, z, a, b, c)
    ARC_FEED(first_end, second_end, first_axis, second_axis, rotation, axis_end_point, a, b, c)

Only these three calls are printed (no feed, unit, plane or spindle calls),
so the output compares line by line with
`rs274 FILE | grep -oE '(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED)\\(.*\\)'`.

`--format json` prints one JSON object per move (JSON Lines): source line,
kind (traverse / feed / arc), start, end, centre and turn of arcs, feed,
plane, inch, and the work offset (machine minus program position).

`--var-file linuxcnc.var` / `--work-offset [G5x=]X,Y,Z` start the
interpreter from the control's zeros, as `rs274 -v FILE` does (default: all
zero, rs274's default parameter file), and `--tool-table` from its tool
table (`rs274 -t`); the JSON records carry the tool length offset too.
Heidenhain and Sinumerik programs print the same records (`--dialect`, or
detected from the content).
"""

from __future__ import annotations

import argparse

from ncpp.cli.compensate import add_placement_arguments, work_offsets
from ncpp.cli.io import add_dialect_argument


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "motion",
        help="print a program's motion as rs274 canonical calls or JSON lines",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("input", nargs="?", metavar="FILE", help="NC program (default: standard input)")
    parser.add_argument("--format", choices=("rs274", "json"), default="rs274")
    parser.add_argument("--strict", action="store_true", help="refuse constructs outside the interpreter's scope")
    add_dialect_argument(parser)
    add_placement_arguments(parser)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import json
    import sys

    from ncpp.cli.io import open_input
    from ncpp.errors import Warnings
    from ncpp.motion.canon import format_event
    from ncpp.motion.segments import Arc, Line
    from ncpp.pipeline import dialect_tools
    from ncpp.program.dialects import parse_program

    warnings = Warnings(strict=args.strict)
    offsets = work_offsets(args) if args.work_offset or args.var_file or args.tool_table or args.subroutine_path else None
    out = sys.stdout
    with open_input(args.input) as (stream, name):
        dialect, blocks = parse_program(stream, name, args.dialect)
        interpret, _ = dialect_tools(dialect)
        for event in interpret(blocks, file=name, warnings=warnings, offsets=offsets):
            if type(event) is not Line and type(event) is not Arc:
                continue
            if args.format == "rs274":
                out.write(format_event(event) + "\n")
                continue
            record = {
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
            out.write(json.dumps(record) + "\n")
    warnings.finish()
    return 0
