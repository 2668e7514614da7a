"""The LinuxCNC `[FILTER]` program: `ncpp-linuxcnc-filter PROGRAM.ngc`.

LinuxCNC runs the filter named for a file's extension with the file's path
as its only argument, loads what the filter writes to stdout, shows a
progress bar from `FILTER_PROGRESS=N` lines (percent) on stderr, and shows
stderr as an error when the exit status is not 0.  The machine file comes
from `$NCPP_MACHINE` or the config files (`ncpp.integrations.config`), the
work offsets and tool lengths from the parameter file and tool table of the
configuration LinuxCNC runs ($INI_FILE_NAME) unless the config names others; with
none, or for a program ncpp compensated already, the program is loaded as it
is.  Output is spooled, so a failed run sends LinuxCNC nothing.
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
from functools import cached_property
from typing import TextIO

from ncpp.errors import Location, NcppError, Warnings
from ncpp.fileio import count_lines
from ncpp.runtime import Terminated, one_blas_thread, terminate_as_interrupt


class FilterProgress:
    """`FILTER_PROGRESS=N` on stderr whenever the percentage of the program's lines done
    changes (`pipeline.process`'s progress: the program's lines read)."""

    def __init__(self, path: str, out: TextIO):
        self.path, self.out = path, out
        self.last = -1

    @cached_property
    def lines(self) -> int:
        """The program's lines (counted when progress is first told: a program loaded as it is needs none)."""
        return max(count_lines(self.path), 1)

    def __call__(self, lines: int) -> None:
        self.report(min(99, 100 * lines // self.lines))

    def report(self, percent: int) -> None:
        if percent != self.last:
            self.last = percent
            print(f"FILTER_PROGRESS={percent}", file=self.out, flush=True)


def already_compensated(path: str) -> bool:
    """Whether the program's head has an ncpp header (`pipeline.refuse_compensated`'s rule)."""
    from ncpp.pipeline import header_comment, program_head
    from ncpp.program.dialects import parse_program

    with open(path, "rb") as f:
        try:
            _, blocks = parse_program(f, path, None)
            return any(header_comment(block) is not None for block in program_head(iter(blocks)))
        except NcppError:  # a program the parser refuses: compensating it says why
            return False


def run(path: str, err: TextIO, machine: str | None = None) -> None:
    """Write the compensated program to stdout (nothing on error), progress to `err`."""
    from ncpp.cli.io import open_output
    from ncpp.integrations.config import find_settings, with_linuxcnc_ini
    from ncpp.pipeline import ErrorSource, process

    settings = with_linuxcnc_ini(find_settings(machine), os.environ.get("INI_FILE_NAME"))
    with open(path, "rb") as stream:
        progress = FilterProgress(path, err)
        progress.report(0)
        with open_output(None) as spool:
            if settings.machine is None or already_compensated(path):
                shutil.copyfileobj(stream, spool)
            else:
                if not os.path.isfile(settings.machine):
                    raise NcppError(f"machine file {settings.machine} does not exist", Location(settings.origin))
                source = ErrorSource.from_machine_file(settings.machine)
                process(stream, spool, file=path, source=source, tolerance=settings.tolerance, warnings=Warnings(stream=err),
                        progress=progress, offsets=settings.offsets())  # fmt: skip
        progress.report(100)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="ncpp-linuxcnc-filter", description="LinuxCNC [FILTER] program: compensate the program named on the command line")
    parser.add_argument("program", help="the NC program LinuxCNC opens")
    parser.add_argument("--machine", help="machine file (default: $NCPP_MACHINE, then the ncpp config files)")
    args = parser.parse_args(argv)
    one_blas_thread()  # before `run` imports numpy (runtime.py)
    terminate_as_interrupt()
    try:
        run(args.program, sys.stderr, args.machine)
    except NcppError as error:
        print(str(error), file=sys.stderr)
        return 2
    except OSError as error:  # (a write's has no file name: LinuxCNC reads the standard output)
        print(f"ncpp-linuxcnc-filter: {error.filename or '<stdout>'}: {error.strerror or error}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except Terminated:
        return Terminated.EXIT_STATUS
    return 0


if __name__ == "__main__":
    sys.exit(main())
