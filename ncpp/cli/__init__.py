"""The `ncpp` command.

Each subcommand lives in its own module of this package and exposes
`register(subparsers)`, which adds its parser and sets `func` to a callable
`func(args) -> int`.  Plain `ncpp` (no subcommand) is the stdin/stdout filter.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from ncpp import __version__
from ncpp.errors import NcppError
from ncpp.runtime import Terminated, one_blas_thread, terminate_as_interrupt

# Module names under ncpp.cli, in the order `ncpp --help` lists them.
COMMANDS: tuple[str, ...] = (
    "filter",
    "motion",
    "extents",
    "compensate",
    "simulate",
    "analyze",
    "predict",
    "fit",
    "diagnose",
    "export_table",
    "post",
    "shipped",
)

DEFAULT_COMMAND = "filter"


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="ncpp",
        description="Make a CNC machine tool more accurate in software.",
    )
    parser.add_argument("--version", action="version", version=f"ncpp {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name in COMMANDS:
        importlib.import_module(f"ncpp.cli.{name}").register(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    one_blas_thread()  # before the commands import numpy (runtime.py)
    terminate_as_interrupt()
    parser = build_parser()
    known = set(parser._subparsers._group_actions[0].choices)  # type: ignore[union-attr, arg-type]
    if not argv or (argv[0] not in known and argv[0] not in ("-h", "--help", "--version")):
        argv.insert(0, DEFAULT_COMMAND)
    args = parser.parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except NcppError as err:
        print(f"ncpp: {err}" if not err.where.file else str(err), file=sys.stderr)
        return 2
    except BrokenPipeError:
        return 1
    except KeyboardInterrupt:
        return 130
    except Terminated:
        return Terminated.EXIT_STATUS
    except OSError as err:  # (a write's has no file name: the output's)
        name = err.filename or getattr(args, "output", None) or "<stdout>"
        print(f"ncpp: {name}: {err.strerror or err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
