"""`ncpp compensate --machine M.toml [--tolerance 0.001] [IN] [-o OUT]`,
`ncpp compensate --machine M.toml [--jobs N] -o FOLDER IN...`.

Rewrites NC programs so that the modelled machine cuts the programmed part.
`--from FILE` compensates straight from one measurement (ball bar,
comparator or laser positioning file) instead of a machine file.  Several
programs go to a folder, each under its own name, `--jobs` of them at once
(one process each): a program that fails is reported and the others go on.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import sys
from collections.abc import Callable
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

from ncpp.cli.io import add_io_arguments, open_input, open_output
from ncpp.cli.options import at_least, positive
from ncpp.cli.progress import progress_printer
from ncpp.errors import NcppError, Warnings
from ncpp.runtime import die_with_parent
from ncpp.summary import write_report


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("compensate", help="compensate an NC program for a machine's errors")
    add_compensation_arguments(p)
    add_expand_argument(p)
    add_io_arguments(p, several=True)
    p.add_argument(
        "--jobs", type=at_least(1), default=1, metavar="N",
        help="programs compensated at once, one process each, when several are given (default 1)",
    )  # fmt: skip
    p.set_defaults(func=run)


def add_expand_argument(p: argparse.ArgumentParser) -> None:
    """`--expand-cycles` and `--expand`, of the commands that compensate a program (not the CL-data post)."""
    p.add_argument(
        "--expand-cycles",
        action="store_true",
        help="write each canned cycle of an ISO program as G0/G1 blocks (G4 where it dwells), each move "
        "compensated, for controls without canned cycles (tapping, G86 and G87 are refused)",
    )
    p.add_argument(
        "--expand",
        action="store_true",
        help="write the loops and subroutines of an ISO program (o-word, M98, Haas's M97, WHILE, GOTO), a Klartext program "
        "(CALL LBL, CALL LBL REP, FN 9-12) or a Sinumerik program (WHILE, FOR, REPEAT, LOOP, GOTOB, L100, "
        "subprograms by name) out as straight code, every run of a body where it runs, each move "
        "compensated (without it their moves pass through uncompensated)",
    )


def add_compensation_arguments(p: argparse.ArgumentParser) -> None:
    source = p.add_mutually_exclusive_group()
    source.add_argument("--machine", metavar="M.toml", help="machine file with the error model")
    source.add_argument(
        "--from", dest="from_file", metavar="FILE", help="compensate from one measurement file"
    )
    p.add_argument(
        "--tolerance",
        type=tolerance_mm,
        default=0.001,
        metavar="MM",
        help="allowed path deviation, mm (default 0.001)",
    )
    p.add_argument("--force", action="store_true", help="compensate a program ncpp has compensated before")
    p.add_argument(
        "--no-verify",
        dest="verify",
        action="store_false",
        help="write the compensated program without reading it back and comparing it with the input "
        "(by default a program whose actions or path differ from the input's is refused, and nothing is written)",
    )
    p.add_argument(
        "--report",
        metavar="FILE.json",
        help="write what compensation did as JSON: the summary line's figures, with the input lines "
        "of each reason moves were left as programmed (several programs: a list)",
    )
    p.add_argument(
        "--no-guard",
        dest="guard",
        action="store_false",
        help="leave out the guards: the block at the program's start that stops it when "
        "the control's work offset is not the one given with --work-offset / --var-file, and the check "
        "after each G43 that stops it when the control's tool or its length is not the one in --tool-table",
    )
    add_placement_arguments(p)


def tell(summary, report: str | None) -> None:
    """A run's summary (`summary.Summary`) on stderr, and in the --report file."""
    print(summary.line(), file=sys.stderr)
    if report:
        write_report(report, [summary])


def add_placement_arguments(p: argparse.ArgumentParser) -> None:
    """Where the program sits on the machine: the zeros the control holds."""
    p.add_argument(
        "--work-offset",
        type=zero_argument,
        action="append",
        default=[],
        metavar="[G5x=]X,Y,Z",
        help="machine position (mm) of a coordinate system's zero, as the control holds it; without G5x= it is G54's "
        "(default 0,0,0); repeat for G55-G59.3, and for Fanuc's G54.1P1-P48 or Haas's G154P1-P99.  A program "
        "selecting a system nobody gave gets a warning",
    )
    p.add_argument(
        "--var-file",
        metavar="FILE",
        help="LinuxCNC parameter file (linuxcnc.var) holding the control's G54-G59.3 zeros, the system in effect, "
        "G92 and the G28/G30 positions (a Fanuc or Haas control's additional offsets at #7001..., #14001...); "
        "--work-offset overrides its systems",
    )
    p.add_argument(
        "--tool-table",
        metavar="FILE",
        help="the control's tool table (LinuxCNC's tool.tbl, Heidenhain's TOOL.T, Sinumerik's _N_TO_INI): "
        "the tool lengths G43, TOOL CALL or M6/D apply, which move the axes and lengthen the Abbe arm "
        "(without it they apply length 0, with a warning), and the radii cutter compensation offsets by",
    )
    p.add_argument(
        "--var-units",
        choices=("mm", "inch"),
        default="mm",
        help="units of --var-file and of a LinuxCNC --tool-table: the INI's [TRAJ]LINEAR_UNITS (default mm; TOOL.T says its own)",
    )
    p.add_argument(
        "--subroutine-path",
        metavar="DIR[:DIR...]",
        type=lambda text: [d for d in text.split(os.pathsep) if d],
        default=[],
        help="folders of subroutine files, as the INI's [RS274NGC]SUBROUTINE_PATH: `o<name> call` of a "
        "subroutine the program does not define runs DIR/name.ngc, Fanuc's M98 P<n> DIR/O<n>, Sinumerik's "
        "L<n> or NAME DIR/NAME.SPF (or _N_NAME_SPF), Klartext's CALL PGM NAME DIR/NAME.H (without it, such a "
        "call ends interpretation with a warning)",
    )


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

    return WorkOffsets.given(
        dict(args.work_offset), args.var_file, UNIT_MM[args.var_units], args.tool_table, args.subroutine_path
    )


def error_source(args: argparse.Namespace):
    from ncpp.pipeline import ErrorSource

    if getattr(args, "from_file", None):
        return ErrorSource.from_measurement(args.from_file)
    if getattr(args, "machine", None):
        return ErrorSource.from_machine_file(args.machine)
    return None


def run(args: argparse.Namespace) -> int:
    from ncpp.cli.filter import configured_source

    source, tolerance, offsets, guard = configured_source(args)
    if source is None:
        raise NcppError(
            "no error model: give --machine M.toml or --from MEASUREMENT, set $NCPP_MACHINE, "
            "or name a machine file in ./ncpp.toml or ~/.config/ncpp/config.toml"
        )
    job = Job(source, tolerance, args.strict, args.force, args.dialect, offsets, args.verify, guard,
              args.expand_cycles, args.expand, args.guard)  # fmt: skip
    folder = args.output is not None and os.path.isdir(args.output)
    if len(args.input) > 1 or folder:
        if args.output is None:
            raise NcppError(
                "several programs need -o FOLDER, the folder each is written to under its own name"
            )
        return compensate_files(job, args.input, Path(args.output), args.jobs, args.report)
    return _compensate_one(job, args.input[0] if args.input else None, args.output, args.report)


Progress = Callable[[int], None] | None


@dataclass(frozen=True)
class Job:
    """How every program of a run is compensated (pickled once to each process of `--jobs`)."""

    source: object  # pipeline.ErrorSource
    tolerance: float
    strict: bool
    force: bool
    dialect: str | None
    offsets: object  # motion.offsets.WorkOffsets
    verify: bool = True
    guard: object = None  # guard.Placement: the placement guard at the program's start (None: none)
    expand_cycles: bool = False  # canned cycles written as G0/G1 blocks
    expand: bool = False  # loops and subroutines written out as straight code
    guard_tools: bool = False  # the told tool lengths checked where the program applies them

    def compensate(self, stream: BinaryIO, out: BinaryIO, name: str, progress: Progress = None):
        """`pipeline.process` of one program, with warnings of its own."""
        from ncpp.pipeline import process

        return process(
            stream, out, file=name, source=self.source,  # type: ignore[arg-type]
            tolerance=self.tolerance, strict=self.strict, force=self.force,
            warnings=Warnings(strict=self.strict), progress=progress, dialect=self.dialect,
            offsets=self.offsets, verify=self.verify, guard=self.guard,  # type: ignore[arg-type]
            expand_cycles=self.expand_cycles, expand=self.expand, guard_tools=self.guard_tools,
        )  # fmt: skip


def _compensate_one(job: Job, path: str | None, output: str | None, report: str | None = None) -> int:
    """One program (standard input for none) to `output` (standard output for none), with progress."""
    progress = progress_printer("compensate")
    with open_input(path) as (stream, name), open_output(output) as out:
        stats = job.compensate(stream, out, name, progress)
    if progress is not None:
        progress.done()
    tell(stats.summary, report)
    return 0


def compensate_files(
    job: Job, paths: list[str], folder: Path, jobs: int = 1, report: str | None = None
) -> int:
    """Each program to `folder` under its own name, `jobs` at once; a failure is reported
    (`file:line:col: message`) and the others go on, a success by its summary.  0 if all were
    written, else 2."""
    targets = _targets(paths, folder)
    folder.mkdir(parents=True, exist_ok=True)
    failed = 0
    summaries = []
    with _executor(job, min(jobs, len(paths))) as pool:
        futures = [pool.submit(_compensate_file, path, str(target)) for path, target in zip(paths, targets)]
        for path, future in zip(paths, futures):
            message = _failure(future, path)
            if message is not None:
                print(message, file=sys.stderr)
                failed += 1
            else:
                summaries.append(future.result())
                print(summaries[-1].line(), file=sys.stderr)
    if report and summaries:
        write_report(report, summaries)
    if failed:
        print(f"ncpp: {failed} of {len(paths)} programs failed", file=sys.stderr)
    return 2 if failed else 0


def _targets(paths: list[str], folder: Path) -> list[Path]:
    """Where each program goes: `folder`/its name; refused where two share a name, or one
    would replace its program."""
    targets = [folder / Path(path).name for path in paths]
    seen: dict[Path, str] = {}
    for path, target in zip(paths, targets):
        if target in seen:
            raise NcppError(f"{seen[target]} and {path} would both be written to {target}")
        if Path(path).resolve() == target.resolve():
            raise NcppError(f"{path}: -o {folder} would replace the program itself")
        seen[target] = path
    return targets


def _failure(future: Future, path: str) -> str | None:
    """How the program at `path` failed, as `ncpp` reports it (None: it was written)."""
    try:
        future.result()
    except NcppError as err:
        return str(err)
    except OSError as err:
        return f"{err.filename or path}: {err.strerror or err}"
    except BrokenProcessPool:  # (killed, or out of memory: the programs it had are not written)
        return f"{path}: the process compensating it stopped"
    return None


class _InProcess(Executor):
    """--jobs 1: each program in this process, one after the other, as the pool would."""

    def __init__(self, job: Job):
        _start_worker(job)

    def submit(self, fn, /, *args, **kwargs) -> Future:
        future: Future = Future()
        try:
            future.set_result(fn(*args, **kwargs))
        except (NcppError, OSError) as err:
            future.set_exception(err)
        return future


def _executor(job: Job, workers: int) -> Executor:
    """Processes started fresh ("spawn"): a fork would copy this process's threads' locks (BLAS's)."""
    if workers <= 1:
        return _InProcess(job)
    context = multiprocessing.get_context("spawn")
    return ProcessPoolExecutor(
        workers, mp_context=context, initializer=_start_worker, initargs=(job, os.getpid())
    )


_job: Job | None = None  # the run's job, in each process that compensates


def _start_worker(job: Job, parent: int | None = None) -> None:
    """The job, in a process `parent` started: that process's end ends it (`die_with_parent`)."""
    global _job
    if parent is not None:
        die_with_parent(parent)
    _job = job


def _compensate_file(path: str, target: str):
    """One program of `compensate_files`, in a process `_start_worker` was told the job."""
    from ncpp.fileio import atomic_output

    assert _job is not None
    with open(path, "rb") as stream, atomic_output(target) as out:
        return _job.compensate(stream, out, path).summary
