"""Input and output for NC-program commands.

Output goes to a spool (memory, then a temporary file past a few MB) and
reaches its destination only when the whole program was processed: a file
is replaced atomically, stdout receives nothing if processing failed.
"""

from __future__ import annotations

import argparse
import contextlib
import shutil
import sys
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

from ncpp.fileio import atomic_output

SPOOL_BYTES = 8 << 20


def add_io_arguments(p: argparse.ArgumentParser, several: bool = False) -> None:
    """IN, -o OUT, --strict and --dialect; with `several`, IN is a list (`args.input`) and
    -o may name the folder the programs are written to."""
    if several:
        p.add_argument("input", nargs="*", metavar="IN", help="NC programs (default: standard input)")
        output = (
            "output file, written atomically (default: standard output); with several programs, "
            "or a folder, the folder each goes to under its own name"
        )
    else:
        p.add_argument("input", nargs="?", help="NC program (default: standard input)")
        output = "output file, written atomically (default: standard output)"
    p.add_argument("-o", "--output", help=output)
    p.add_argument(
        "--strict", action="store_true", help="refuse constructs that would pass through with a warning"
    )
    add_dialect_argument(p)


def add_dialect_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "--dialect",
        default=None,
        type=dialect_name,
        help="NC dialect: iso (LinuxCNC's; `linuxcnc` says the same), fanuc, haas, grbl, heidenhain or "
        "sinumerik (default: detected from the content)",
    )


def dialect_name(text: str) -> str:
    """A dialect's name as ncpp knows it (case-insensitive; `linuxcnc` is iso): a name it does not
    know is a usage error, before any program is read."""
    from ncpp.program.dialects import DIALECTS

    name = "iso" if text.lower() == "linuxcnc" else text.lower()
    if name not in DIALECTS:
        raise argparse.ArgumentTypeError(f"unknown dialect {text!r} (known: {', '.join(DIALECTS)}, linuxcnc)")
    return name


@contextlib.contextmanager
def open_input(path: str | None) -> Iterator[tuple[BinaryIO, str]]:
    """The program to read and its name for messages (standard input for none or `-`)."""
    if path is None or path == "-":
        yield sys.stdin.buffer, "<stdin>"
        return
    with open(path, "rb") as stream:
        yield stream, path


@contextlib.contextmanager
def open_output(path: str | None) -> Iterator[BinaryIO]:
    if path is not None and path != "-":
        with atomic_output(Path(path)) as out:
            yield out
        return
    with tempfile.SpooledTemporaryFile(max_size=SPOOL_BYTES) as spool:
        yield spool  # type: ignore[misc]
        spool.seek(0)
        shutil.copyfileobj(spool, sys.stdout.buffer)
        sys.stdout.buffer.flush()
