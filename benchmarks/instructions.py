"""Instructions per input line under callgrind: a section of `benchmarks/run.py`.

Time on a shared machine swings by a fifth from one minute to the next, and with it
every ratio of rates; the instructions a program runs do not.  Where the kernel
counts them (`counters.py`) the throughput rows say so; where it refuses, this
section counts them with valgrind's callgrind, which repeats to the instruction
whatever the machine's load: `ncpp compensate` in one process (HR5B, 1 µm, placed as
`compensate_speed` places it) and pygcode's `Line()` on the first LINES lines of each
core file.  A run of SHORT lines is subtracted, so that the start, the imports and the
grammar cancel; each tool runs once untimed first, so that no bytecode is compiled in
a counted run (an edited module compiled there counted as 2% of the work).

Callgrind runs 50-100 times slower than the program: 10k lines take a minute or two.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import tempfile
from itertools import islice
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
LINES = 10_000
SHORT = 60

# The child: one tool over one file (argv: tool, path, work offset x,y,z)
_CHILD = """
import sys
sys.path[:0] = {path!r}
from pathlib import Path
tool, path = sys.argv[1], Path(sys.argv[2])
if tool == "pygcode":
    import run
    run.pygcode_rate(path)
else:
    import compensate_speed
    compensate_speed.ncpp_process_rate(path, tuple(map(float, sys.argv[3].split(","))))
"""


def _run(tool: str, path: Path, offset: str, valgrind: tuple[str, ...] = ()) -> subprocess.CompletedProcess:
    """The child that runs `tool` ("ncpp" or "pygcode") over `path`, started as ncpp starts its
    own (one BLAS thread), with a fixed hash seed; under `valgrind` when given."""
    from ncpp.runtime import one_blas_thread  # (imported when the section runs, as compensate_speed's)

    # -P: the working folder is not put first on the child's path (it may hold another ncpp)
    command = [
        *valgrind,
        sys.executable,
        "-P",
        "-c",
        _CHILD.format(path=[str(HERE), str(ROOT)]),
        tool,
        str(path),
        offset,
    ]
    return subprocess.run(
        command,
        capture_output=True,
        text=True,
        env=one_blas_thread({**os.environ, "PYTHONHASHSEED": "0"}),
        check=False,
    )


def counted(tool: str, path: Path, offset: str, workdir: Path) -> int:
    """Instructions callgrind counts for `tool` over `path`, the whole process."""
    out = workdir / "callgrind.out"
    done = _run(tool, path, offset, ("valgrind", "--tool=callgrind", f"--callgrind-out-file={out}"))
    out.unlink(missing_ok=True)
    found = re.search(r"Collected : (\d+)", done.stderr)
    if done.returncode != 0 or found is None:
        raise RuntimeError(f"callgrind {tool} {path.name}: exit {done.returncode}: {done.stderr[-1500:]}")
    return int(found.group(1))


def per_line(tool: str, path: Path, offset: str, workdir: Path, lines: int = LINES) -> dict[str, Any]:
    """Instructions per input line of `tool` on the first `lines` lines of `path`: the
    difference of a run over them and one over the first SHORT, over the lines between."""
    heads = {}
    with open(path, "rb") as f:
        text = list(islice(f, lines))
    for n in (len(text), SHORT):
        heads[n] = workdir / f"head-{n}-{path.name}"
        heads[n].write_bytes(b"".join(text[:n]))
    warm = _run(tool, heads[SHORT], offset)  # compiles the bytecode, fills the grammar cache
    if warm.returncode != 0:
        raise RuntimeError(f"{tool} {path.name}: exit {warm.returncode}: {warm.stderr[-1500:]}")
    long, short = (counted(tool, heads[n], offset, workdir) for n in (len(text), SHORT))
    return {
        "lines": len(text) - SHORT,
        "instructions": long - short,
        "per_line": (long - short) / (len(text) - SHORT),
    }


def instructions(ctx):
    import run as bench
    from compensate_speed import work_offset

    Section = bench.Section
    if shutil.which("valgrind") is None:
        return Section("Instructions per input line (callgrind)", ["program", "tool", "k per line", "note"], [], {},
                       ["valgrind is not installed here: nothing counted"])  # fmt: skip
    programs = ctx.programs or ({} if ctx.quick else {"stellabee1.ngc": bench.STELLABEE}) | {
        "generated": ctx.generated(LINES)
    }
    rows, data = [], {}
    with tempfile.TemporaryDirectory(prefix="ncpp-callgrind-") as tmp:
        for label, path in programs.items():
            offset = ",".join(map(str, work_offset(path)))
            ncpp = per_line("ncpp", path, offset, Path(tmp))
            pygcode = per_line("pygcode", path, offset, Path(tmp))
            data[label] = {"ncpp_compensate_one_process": ncpp, "pygcode": pygcode}
            ratio = pygcode["per_line"] / ncpp["per_line"]
            rows += [
                [
                    label,
                    "ncpp compensate 1 µm (HR5B), one process",
                    f"{ncpp['per_line'] / 1000:.0f}",
                    f"lines {SHORT + 1:,}-{SHORT + ncpp['lines']:,}",
                ],
                [label, "pygcode Line()", f"{pygcode['per_line'] / 1000:.0f}", ""],
                [
                    label,
                    "pygcode / ncpp",
                    f"{ratio:.2f}x",
                    "at equal instructions per second, the ratio of the rates",
                ],
            ]
    notes = [
        f"the first {LINES:,} lines, less a run over the first {SHORT}; valgrind's callgrind, PYTHONHASHSEED=0"
    ]
    return Section(
        "Instructions per input line (callgrind)",
        ["program", "tool", "k per line", "note"],
        rows,
        data,
        notes,
    )
