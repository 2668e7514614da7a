"""Program files a Sinumerik or Klartext program calls, found on the subroutine path.

A control keeps a called program under its name in its own file system; on a PC ncpp is
told the folders that hold copies of them (`--subroutine-path`, as LinuxCNC's
SUBROUTINE_PATH for o-word calls: only those folders are searched).  Both controls ignore
case in program names, so a file is matched by name without case; the first folder (in
the order given) that holds one of the names wins, the names tried in the order given.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

from ncpp.errors import Location, NcppError
from ncpp.motion.flow import MAX_RERUN
from ncpp.program.blocks import Block
from ncpp.program.parser import parse_stream

# Blocks of one called file held in memory (its text is run, perhaps many times, from there)
MAX_CALLED_BLOCKS = 200_000


class Files:
    """The files an interpreter's calls name, looked up once per name (a call in a loop is
    looked up once) and read once per file."""

    def __init__(self, folders: Sequence[Path], dialect: str):
        self.folders, self.dialect = tuple(folders), dialect
        self._found: dict[tuple[str, ...], Path | None] = {}
        self._read: dict[Path, list[Block]] = {}

    def find(self, names: Sequence[str]) -> Path | None:
        key = tuple(names)
        if key not in self._found:
            self._found[key] = find_file(self.folders, names)
        return self._found[key]

    def blocks(self, path: Path) -> list[Block]:
        if path not in self._read:
            self._read[path] = read_blocks(path, self.dialect)
        return self._read[path]


def find_file(folders: Sequence[Path], names: Sequence[str]) -> Path | None:
    """The first file of `names` (any case) in the first folder of `folders` that holds one."""
    for folder in folders:
        try:
            entries = {entry.lower(): entry for entry in os.listdir(folder)}
        except OSError:
            continue
        for name in names:
            found = entries.get(name.lower())
            if found is not None and (Path(folder) / found).is_file():
                return Path(folder) / found
    return None


def searched(folders: Sequence[Path], names: Sequence[str]) -> str:
    """Where a called file was looked for, for a message."""
    if not folders:
        return "no --subroutine-path gives the folders of called files"
    return f"none of {', '.join(names)} in {os.pathsep.join(map(str, folders))}"


def count_called(count: int, file: str, caller: Block) -> int:
    """`count` blocks run in called files, and one more: past MAX_RERUN the program is taken for
    one that never ends (calls nested and repeated multiply) and refused at the calling line."""
    if count >= MAX_RERUN:
        raise NcppError(f"more than {MAX_RERUN:,} blocks run in called files: a program that never ends "
                        "(ncpp follows a program to its end)", Location(file, caller.line, None))  # fmt: skip
    return count + 1


def read_blocks(path: Path, dialect: str) -> list[Block]:
    """The blocks of a called file (a parse error is reported at its line in that file)."""
    blocks: list[Block] = []
    with open(path, "rb") as stream:
        for block in parse_stream(stream, str(path), dialect):
            blocks.append(block)
            if len(blocks) > MAX_CALLED_BLOCKS:
                raise NcppError(
                    f"a called file of more than {MAX_CALLED_BLOCKS:,} blocks (ncpp holds a called "
                    "file in memory while it runs)",
                    Location(str(path), block.line, None),
                )
    return blocks
