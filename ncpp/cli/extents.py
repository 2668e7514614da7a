"""`ncpp extents FILE [--machine M.toml] [--work-offset ...] [--format text|json]`.

The box a program's moves sweep.

Prints the lowest and highest X, Y, Z the program's moves reach, for the whole
program, per work coordinate system (G54-G59.3; Heidenhain and Sinumerik
programs have one program zero) and per tool (the tool in the spindle: T with
M6, TOOL CALL).  Feed and rapid moves both count; arcs count by their true
extent (the quadrant points they pass), not only their end points.  A move
counts from the point it goes to: where the tool stands when the program
starts is not known (the interpreter starts at 0,0,0, as rs274 does).

Each box is given in program coordinates (mm) and, where the zero the control
holds is known (`--work-offset`, `--var-file`, or the program's own `G10 L2 P..
X.. Y.. Z..`, which wins over them), in machine axis positions (mm, with the
tool length in effect from `--tool-table`).  With `--machine M.toml`
each machine box is compared with the machine's [limits]: per axis it fits, or
it leaves the travel by so many mm at an end.  Try another `--work-offset`
until it fits.
"""

from __future__ import annotations

import argparse
import json
import sys

from ncpp.cli.compensate import add_placement_arguments, work_offsets
from ncpp.cli.io import add_dialect_argument
from ncpp.errors import Warnings
from ncpp.motion.extents import Extent, extents, fit_in_travel
from ncpp.program.dialects import FAMILY

MOVES = "feed and rapid moves, arcs by their true extent"


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "extents",
        help="the box a program's moves sweep, per work offset and tool, and whether it fits the machine",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("input", nargs="?", metavar="FILE", help="NC program (default: standard input)")
    parser.add_argument(
        "--machine", metavar="M.toml", help="machine file whose [limits] the boxes are checked against"
    )
    parser.add_argument("--format", choices=("text", "json"), default="text")
    parser.add_argument(
        "--strict", action="store_true", help="refuse constructs outside the interpreter's scope"
    )
    add_dialect_argument(parser)
    add_placement_arguments(parser)
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ncpp.cli.io import open_input
    from ncpp.cli.motion import interpreted, warn_off_path
    from ncpp.motion.offsets import system_name

    limits = None
    if args.machine:
        from ncpp.machine import load_machine

        limits = load_machine(args.machine).limits
    placed = bool(args.work_offset or args.var_file)  # the zeros are known: machine positions can be said
    offsets = work_offsets(args) if placed or args.tool_table or args.subroutine_path else None
    warnings = Warnings(strict=args.strict)
    with open_input(args.input) as (stream, name):
        dialect, moves = interpreted(stream, name, args.dialect, warnings, offsets)
        events = warn_off_path(
            moves, warnings, name, "counted as programmed (the tool centre is off them by the radius)"
        )
        known = offsets if placed else None  # the zeros the control holds, where the user told them
        if FAMILY[dialect] == "iso":
            found = extents(events, lambda c: known is not None and known.told(c.system),
                            lambda c: system_name(c.system, dialect))  # fmt: skip
        else:  # one program zero: the system in effect when the program starts
            found = extents(
                events, lambda c: known is not None and known.told(known.active), lambda c: "program zero"
            )
    warnings.finish()
    report = as_report(name, *found, limits)
    sys.stdout.write(json.dumps(report, indent=2) + "\n" if args.format == "json" else as_text(report))
    return 0


def as_report(name: str, whole: Extent, systems: dict[str, Extent], tools: dict[str, Extent], limits) -> dict:
    return {
        "file": name,
        "moves": MOVES,
        "all": _group(whole, limits),
        "work_offsets": [
            _group(e, limits) | {"zero_from_program": e.zero_from_program} for e in systems.values()
        ],
        "tools": [_group(e, limits, tool=True) for e in tools.values()],
    }


def _group(extent: Extent, limits, tool: bool = False) -> dict:
    out: dict = {"tool" if tool else "name": extent.name if not tool else (extent.name or None)}
    out.update(lines=[extent.program.first_line, extent.program.last_line], moves=extent.program.moves)
    out["program_mm"] = extent.program.as_dict() if not extent.program.empty else None
    out["machine_mm"] = extent.machine.as_dict() if not extent.machine.empty else None
    out["moves_zero_unknown"] = extent.unknown_zero
    if limits is not None and not extent.machine.empty:
        out["travel"] = {axis: f.as_dict() for axis, f in fit_in_travel(extent.machine, limits).items()}
    return out


def as_text(report: dict) -> str:
    lines = [f"{report['file']}: extents of {MOVES} (mm)"]
    for title, group in [("whole program", report["all"])] + [
        (f"work offset {g['name']}", g) for g in report["work_offsets"]
    ] + [(f"tool {g['tool']}" if g["tool"] else "no tool", g) for g in report["tools"]]:  # fmt: skip
        if group.get("zero_from_program"):
            title += " (its zero set by the program itself, G10)"
        lines += _group_text(title, group)
    if report["all"]["moves_zero_unknown"]:
        lines.append("machine positions need the zeros the control holds: give --work-offset or --var-file")
    return "\n".join(lines) + "\n"


def _group_text(title: str, group: dict) -> list[str]:
    lines = ["", f"{title}: {group['moves']} moves, lines {group['lines'][0]}-{group['lines'][1]}"]
    for label, key in (("program", "program_mm"), ("machine", "machine_mm")):
        if group[key] is not None:
            lines.append(
                f"  {label:<8}"
                + "  ".join(f"{a} {lo:10.3f} .. {hi:10.3f}" for a, (lo, hi) in group[key].items())
            )
    if group["moves_zero_unknown"] and group["machine_mm"] is not None:
        lines.append(
            f"  ({group['moves_zero_unknown']} moves in systems whose zero is not known are not in the box)"
        )
    fits = [
        f"{axis} [{f['travel'][0]:g}, {f['travel'][1]:g}]"
        for axis, f in group.get("travel", {}).items()
        if f["fits"]
    ]
    if fits:
        lines.append("  fits the travel of " + ", ".join(fits))
    for axis, fit in group.get("travel", {}).items():
        beyond = [f"{fit['below_mm']:.3f} mm below its low end" if fit["below_mm"] else "",
                  f"{fit['above_mm']:.3f} mm above its high end" if fit["above_mm"] else ""]  # fmt: skip
        if not fit["fits"]:
            lo, hi = fit["travel"]
            lines.append(
                f"  {axis} does NOT fit the travel [{lo:g}, {hi:g}]: " + " and ".join(b for b in beyond if b)
            )
    return lines
