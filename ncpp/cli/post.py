"""`ncpp post FILE.cls --dialect iso|linuxcnc|fanuc|heidenhain|sinumerik [--machine M.toml] [-o OUT]`.

Posts APT CL data (NX CLSF, Creo NCL, ...) as an NC program with real arcs,
compensated through the same passes as `ncpp compensate` when a machine
file (or `--from` measurement) is given.
"""

from __future__ import annotations

import argparse

from ncpp.cli.compensate import add_compensation_arguments, error_source, tell, work_offsets
from ncpp.cli.io import open_output
from ncpp.errors import Warnings

DIALECTS = (
    "iso",
    "linuxcnc",
    "fanuc",
    "heidenhain",
    "sinumerik",
)  # = ncpp.post.GENERATORS, without importing it


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("post", help="post APT CL data as an NC program (compensated with --machine)")
    p.add_argument("input", help="CL data file (APT / CLSF / NCL); - for standard input")
    p.add_argument("--dialect", required=True, choices=DIALECTS, help="NC dialect to write")
    p.add_argument("-o", "--output", help="output file, written atomically (default: standard output)")
    p.add_argument("--strict", action="store_true", help="refuse records that would pass through as comments")
    add_compensation_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import sys
    from typing import Any

    from ncpp.cli.progress import progress_printer
    from ncpp.guard import Placement
    from ncpp.motion.offsets import UNIT_MM
    from ncpp.post import post
    from ncpp.summary import Summary

    source = error_source(args)
    summary = Summary(args.input) if source is not None else None
    offsets = work_offsets(args)
    told = args.guard and (args.work_offset or args.var_file)
    guard = Placement.of(offsets, UNIT_MM[args.var_units]) if told else None
    warnings = Warnings(strict=args.strict)
    progress = progress_printer("post")
    options: dict[str, Any] = dict(dialect=args.dialect, source=source, tolerance=args.tolerance, warnings=warnings, progress=progress,
                                   offsets=offsets, verify=args.verify, summary=summary, guard=guard)  # fmt: skip
    with open_output(args.output) as out:
        if args.input == "-":
            post(sys.stdin, out, file="<stdin>", **options)
        else:
            with open(args.input, encoding="latin-1") as stream:
                post(stream, out, file=args.input, **options)
    if progress is not None:
        progress.done()
    if summary is not None:
        tell(summary, args.report)
    return 0
