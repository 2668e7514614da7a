"""Atomic output files: written to a temporary file beside the target and
renamed into place only when complete, so a failed run never leaves a
partial program or table behind (on Linux an anonymous file, named only then,
so that not even a killed run leaves one).  And what the program files read are: their
paths (`program_file`) and line counts."""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import shutil
import stat
import tempfile
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import BinaryIO

from ncpp.errors import Location, NcppError


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike[str]) -> Iterator[BinaryIO]:
    """Yield a binary file; on clean exit it replaces `path`, on error it vanishes.

    A symbolic link is written through: its target is replaced, the link kept.  A file
    that is not a regular one (`/dev/null`, a FIFO) is never replaced: it receives the
    output, kept aside until complete, written into it."""
    target = Path(os.path.realpath(path))
    try:
        held = os.stat(target)
    except FileNotFoundError:
        held = None
    if held is not None and not stat.S_ISREG(held.st_mode):
        with _into_special(target) as out:
            yield out
        return
    with _beside(target) as (out, put_in_place):
        yield out
        out.flush()
        os.fsync(out.fileno())
        os.chmod(out.fileno(), held.st_mode & 0o777 if held is not None else 0o666 & ~_umask())
        put_in_place()


@contextlib.contextmanager
def _into_special(target: Path) -> Iterator[BinaryIO]:
    """Output for a device or a FIFO, written into it once complete."""
    if stat.S_ISDIR(os.stat(target).st_mode):
        raise IsADirectoryError(errno.EISDIR, os.strerror(errno.EISDIR), str(target))
    with tempfile.TemporaryFile() as spool:
        yield spool
        spool.seek(0)
        with open(target, "wb") as out:  # (no truncation or replacing for such a file: it is written)
            shutil.copyfileobj(spool, out, 1 << 20)


@contextlib.contextmanager
def _beside(target: Path) -> Iterator[tuple[BinaryIO, Callable[[], None]]]:
    """A file in the target's folder, and the call that puts it in the target's place.  Where
    Linux makes one, an anonymous file (O_TMPFILE) named only then, which a SIGKILL leaves no
    trace of; elsewhere a named temporary, removed on error (a SIGTERM is one: `cli`)."""
    fd = _anonymous_file(target.parent)
    named: list[str | None] = [None]
    if fd is None:
        fd, named[0] = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=str(target.parent))

    def put_in_place() -> None:
        name = named[0] if named[0] is not None else _link_beside(fd, target)
        named[0] = name
        os.replace(name, target)

    try:
        with os.fdopen(fd, "wb") as out:
            yield out, put_in_place
    except BaseException:
        if named[0] is not None:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(named[0])
        raise


def _anonymous_file(folder: Path) -> int | None:
    """A descriptor of a new file in `folder` no name holds (Linux's O_TMPFILE, mode from the umask
    as for any file created), or None where the system or its file system makes none."""
    flag = getattr(os, "O_TMPFILE", None)
    if flag is None or not os.path.isdir("/proc/self/fd"):  # (`_link_beside` names it through /proc)
        return None
    try:
        return os.open(folder, flag | os.O_WRONLY, 0o666)
    except OSError as err:
        if err.errno in (errno.EOPNOTSUPP, errno.EISDIR, errno.EINVAL):
            return None
        raise


def _link_beside(fd: int, target: Path) -> str:
    """A name beside `target` given to the anonymous file `fd` (a name no file holds yet)."""
    folder = os.open(target.parent, os.O_RDONLY | os.O_DIRECTORY)
    try:
        while True:
            name = f".{target.name}.{secrets.token_hex(4)}.tmp"
            try:  # (a folder's descriptor: Python 3.11's os.link calls linkat, which follows /proc's link)
                os.link(f"/proc/self/fd/{fd}", name, dst_dir_fd=folder, follow_symlinks=True)
                return str(target.parent / name)
            except FileExistsError:
                continue
    finally:
        os.close(folder)


def _umask() -> int:
    """This process's umask: Linux says it in /proc; elsewhere it is set and set back."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status", encoding="ascii", errors="replace") as status:
            for line in status:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def write_text_atomic(path: str | os.PathLike[str], text: str, encoding: str = "utf-8") -> None:
    with atomic_output(path) as out:
        out.write(text.encode(encoding))


def write_bytes_atomic(path: str | os.PathLike[str], data: bytes) -> None:
    with atomic_output(path) as out:
        out.write(data)


# Input files that are settings, not programs (machine files, parameter files, tool tables,
# ncpp.toml, LinuxCNC's INI, measurement files) are read whole: past this size a path names no
# such file (`/dev/zero` never ends) and is refused before it fills the memory.
SMALL_FILE_BYTES = 64 << 20


def read_small(path: str | os.PathLike[str], what: str, limit: int = SMALL_FILE_BYTES) -> bytes:
    """The bytes of a settings file `what` (for the message); NcppError if it holds more than `limit`."""
    with open(path, "rb") as f:
        data = f.read(limit + 1)
    if len(data) > limit:
        raise NcppError(f"not {what}: it holds more than {limit >> 20} MB", Location(os.fspath(path), 1, 1))
    return data


def count_lines(path: str | os.PathLike[str]) -> int:
    """The lines of a file (its newlines, and a last line without one), read a megabyte at a time."""
    count, last = 0, b"\n"
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            count += chunk.count(b"\n")
            last = chunk[-1:]
    return count + (last != b"\n")


def program_file(stream: BinaryIO) -> str | None:
    """The path of the regular file `stream` reads, not read yet: its name, or for standard
    input redirected from a file (`ncpp compensate ... < in.nc`, no name) the file Linux
    says the descriptor holds; None for a pipe, a terminal, a file read from elsewhere
    than its start, or a file no path names any more or this process may not open."""
    try:
        if stream.tell() != 0:
            return None
        fd = stream.fileno()
        held = os.fstat(fd)
    except (OSError, ValueError, AttributeError):  # (io.UnsupportedOperation is an OSError)
        return None
    if not stat.S_ISREG(held.st_mode):
        return None
    named = getattr(stream, "name", None)
    candidates = [named] if isinstance(named, str) else []
    candidates.append(f"/proc/self/fd/{fd}")  # (Linux: a link to the file the descriptor holds)
    for candidate in candidates:
        path = os.path.realpath(candidate)
        try:
            # (a deleted file's link names no file; the parts open the path, so it must be readable)
            if os.path.samestat(os.stat(path), held) and os.access(path, os.R_OK):
                return path
        except OSError:
            pass
    return None


# How far up from a written file's folder an input may be and still be named by its relative path
# (`samples/story/cold/x.csv` from `samples/story/model.toml`; farther off, a relative path names
# the build machine's folders as an absolute one would).
PORTABLE_LEVELS_UP = 2


def portable_name(source: str | os.PathLike[str], written: str | os.PathLike[str]) -> str:
    """How a file that writes `written` names an input `source` so that it means the same on another
    machine: its path relative to the written file's folder, or where that climbs more than
    PORTABLE_LEVELS_UP folders, its name and sha256 (a path there would name this machine's folders)."""
    path = Path(source)
    if not path.is_file():  # standard input, a stream: nothing on disk to point at
        return str(source)
    try:
        relative = Path(os.path.relpath(path.resolve(), Path(written).resolve().parent))
    except ValueError:  # (another drive)
        relative = Path(*[".."] * (PORTABLE_LEVELS_UP + 1))
    if relative.parts[: PORTABLE_LEVELS_UP + 1].count("..") <= PORTABLE_LEVELS_UP:
        return relative.as_posix()
    import hashlib

    return f"{path.name} sha256:{hashlib.sha256(path.read_bytes()).hexdigest()[:16]}"


def rebased_name(name: str, old: str | os.PathLike[str], new: str | os.PathLike[str]) -> str:
    """`name` (a path, maybe followed by " [what]") written in file `old`, as file `new` names it:
    a relative path that names a file beside `old` is named afresh (`portable_name`); others stay."""
    path, space, rest = name.partition(" ")
    beside = Path(old).parent / path
    if Path(path).is_absolute() or not beside.is_file():
        return name
    return portable_name(beside, new) + space + rest
