"""`ncpp [IN] [-o OUT]`: the stdin/stdout NC filter.

With no passes the output is the input, byte for byte; the program is still
read completely first, so a program with an error produces no output.
"""

from __future__ import annotations

import argparse

from ncpp.cli.io import add_io_arguments, open_input, open_output
from ncpp.errors import Warnings
from ncpp.program.parser import parse_stream
from ncpp.program.writer import write_blocks


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("filter", help="read an NC program and write it back (the default command)")
    add_io_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    warnings = Warnings(strict=args.strict)
    with open_input(args.input) as (stream, name), open_output(args.output) as out:
        write_blocks(parse_stream(stream, name), out)
    return 1 if warnings.count and args.strict else 0
