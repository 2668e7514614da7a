"""A seeded mutator over real input files, and a worker that runs `ncpp` commands on them.

The mutations are what a damaged file, a wrong file or a hostile one holds: bytes flipped,
lines cut, doubled and spliced from other files, long runs of one token, tokens NC programs
hold (brackets, loops, cycles, huge numbers, control characters).  The worker runs each case
in its own process's `ncpp.cli.main` (a fresh interpreter per case would cost most of the
time budget), each under an alarm, the whole under an address-space limit, and reports the
exit status, what it printed on stderr and whether it ended by an exception, as JSON lines.
"""

from __future__ import annotations

import io
import json
import os
import random
import sys
from contextlib import redirect_stderr
from pathlib import Path

TOKENS = [
    b"[",
    b"]",
    b"(",
    b")",
    b"#<a>",
    b"#1=",
    b"o100 while [1]\n",
    b"o100 endwhile\n",
    b"o100 repeat [1e6]\n",
    b"o100 endrepeat\n",
    b"o<x> call\n",
    b"o<x> sub\n",
    b"G83 X1 Y1 Z-5 R1 Q0.001\n",
    b"G2 X1 Y1 R0.0001 ",
    b"9" * 400,
    b"1e308",
    b"-0",
    b"\x00",
    b"\x1b[2J",
    b"\xff\xfe",
    b"\r",
    b"~\n",
    b";",
    b"%\n",
    b"N",
    b"=",
    b"SIN(",
    b"ATAN2(1)",
    b"MAXVAL(1,2,3)",
    b"Q1 = -8 ^ 0,5\n",
    b"FN 4: Q1 = +6 DIV +2\n",
    b"REPEAT",
    b"GOTOB",
    b"GOTO/",
    b"CIRCLE/",
    b"$$",
    b"= [",
    b"{",
    b"}",
    b'"',
    b"\n\n",
    b",",
    b"nan",
    b"inf",
    b"X",
    b"G",
    b"M98 P1 L9999\n",
]


def mutate(data: bytes, rng: random.Random, others: list[bytes]) -> bytes:
    """`data` with one to four random mutations (bounded: at most 300 kB)."""
    for _ in range(rng.randint(1, 4)):
        data = rng.choice(_MUTATIONS)(data, rng, others)
    return data[:300_000]


def _flip(data: bytes, rng: random.Random, others: list[bytes]) -> bytes:
    if not data:
        return bytes([rng.randrange(256)])
    at = rng.randrange(len(data))
    return data[:at] + bytes([rng.randrange(256)]) + data[at + 1 :]


def _insert(data: bytes, rng: random.Random, others: list[bytes]) -> bytes:
    at = rng.randrange(len(data) + 1)
    return data[:at] + rng.choice(TOKENS) * rng.choice((1, 1, 2, 50, 3000)) + data[at:]


def _cut(data: bytes, rng: random.Random, others: list[bytes]) -> bytes:
    if not data:
        return data
    a = rng.randrange(len(data))
    return data[:a] + data[a + rng.randrange(1, 400) :]


def _lines(data: bytes, rng: random.Random, others: list[bytes]) -> bytes:
    lines = data.split(b"\n")
    k = rng.randrange(len(lines))
    action = rng.randrange(3)
    if action == 0:  # a line repeated
        lines[k:k] = [lines[k]] * rng.choice((2, 10, 500))
    elif action == 1:  # a line from another file
        source = rng.choice(others).split(b"\n")
        lines.insert(k, rng.choice(source))
    else:  # lines swapped
        j = rng.randrange(len(lines))
        lines[k], lines[j] = lines[j], lines[k]
    return b"\n".join(lines)


def _truncate(data: bytes, rng: random.Random, others: list[bytes]) -> bytes:
    return data[: rng.randrange(len(data) + 1)]


_MUTATIONS = (_flip, _flip, _insert, _insert, _insert, _cut, _lines, _lines, _truncate)


class CaseTimeout(BaseException):
    """A case ran past its time."""


def run_cases(cases: list[dict], seconds: float, results: Path) -> None:
    """Run each case (`argv` for `ncpp.cli.main`) and write a JSON line per case to `results`
    (standard output is the program's, which goes nowhere)."""
    import signal
    import traceback

    from ncpp.cli import main

    def expire(signum, frame):
        raise CaseTimeout()

    for case in cases:
        signal.signal(signal.SIGALRM, expire)
        signal.setitimer(signal.ITIMER_REAL, seconds)
        err = io.StringIO()
        result = {"id": case["id"], "status": None, "exception": None}
        try:
            with redirect_stderr(err):
                result["status"] = main(case["argv"])
        except CaseTimeout:
            result["exception"] = "timeout"
        except SystemExit as usage:  # (argparse's: a command line it refuses, said on stderr)
            result["status"] = usage.code
        except BaseException as caught:  # a traceback the user would see
            result["exception"] = "".join(traceback.format_exception(caught))[-3000:]
        finally:
            signal.setitimer(signal.ITIMER_REAL, 0)
        result["stderr"] = "\n".join(line[:400] for line in err.getvalue().splitlines()[-20:])
        result["peak_kb"] = _peak_kb()
        with open(results, "a") as f:
            f.write(json.dumps(result) + "\n")


def _peak_kb() -> int:
    """This process's own peak memory (/proc's VmHWM: getrusage's maxrss keeps that of the
    process it was forked from, the test runner's, across exec)."""
    import resource

    try:
        with open("/proc/self/status") as status:
            return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:"))
    except (OSError, StopIteration):
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


if __name__ == "__main__":
    import resource

    limit = int(sys.argv[2]) << 20
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
    sys.stdout = open(os.devnull, "w")
    run_cases(json.loads(Path(sys.argv[1]).read_text()), float(sys.argv[3]), Path(sys.argv[4]))
