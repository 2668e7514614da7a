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
import tempfile
from functools import cached_property
from typing import BinaryIO, TextIO

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
    """Write the compensated program to stdout (nothing on error), progress, warnings and the
    summary to `err`; the summary and each kind of warning also as `(MSG, ...)` lines at the
    program's start, which LinuxCNC shows the operator when the program runs."""
    from ncpp.cli.filter import NOT_COMPENSATED, placement_guard
    from ncpp.cli.io import open_output
    from ncpp.integrations.config import find_settings, with_linuxcnc_ini
    from ncpp.pipeline import ErrorSource, process

    settings = with_linuxcnc_ini(find_settings(machine), os.environ.get("INI_FILE_NAME"))
    if settings.machine is None:
        print(f"ncpp: {path}: warning: {NOT_COMPENSATED}", file=err)
    with open(path, "rb") as stream:
        progress = FilterProgress(path, err)
        progress.report(0)
        with open_output(None) as spool:
            if settings.machine is None or already_compensated(path):
                shutil.copyfileobj(stream, spool)
            else:
                if not os.path.isfile(settings.machine):
                    raise NcppError(
                        f"machine file {settings.machine} does not exist", Location(settings.origin)
                    )
                source = ErrorSource.from_machine_file(settings.machine)
                offsets = settings.offsets()
                with tempfile.TemporaryFile() as written:
                    stats = process(stream, written, file=path, source=source, tolerance=settings.tolerance,
                                    warnings=Warnings(stream=err), progress=progress, offsets=offsets,
                                    guard=placement_guard(settings, offsets), guard_tools=True)  # fmt: skip
                    summary = stats.summary
                    assert summary is not None  # (a compensating run's)
                    print(summary.line(), file=err)
                    written.seek(0)
                    with_messages(written, spool, operator_messages(summary))
        progress.report(100)


MSG_TEXT = 200  # characters of a message line's text at most (rs274 refuses lines of 255 and more)
MSG_KINDS = 8  # kinds of warning shown the operator at most (the rest are counted)


def operator_messages(summary) -> list[str]:
    """`(MSG, ...)` lines: the summary (`summary.Summary`), a line per part, then each kind of
    warning at its first line.  LinuxCNC's G-code manual ("G Code Overview", comments): the text
    after `MSG,` is shown the operator; a comment ends at the first `)`, so none may be inside."""
    texts: list[str] = []
    said = summary.line(os.path.basename(summary.file))
    for part in said.split("; "):  # parts joined up to a line's length
        if texts and len(texts[-1]) + len(part) + 2 <= MSG_TEXT:
            texts[-1] += f"; {part}"
        else:
            texts.append(part if not texts else f"ncpp: {part}")
    warned = list(summary.warned.items())
    for message, (where, times) in warned[:MSG_KINDS]:
        again = f" [and {times - 1} more]" if times > 1 else ""
        texts.append(f"ncpp warning line {where.line}{again}: {message}")
    if len(warned) > MSG_KINDS:
        texts.append(f"ncpp: {len(warned) - MSG_KINDS} more kinds of warning: see the filter's output")
    return [f"(MSG, {_msg_text(text)})" for text in texts]


def _msg_text(text: str) -> str:
    text = text.replace("(", "[").replace(")", "]").replace("µm", "um")  # (ASCII: the screens' fonts)
    return text if len(text) <= MSG_TEXT else text[: MSG_TEXT - 3] + "..."


def with_messages(written: BinaryIO, out: BinaryIO, messages: list[str]) -> None:
    """Copy the written program to `out` with the message lines after its header comment
    (after a `%` line, where ncpp puts the header)."""
    from ncpp.pipeline import HEADER_TAG

    head = [written.readline() for _ in range(2)]
    at = next((k + 1 for k, line in enumerate(head) if HEADER_TAG.encode() in line), 0)
    eol = b"\r\n" if head[0].endswith(b"\r\n") else b"\n"
    out.writelines(head[:at])
    out.writelines(m.encode("latin-1", errors="replace") + eol for m in messages)
    out.writelines(head[at:])
    shutil.copyfileobj(written, out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="ncpp-linuxcnc-filter",
        description="LinuxCNC [FILTER] program: compensate the program named on the command line",
    )
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
        print(
            f"ncpp-linuxcnc-filter: {error.filename or '<stdout>'}: {error.strerror or error}",
            file=sys.stderr,
        )
        return 2
    except KeyboardInterrupt:
        return 130
    except Terminated:
        return Terminated.EXIT_STATUS
    return 0


if __name__ == "__main__":
    sys.exit(main())
