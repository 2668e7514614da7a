"""`ncpp compensate --machine M.toml [--tolerance 0.001] [IN] [-o OUT]`.

Rewrites an NC program so that the modelled machine cuts the programmed part.
`--from FILE` compensates straight from one measurement (ball bar,
comparator or laser positioning file) instead of a machine file.
"""

from __future__ import annotations

import argparse
import sys

from ncpp.cli.io import add_io_arguments, open_input, open_output
from ncpp.errors import NcppError, Warnings


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("compensate", help="compensate an NC program for a machine's errors")
    add_compensation_arguments(p)
    add_io_arguments(p)
    p.set_defaults(func=run)


def add_compensation_arguments(p: argparse.ArgumentParser) -> None:
    source = p.add_mutually_exclusive_group()
    source.add_argument("--machine", metavar="M.toml", help="machine file with the error model")
    source.add_argument("--from", dest="from_file", metavar="FILE", help="compensate from one measurement file")
    p.add_argument("--tolerance", type=float, default=0.001, metavar="MM", help="allowed path deviation, mm (default 0.001)")
    p.add_argument("--force", action="store_true", help="compensate a program ncpp has compensated before")
    p.add_argument(
        "--work-offset",
        type=parse_vector,
        default=None,
        metavar="X,Y,Z",
        help="machine position (mm) of the program zero, as the control's work offset holds it (default 0,0,0)",
    )


def parse_vector(text: str) -> tuple[float, float, float]:
    try:
        values = tuple(float(v) for v in text.split(","))
    except ValueError:
        values = ()
    if len(values) != 3:
        raise argparse.ArgumentTypeError(f"expected X,Y,Z in mm, got {text!r}")
    return values  # type: ignore[return-value]


def error_source(args: argparse.Namespace):
    from ncpp.pipeline import ErrorSource

    if getattr(args, "from_file", None):
        return ErrorSource.from_measurement(args.from_file).shifted(args.work_offset)
    if getattr(args, "machine", None):
        return ErrorSource.from_machine_file(args.machine).shifted(args.work_offset)
    return None


def run(args: argparse.Namespace) -> int:
    from ncpp.pipeline import process

    source = error_source(args)
    if source is None:
        raise NcppError("no error model: give --machine M.toml or --from MEASUREMENT")
    if not args.tolerance > 0:
        raise NcppError("--tolerance must be positive")
    warnings = Warnings(strict=args.strict)
    with open_input(args.input) as (stream, name), open_output(args.output) as out:
        stats = process(
            stream, out, file=name, source=source, tolerance=args.tolerance, strict=args.strict, force=args.force,
            warnings=warnings, dialect=args.dialect,
        )
    if sys.stderr.isatty():
        print(f"ncpp: {stats.lines_in} lines in, {stats.lines_out} lines out", file=sys.stderr)
    return 0
