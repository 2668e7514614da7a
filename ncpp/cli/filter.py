"""`ncpp [IN] [-o OUT]`: the stdin/stdout NC filter.

With no passes the output is the input, byte for byte.  Every block goes
through the motion interpreter, so a program LinuxCNC would refuse (bad arc
radius, conflicting words...) fails with `file:line:col: message` and
nothing is written; output is spooled until the whole program was read.
The dialect is detected from the first few KB (`--dialect` overrides);
Heidenhain and Sinumerik programs are parsed (a syntax error fails the same
way) and written back as read, until their interpreters exist.
"""

from __future__ import annotations

import argparse
from typing import Iterable, Iterator

from ncpp.cli.io import add_io_arguments, open_input, open_output
from ncpp.errors import Warnings
from ncpp.motion import interpret
from ncpp.motion.segments import Event
from ncpp.program.blocks import Block
from ncpp.program.dialects import parse_program
from ncpp.program.writer import write_blocks


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("filter", help="read an NC program and write it back (the default command)")
    add_io_arguments(p)
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    warnings = Warnings(strict=args.strict)
    with open_input(args.input) as (stream, name), open_output(args.output) as out:
        dialect, blocks = parse_program(stream, name, args.dialect)
        if dialect == "iso":
            blocks = source_blocks(interpret(blocks, file=name, warnings=warnings))
        write_blocks(blocks, out)
    return 1 if warnings.count and args.strict else 0


def source_blocks(events: Iterable[Event]) -> Iterator[Block]:
    """Each event's block, once (a G28 block makes two moves)."""
    last = None
    for event in events:
        block = event.block
        if block is not last:
            yield block
            last = block
