"""Input and output for NC-program commands.

Output goes to a spool (memory, then a temporary file past a few MB) and
reaches its destination only when the whole program was processed: a file
is replaced atomically, stdout receives nothing if processing failed.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import shutil
import sys
import tempfile
from pathlib import Path
from typing import BinaryIO, Iterator

from ncpp.fileio import atomic_output, program_file

SPOOL_BYTES = 8 << 20


def add_io_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("input", nargs="?", help="NC program (default: standard input)")
    p.add_argument("-o", "--output", help="output file, written atomically (default: standard output)")
    p.add_argument("--strict", action="store_true", help="refuse constructs that would pass through with a warning")
    add_dialect_argument(p)


def add_dialect_argument(p: argparse.ArgumentParser) -> None:
    p.add_argument("--dialect", default=None, help="NC dialect: iso, heidenhain or sinumerik (default: detected from the content)")


@contextlib.contextmanager
def open_input(path: str | None, spool_from: int | None = None) -> Iterator[tuple[BinaryIO, str]]:
    """The program to read and its name for messages.  `spool_from`: standard input that
    is not a program file (a pipe, `fileio.program_file`) and holds at least this many
    bytes is copied to a temporary file first, which can be compensated in two parts
    (`ncpp/parts.py`; the output is written at the end either way); less is read from memory."""
    if path is None or path == "-":
        stdin = sys.stdin.buffer
        if spool_from is None or program_file(stdin) is not None:  # (a file the parts can read themselves)
            yield stdin, "<stdin>"
            return
        with _spooled(stdin, spool_from) as stream:
            yield stream, "<stdin>"
        return
    with open(path, "rb") as stream:
        yield stream, path


@contextlib.contextmanager
def _spooled(stream: BinaryIO, spool_from: int) -> Iterator[BinaryIO]:
    head = stream.read(spool_from) if spool_from else b""
    if spool_from and len(head) < spool_from:  # the whole program, and short
        yield io.BytesIO(head)
        return
    with tempfile.TemporaryDirectory(prefix="ncpp-input-") as folder:
        with open(os.path.join(folder, "stdin.nc"), "w+b") as spool:
            spool.write(head)
            shutil.copyfileobj(stream, spool, 1 << 20)
            spool.seek(0)
            yield spool


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
