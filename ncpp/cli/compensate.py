"""`ncpp compensate --machine M.toml [--tolerance 0.001] [IN] [-o OUT]`.

Rewrites an NC program so that the modelled machine cuts the programmed part.
`--from FILE` compensates straight from one measurement (ball bar,
comparator or laser positioning file) instead of a machine file.
"""

from __future__ import annotations

import argparse
import io
import os
import sys
from typing import BinaryIO

from ncpp.cli.io import add_io_arguments, open_input, open_output
from ncpp.cli.options import positive
from ncpp.cli.progress import progress_printer
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
    p.add_argument("--tolerance", type=tolerance_mm, default=0.001, metavar="MM", help="allowed path deviation, mm (default 0.001)")
    p.add_argument("--force", action="store_true", help="compensate a program ncpp has compensated before")
    p.add_argument(
        "--no-verify",
        dest="verify",
        action="store_false",
        help="write the compensated program without reading it back and comparing it with the input "
        "(by default a program whose actions or path differ from the input's is refused, and nothing is written)",
    )
    add_placement_arguments(p)
    p.add_argument(
        "--jobs",
        type=int,
        choices=(1, 2),
        default=None,
        help="processes: 2 compensates a program file of 8192 lines or more in two parts, one process each, and "
        "other input with its numeric work in a second process (the same output either way; a piped program is "
        "copied to a temporary file first); default 2 for a program file or piped program over 2 MB on a machine "
        "with two or more cores, else 1 (a pipe then streams)",
    )


def add_placement_arguments(p: argparse.ArgumentParser) -> None:
    """Where the program sits on the machine: the zeros the control holds."""
    p.add_argument(
        "--work-offset",
        type=zero_argument,
        action="append",
        default=[],
        metavar="[G5x=]X,Y,Z",
        help="machine position (mm) of a coordinate system's zero, as the control holds it; without G5x= it is G54's "
        "(default 0,0,0); repeat for G55-G59.3.  A program selecting a system nobody gave gets a warning",
    )
    p.add_argument(
        "--var-file",
        metavar="FILE",
        help="LinuxCNC parameter file (linuxcnc.var) holding the control's G54-G59.3 zeros, the system in effect, "
        "G92 and the G28/G30 positions; --work-offset overrides its systems",
    )
    p.add_argument(
        "--tool-table",
        metavar="FILE",
        help="the control's tool table (LinuxCNC's tool.tbl, Heidenhain's TOOL.T, Sinumerik's _N_TO_INI): the tool lengths G43, TOOL CALL or M6/D apply, "
        "which move the axes and lengthen the Abbe arm; without it they apply length 0, with a warning",
    )
    p.add_argument(
        "--var-units", choices=("mm", "inch"), default="mm", help="units of --var-file and of a LinuxCNC --tool-table: the INI's [TRAJ]LINEAR_UNITS (default mm; TOOL.T says its own)"
    )
    p.add_argument(
        "--subroutine-path",
        metavar="DIR[:DIR...]",
        type=lambda text: [d for d in text.split(os.pathsep) if d],
        default=[],
        help="folders of subroutine files, as the INI's [RS274NGC]SUBROUTINE_PATH: `o<name> call` of a subroutine the "
        "program does not define runs DIR/name.ngc (without it, such a call ends interpretation with a warning)",
    )


# A worker process pays off from about this size: it costs ~0.3 s to start (overlapped
# with the first chunks) and takes a fifth to a third of the run off this process.
AUTO_JOBS_BYTES = 2 << 20


def jobs_for(requested: int | None, stream: BinaryIO) -> int:
    """--jobs, or what suits this input on this machine."""
    if requested is not None:
        return requested
    try:
        size = os.fstat(stream.fileno()).st_size  # a pipe says 0 (`spool_from` copies a long one to a file)
    except (OSError, ValueError, io.UnsupportedOperation):
        return 1
    return 2 if _cores() >= 2 and size >= AUTO_JOBS_BYTES else 1


def spool_from(requested: int | None) -> int | None:
    """From how many bytes a program piped to standard input is copied to a file before it
    is compensated (`open_input`), where two processes can read it: any with --jobs 2,
    none with --jobs 1, else from the size at which `jobs_for` gives a file two."""
    if requested is not None:
        return 0 if requested >= 2 else None
    return AUTO_JOBS_BYTES if _cores() >= 2 else None


def _cores() -> int:
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)


def tolerance_mm(text: str) -> float:
    """--tolerance: a positive, finite number of mm."""
    try:
        return positive(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"expected a positive number of mm, got {text!r}") from None


def zero_argument(text: str) -> tuple[str, tuple[float, float, float]]:
    from ncpp.motion.offsets import parse_zero

    try:
        return parse_zero(text)
    except ValueError as err:
        raise argparse.ArgumentTypeError(str(err)) from None


def work_offsets(args: argparse.Namespace):
    """The control's zeros and tool table from --var-file, --work-offset and --tool-table."""
    from ncpp.motion.offsets import UNIT_MM, WorkOffsets

    return WorkOffsets.given(dict(args.work_offset), args.var_file, UNIT_MM[args.var_units], args.tool_table, args.subroutine_path)


def error_source(args: argparse.Namespace):
    from ncpp.pipeline import ErrorSource

    if getattr(args, "from_file", None):
        return ErrorSource.from_measurement(args.from_file)
    if getattr(args, "machine", None):
        return ErrorSource.from_machine_file(args.machine)
    return None


def run(args: argparse.Namespace) -> int:
    from ncpp.pipeline import process

    source = error_source(args)
    if source is None:
        raise NcppError("no error model: give --machine M.toml or --from MEASUREMENT")
    warnings = Warnings(strict=args.strict)
    progress = progress_printer("compensate")
    with open_input(args.input, spool_from(args.jobs)) as (stream, name), open_output(args.output) as out:
        stats = process(
            stream, out, file=name, source=source, tolerance=args.tolerance, strict=args.strict, force=args.force,
            warnings=warnings, progress=progress, dialect=args.dialect, jobs=jobs_for(args.jobs, stream), offsets=work_offsets(args), verify=args.verify,
        )
    if progress is not None:
        progress.done()
        print(f"ncpp: {stats.lines_in} lines in, {stats.lines_out} lines out", file=sys.stderr)
    return 0
