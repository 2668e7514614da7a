"""`ncpp [IN] [-o OUT] [--machine M.toml]`: the stdin/stdout NC filter of a shop pipeline.

It compensates with the machine file found by `ncpp.integrations.config`
(`--machine`, then `$NCPP_MACHINE`, then `./ncpp.toml` or
`~/.config/ncpp/config.toml`) and passes the program through unchanged
when there is none: with no passes the output is the input, byte for byte.
Every block goes through the motion interpreter, so a program LinuxCNC
would refuse (bad arc radius, conflicting words...) fails with
`file:line:col: message`, a non-zero exit status and no output (output is
spooled until the whole program was read), so that a pipeline stops.
The dialect is detected from the first few KB (`--dialect` overrides);
Heidenhain and Sinumerik programs are parsed (a syntax error fails the same
way) and written back as read, until their interpreters exist.  A progress
line goes to stderr when stderr is a terminal.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Callable, Iterable, Iterator

from ncpp.cli.compensate import add_compensation_arguments
from ncpp.cli.io import add_io_arguments, open_input, open_output
from ncpp.cli.progress import progress_printer
from ncpp.errors import Location, NcppError, Warnings
from ncpp.motion import interpret
from ncpp.motion.segments import Event
from ncpp.program.blocks import Block
from ncpp.program.dialects import sniff
from ncpp.program.parser import parse_stream
from ncpp.program.writer import write_blocks


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("filter", help="read an NC program and write it back, compensated when a machine file is configured (the default command)")
    add_io_arguments(p)
    add_compensation_arguments(p)
    p.set_defaults(func=run, tolerance=None)  # None: the config file's, else 0.001


def run(args: argparse.Namespace) -> int:
    warnings = Warnings(strict=args.strict)
    source, tolerance = configured_source(args)
    progress = progress_printer("filter")
    with open_input(args.input) as (stream, name), open_output(args.output) as out:
        dialect, lines = sniff(stream, name, args.dialect)
        if source is not None:
            if dialect != "iso":
                raise NcppError(f"cannot compensate {dialect} programs yet (no {dialect} interpreter); ISO / Fanuc / LinuxCNC G code only")
            from ncpp.pipeline import process

            process(lines, out, file=name, source=source, tolerance=tolerance, strict=args.strict, force=args.force, warnings=warnings, progress=progress)  # type: ignore[arg-type]
        else:
            blocks = counted(parse_stream(lines, name, dialect), progress)
            if dialect == "iso":
                blocks = source_blocks(interpret(blocks, file=name, warnings=warnings))
            write_blocks(blocks, out)
    if progress is not None:
        progress.done()
    return 1 if warnings.count and args.strict else 0


def configured_source(args: argparse.Namespace):
    """(ErrorSource or None, tolerance) from the command line, $NCPP_MACHINE and the config file."""
    from ncpp.integrations.config import find_settings

    settings = find_settings(args.machine, args.tolerance, args.work_offset)
    if not settings.tolerance > 0:
        raise NcppError("--tolerance must be positive")
    if not (args.from_file or settings.machine):
        return None, settings.tolerance
    from ncpp.pipeline import ErrorSource

    if args.from_file:
        return ErrorSource.from_measurement(args.from_file).shifted(settings.work_offset), settings.tolerance
    if not Path(settings.machine).is_file():
        raise NcppError(f"machine file {settings.machine} does not exist", Location(settings.origin))
    return ErrorSource.from_machine_file(settings.machine).shifted(settings.work_offset), settings.tolerance


def counted(blocks: Iterable[Block], progress: Callable[[int], None] | None) -> Iterator[Block]:
    if progress is None:
        yield from blocks
        return
    for n, block in enumerate(blocks, start=1):
        if n % 1000 == 0:
            progress(n)
        yield block


def source_blocks(events: Iterable[Event]) -> Iterator[Block]:
    """Each event's block, once (a G28 block makes two moves)."""
    last = None
    for event in events:
        block = event.block
        if block is not last:
            yield block
            last = block
