"""Built once per user, loaded after: things that take a while to build from files
that ship with ncpp (the grammars' LALR tables).

The cache is a folder of the user's own (`$NCPP_CACHE`, else `$XDG_CACHE_HOME/ncpp`,
else `~/.cache/ncpp`; `NCPP_CACHE=` empty turns it off): what it holds is
unpickled, which runs code, so an entry is read only from a folder the user owns and
nobody else may write to, and only when the user owns it and nobody else may write to
it (checked on the opened file, before each read); otherwise it is built in memory.  An entry's name carries a
digest of everything it was built from, so a changed grammar or library version
builds anew; entries are written atomically, and one that cannot be read or
written is built in memory as if there were no cache.
"""

from __future__ import annotations

import hashlib
import os
import stat
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import BinaryIO, Protocol, TypeVar


class Savable(Protocol):
    def save(self, f: BinaryIO) -> None: ...


T = TypeVar("T", bound=Savable)


def cache_folder() -> Path | None:
    """Where entries are kept (None: nowhere)."""
    chosen = os.environ.get("NCPP_CACHE")
    if chosen is not None:
        return Path(chosen) if chosen else None
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "ncpp"


def cached_build(name: str, source: str, build: Callable[[], T], load: Callable[[BinaryIO], T]) -> T:
    """The object `build()` makes from `source` (text), kept under `name`; `load` reads
    back what the object's `save(file)` wrote."""
    folder = cache_folder()
    if folder is None:
        return build()
    version = ".".join(map(str, sys.version_info[:2]))
    path = folder / f"{name}-{hashlib.sha256(f'{source}{version}'.encode()).hexdigest()[:20]}.pickle"
    if not _private(folder):
        return build()
    try:
        with _open_private(path) as f:
            return load(f)
    except Exception:  # missing, another's, or unreadable (another version's pickle): build it
        pass
    made = build()
    _save(made, path)
    return made


def _owned_and_closed(held: os.stat_result) -> bool:
    """Whether the user owns it and neither group nor others may write to it."""
    return held.st_uid == os.geteuid() and not held.st_mode & (stat.S_IWGRP | stat.S_IWOTH)


def _private(folder: Path) -> bool:
    """Whether the cache folder is the user's alone (made so when missing)."""
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        held = os.stat(folder, follow_symlinks=False)
    except OSError:
        return False
    return stat.S_ISDIR(held.st_mode) and _owned_and_closed(held)


def _open_private(path: Path) -> BinaryIO:
    """The entry, opened without following a link, if it is the user's alone (else OSError)."""
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    held = os.fstat(fd)
    if not (stat.S_ISREG(held.st_mode) and _owned_and_closed(held)):
        os.close(fd)
        raise PermissionError(f"{path} is not the user's alone")
    return os.fdopen(fd, "rb")


def _save(made: Savable, path: Path) -> None:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        handle, temporary = tempfile.mkstemp(dir=path.parent, prefix=path.name, suffix=".part")
        try:
            with os.fdopen(handle, "wb") as f:
                made.save(f)
            os.replace(temporary, path)
        except BaseException:
            os.unlink(temporary)
            raise
    except OSError:  # a read-only home: no cache, same results
        pass
