"""`ncpp [IN] [-o OUT] [--machine M.toml]`: the stdin/stdout NC filter of a shop pipeline.

It compensates with the machine file found by `ncpp.integrations.config`
(`--machine`, then `$NCPP_MACHINE`, then `./ncpp.toml` or
`~/.config/ncpp/config.toml`) and passes the program through unchanged
when there is none: with no passes the output is the input, byte for byte.
Every block goes through the motion interpreter, so a program LinuxCNC
would refuse (bad arc radius, conflicting words...) fails with
`file:line:col: message`, a non-zero exit status and no output (output is
spooled until the whole program was read), so that a pipeline stops.
The dialect (ISO / LinuxCNC, Fanuc, Haas, grbl, Heidenhain, Sinumerik) is detected
from the content (`--dialect` overrides), and the same pipeline as `ncpp
compensate` runs (`ncpp.pipeline.process`).  A progress line goes to stderr
when stderr is a terminal.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

from ncpp.cli.compensate import add_compensation_arguments, add_expand_argument, tell
from ncpp.cli.io import add_io_arguments, open_input, open_output
from ncpp.cli.progress import progress_printer
from ncpp.errors import Location, NcppError, Warnings


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "filter",
        help="read an NC program and write it back, compensated when a machine file is configured (the default command)",
    )
    add_io_arguments(p)
    add_compensation_arguments(p)
    add_expand_argument(p)
    p.set_defaults(func=run, tolerance=None)  # None: the config file's, else 0.001


def run(args: argparse.Namespace) -> int:
    from ncpp.pipeline import process

    warnings = Warnings(strict=args.strict)
    source, tolerance, offsets, guard = configured_source(args)
    progress = progress_printer("filter")
    with open_input(args.input) as (stream, name), open_output(args.output) as out:
        stats = process(stream, out, file=name, source=source, tolerance=tolerance, strict=args.strict, force=args.force,
                        warnings=warnings, progress=progress, dialect=args.dialect, offsets=offsets, verify=args.verify,
                        guard=guard, expand_cycles=args.expand_cycles, expand=args.expand,
                        guard_tools=args.guard)  # fmt: skip
    if progress is not None:
        progress.done()
    if stats.summary is not None:
        tell(stats.summary, args.report)
    else:
        print(f"ncpp: {name}: warning: {NOT_COMPENSATED}", file=sys.stderr)
    return 1 if warnings.count and args.strict else 0


# What a run without a machine file says: it passes the program through as it is.
NOT_COMPENSATED = (
    "no machine file, nothing was compensated: the program passes through unchanged "
    "(give --machine, set $NCPP_MACHINE, or name one in ./ncpp.toml or ~/.config/ncpp/config.toml)"
)


def configured_source(args: argparse.Namespace):
    """(ErrorSource or None, tolerance, WorkOffsets, the placement guard or None) from the
    command line, $NCPP_MACHINE and the config file."""
    from ncpp.integrations.config import find_settings

    var_units = (
        args.var_units if args.var_file or args.tool_table else None
    )  # the config's when the files are the config's
    settings = find_settings(
        args.machine, args.tolerance, dict(args.work_offset), args.var_file, var_units, args.tool_table
    )
    settings = replace(settings, subroutine_path=tuple(args.subroutine_path))
    if not (args.from_file or settings.machine):
        return None, settings.tolerance, None, None
    from ncpp.pipeline import ErrorSource

    offsets = settings.offsets()
    guard = placement_guard(settings, offsets) if args.guard else None
    if args.from_file:
        return ErrorSource.from_measurement(args.from_file), settings.tolerance, offsets, guard
    assert settings.machine is not None  # (a machine file or a measurement, above)
    if not Path(settings.machine).exists():  # (a device is read, to its size limit)
        raise NcppError(f"machine file {settings.machine} does not exist", Location(settings.origin))
    return ErrorSource.from_machine_file(settings.machine), settings.tolerance, offsets, guard


def placement_guard(settings, offsets):
    """The placement guard (`guard.Placement`) where the settings tell the work offset (--work-offset,
    --var-file or the config's), else None."""
    from ncpp.guard import Placement
    from ncpp.motion.offsets import UNIT_MM

    if not (settings.zeros or settings.var_file):
        return None
    return Placement.of(offsets, UNIT_MM[settings.var_units])
