"""Where the passes' numeric kernels run: inline, or in one worker process.

A kernel is a picklable callable that takes and returns arrays (and may keep
state from call to call, like the direction each axis holds).  A pass binds
it once and calls it a chunk ahead of the events it writes; the call returns
a handle whose `result()` it asks for when it writes that chunk.  Inline, the
kernel runs at the call.  With a `Worker`, it runs in a second process while
this one parses, interprets and writes the neighbouring chunks: the numpy work
of compensation and the Python work of the stream overlap on two cores.

The worker runs calls in the order they were made, each kernel on its own
copy, so the numbers (and the output) are the same as inline, bit for bit.
"""

from __future__ import annotations

import multiprocessing
import queue
import traceback
from typing import Any, Callable, Protocol

from ncpp.errors import NcppError


class Handle(Protocol):
    def result(self) -> Any: ...


class Kernels(Protocol):
    def bind(self, kernel: Callable) -> Callable[..., Handle]: ...

    def close(self) -> None: ...


class _Done:
    __slots__ = ("value",)

    def __init__(self, value: Any):
        self.value = value

    def result(self) -> Any:
        return self.value


class Inline:
    """Kernels run where they are called."""

    def bind(self, kernel: Callable) -> Callable[..., Handle]:
        return lambda *args: _Done(kernel(*args))

    def close(self) -> None:
        pass


INLINE = Inline()


class WorkerError(RuntimeError):
    """A kernel failed in the worker with something other than an NcppError."""


class Worker:
    """Kernels run in one spawned worker process, in call order.

    Spawned, not forked: a fork copies whatever threads and locks this process
    holds (BLAS pools, FreeCAD's) into a child that cannot use them safely.
    The queues' feeder threads keep either side from blocking on a full pipe
    while the other is blocked too."""

    POLL_S = 1.0  # how often a wait checks that the worker is still alive

    def __init__(self) -> None:
        context = multiprocessing.get_context("spawn")
        self._requests = context.Queue()
        self._replies = context.Queue()
        self._process = context.Process(target=_serve, args=(self._requests, self._replies), daemon=True, name="ncpp-kernels")
        self._process.start()
        self._kernels = 0
        self._calls = 0
        self._received: dict[int, tuple[bool, Any]] = {}

    def bind(self, kernel: Callable) -> Callable[..., Handle]:
        key = self._kernels
        self._kernels += 1
        self._requests.put(("bind", key, kernel))

        def call(*args: Any) -> Handle:
            number = self._calls
            self._calls += 1
            self._requests.put(("call", key, args))
            return _Remote(self, number)

        return call

    def _result(self, number: int) -> Any:
        while number not in self._received:
            try:
                done, ok, value = self._replies.get(timeout=self.POLL_S)
            except queue.Empty:
                if not self._process.is_alive():
                    raise WorkerError(f"the compensation worker stopped (exit code {self._process.exitcode})") from None
                continue
            self._received[done] = (ok, value)
        ok, value = self._received.pop(number)
        if not ok:
            raise value
        return value

    def close(self) -> None:
        """Stops the worker (at once if calls are still under way: their results are not wanted)."""
        if self._process.is_alive():
            self._requests.put(None)
            self._process.join(timeout=2.0)
        if self._process.is_alive():
            self._process.terminate()
            self._process.join()
        self._requests.close()
        self._replies.close()

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


def _serve(requests: Any, replies: Any) -> None:
    """The worker's loop: bind kernels, run calls in order, send back results or errors."""
    kernels: dict[int, Callable] = {}
    done = 0
    try:
        while (request := requests.get()) is not None:
            kind, key, payload = request
            if kind == "bind":
                kernels[key] = payload
                continue
            try:
                replies.put((done, True, kernels[key](*payload)))
            except NcppError as err:  # the user's input: reported as if it ran here
                replies.put((done, False, err))
            except Exception:  # a bug: its traceback, as text (it may not pickle)
                replies.put((done, False, WorkerError(traceback.format_exc())))
            done += 1
    except KeyboardInterrupt:  # the main process is stopping too and says so
        pass
