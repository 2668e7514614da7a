"""Where the passes' numeric kernels run: inline, or in one worker process.

A kernel is a picklable callable that takes and returns arrays (and may keep
state from call to call, like the direction each axis holds).  A pass binds
it once and calls it `ahead` chunks before it writes the first of them
(`run_ahead`); the call returns a handle whose `result()` it asks for when it
writes that chunk.  Inline, the kernel runs at the call and nothing runs ahead; either way an
NcppError it raises is raised by `result()`.  With a `Worker`, it runs in a second process while
this one parses, interprets and writes the neighbouring chunks: the numpy work
of compensation and the Python work of the stream overlap on two cores.

The worker runs calls in the order they were made, each kernel on its own
copy, so the numbers (and the output) are the same as inline, bit for bit.
"""

from __future__ import annotations

import os
import pickle
import queue
import subprocess
import sys
import threading
import traceback
from collections import deque
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator, Protocol, TypeVar

from ncpp.errors import NcppError
from ncpp.runtime import keep_freed_memory, one_blas_thread


class Handle(Protocol):
    def result(self) -> Any: ...


class Kernels(Protocol):
    ahead: int  # calls a pass makes before it asks for the first result

    def bind(self, kernel: Callable) -> Callable[..., Handle]: ...

    def close(self) -> None: ...


T = TypeVar("T")


def run_ahead(items: Iterable[T], start: Callable[[T], Handle | None], ahead: int) -> Iterator[tuple[T, Handle | None]]:
    """Each item with the handle `start(item)` gave, `start` having been called for up to
    `ahead` items after it: with a worker the stream reads that far ahead of the results.
    Where reading an item raises an NcppError, the items before it are handed on first."""
    started: deque = deque()
    try:
        for item in items:
            started.append((item, start(item)))
            if len(started) > ahead:
                yield started.popleft()
    except NcppError:
        yield from started
        raise
    yield from started


class _Done:
    """A kernel's result, or the NcppError it raised: raised when the result is asked for,
    as a worker's is (the pass hands on the lines before the refused one first)."""

    __slots__ = ("value", "error")

    def __init__(self, value: Any, error: NcppError | None = None):
        self.value, self.error = value, error

    def result(self) -> Any:
        if self.error is not None:
            raise self.error
        return self.value


class Inline:
    """Kernels run where they are called."""

    ahead = 0  # nothing runs meanwhile: a chunk ahead would only hold memory

    def bind(self, kernel: Callable) -> Callable[..., Handle]:
        def call(*args: Any) -> Handle:
            try:
                return _Done(kernel(*args))
            except NcppError as error:
                return _Done(None, error)

        return call

    def close(self) -> None:
        pass


INLINE = Inline()


class WorkerError(RuntimeError):
    """A kernel failed in the worker with something other than an NcppError,
    or the worker stopped."""


def child_command(code: str) -> list[str]:
    """`python -c code` as ncpp starts a process of its own (with `child_environment`).
    `-P`: no working folder first on the child's import path.  A folder holding another
    ncpp (a checkout of another version) would give the child that one's code: its part
    of a program compensated otherwise, or a worker's numbers, silently."""
    return [sys.executable, "-P", "-c", code]


def child_environment() -> dict[str, str]:
    """The environment of a process ncpp starts (`child_command`): this one's, with its
    import path behind the folder this process's ncpp is in (the child imports the same
    ncpp), and one BLAS thread unless the user said otherwise (`runtime.py`)."""
    home = str(Path(__file__).resolve().parents[2])  # ncpp/passes/kernels.py: the folder holding ncpp
    path = [home, *(p for p in sys.path if p)]
    return one_blas_thread({**os.environ, "PYTHONPATH": os.pathsep.join(path)})


class Worker:
    """Kernels run in one worker process, in call order.

    A fresh interpreter (`python -c`), not a fork: a fork copies whatever
    threads and locks this process holds (BLAS pools, a host application's)
    into a child that cannot use them safely.  Nor multiprocessing's spawn:
    it re-runs the calling script in the child, which an unguarded script
    does not survive.  Requests and replies are pickles on the child's stdin
    and stdout, written and read here by two threads: neither process ever
    waits on a full pipe, and the worker runs ahead of the results asked for."""

    # Two chunks ahead keep the worker busy while this process writes one chunk and
    # reads the next (one ahead left it waiting a sixth of the time); memory: three chunks.
    ahead = 2

    def __init__(self) -> None:
        self._process = subprocess.Popen(
            child_command("from ncpp.passes.kernels import _serve; _serve()"),
            stdin=subprocess.PIPE, stdout=subprocess.PIPE, env=child_environment(),
        )  # fmt: skip
        self._outbox: queue.SimpleQueue = queue.SimpleQueue()
        self._inbox: queue.SimpleQueue = queue.SimpleQueue()
        self._sender = threading.Thread(target=self._send, daemon=True, name="ncpp-kernels-send")
        self._receiver = threading.Thread(target=self._receive, daemon=True, name="ncpp-kernels-receive")
        self._sender.start()
        self._receiver.start()
        self._kernels = 0
        self._calls = 0
        self._received: dict[int, tuple[bool, Any]] = {}

    def _send(self) -> None:
        pipe = self._process.stdin
        try:
            while (request := self._outbox.get()) is not None:
                pickle.dump(request, pipe, protocol=pickle.HIGHEST_PROTOCOL)
                pipe.flush()
            pipe.close()
        except (BrokenPipeError, OSError):  # the worker stopped: `_result` says so
            pass

    def _receive(self) -> None:
        pipe = self._process.stdout
        try:
            while True:
                self._inbox.put(pickle.load(pipe))
        except (EOFError, OSError, pickle.UnpicklingError, ValueError):
            self._inbox.put(None)  # the worker stopped

    def bind(self, kernel: Callable) -> Callable[..., Handle]:
        key = self._kernels
        self._kernels += 1
        self._outbox.put(("bind", key, kernel))

        def call(*args: Any) -> Handle:
            number = self._calls
            self._calls += 1
            self._outbox.put(("call", key, args))
            return _Remote(self, number)

        return call

    def _result(self, number: int) -> Any:
        while number not in self._received:
            reply = self._inbox.get()
            if reply is None:
                self._inbox.put(None)  # for whoever asks next
                raise WorkerError(f"the compensation worker stopped (exit code {self._process.wait()})")
            done, ok, value = reply
            self._received[done] = (ok, value)
        ok, value = self._received.pop(number)
        if not ok:
            raise value
        return value

    def close(self) -> None:
        """Stops the worker (at once if calls are still under way: their results are not wanted)."""
        self._outbox.put(None)
        self._sender.join(timeout=2.0)
        if self._process.poll() is None:
            self._process.terminate()
        self._process.wait()
        self._receiver.join(timeout=2.0)
        self._process.stdout.close()

    def __enter__(self) -> "Worker":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


class _Remote:
    __slots__ = ("worker", "number")

    def __init__(self, worker: Worker, number: int):
        self.worker, self.number = worker, number

    def result(self) -> Any:
        return self.worker._result(self.number)


def _serve() -> None:
    """The worker's loop: bind kernels, run calls in order, send back results or errors."""
    keep_freed_memory()  # the kernels are numpy's: their temporaries reuse the heap (runtime.py)
    requests, replies = sys.stdin.buffer, sys.stdout.buffer
    sys.stdout = sys.stderr  # a stray print must not corrupt the replies
    kernels: dict[int, Callable] = {}
    done = 0
    try:
        while True:
            try:
                kind, key, payload = pickle.load(requests)
            except EOFError:
                return
            if kind == "bind":
                kernels[key] = payload
                continue
            try:
                reply = (done, True, kernels[key](*payload))
            except NcppError as err:  # the user's input: reported as if it ran in the caller
                reply = (done, False, err)
            except Exception:  # a bug: its traceback, as text (it may not pickle)
                reply = (done, False, WorkerError(traceback.format_exc()))
            pickle.dump(reply, replies, protocol=pickle.HIGHEST_PROTOCOL)
            replies.flush()
            done += 1
    except (KeyboardInterrupt, BrokenPipeError):  # the caller is stopping and says why
        pass
