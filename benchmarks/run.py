"""ncpp benchmarks: throughput against pygcode and LinuxCNC's rs274, and memory.

    python benchmarks/run.py [--quick]

One run measures every tool on the same files and prints a table; the
figures also go to benchmarks/out/results.json.  See benchmarks/README.md.

A benchmark is a *section*: a function `(Context) -> Section` listed in
SECTIONS.  Later benchmarks (compensation throughput, accuracy) are added
by writing one more such function and appending it to SECTIONS.
"""

from __future__ import annotations

import argparse
import io
import json
import os
import platform
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))  # measure the checkout, not an installed copy
sys.path.insert(0, str(HERE))

from generate import generate  # noqa: E402

SHARED = Path(os.environ.get("NCPP_SHARED", ROOT.parent / "shared"))
STELLABEE = SHARED / "corpus/iso_gcode/linuxcnc/large/stellabee1.ngc"
# LinuxCNC's 3D_Chips sample, twice: a parameter expression in every line (the LALR parser's lines)
PARAMETRIC = SHARED / "corpus/iso_gcode/linuxcnc/large/3D_Chips_abort.ngc"
RS274 = SHARED / "tools/rs274"
OUT = HERE / "out" / "results.json"
PYGCODE_FLOOR = 2.0  # the floor: ncpp parse+interpret at least twice pygcode's parse rate


@dataclass
class Context:
    quick: bool
    workdir: Path  # temporary; generated programs live here and are deleted at the end
    programs: dict[str, Path] = field(default_factory=dict)  # label -> program used by every tool

    def generated(self, lines: int) -> Path:
        """A generated program of `lines` lines (made once per run, seed fixed)."""
        path = self.workdir / f"generated-{lines}.ngc"
        if not path.exists():
            generate(path, lines)
        return path


@dataclass
class Section:
    title: str
    columns: list[str]
    rows: list[list[Any]]
    data: dict[str, Any]  # what goes into results.json
    notes: list[str] = field(default_factory=list)


# -- the tools being measured -------------------------------------------------


def count_lines(path: Path) -> int:
    with open(path, "rb") as f:
        return sum(chunk.count(b"\n") for chunk in iter(lambda: f.read(1 << 20), b""))


def interpreter() -> Callable | None:
    """ncpp.motion.interpret, when the motion interpreter exists in this checkout."""
    try:
        from ncpp.motion import interpret
    except ImportError:
        return None
    return interpret


def ncpp_rate(path: Path, interpret: Callable | None) -> dict[str, Any]:
    """Parse (and interpret) a program in this process; lines/s over the lines read.

    The interpreter stops at a construct outside its scope (with a warning):
    `lines` then counts the lines it consumed, and `warnings` says so.
    """
    from ncpp.errors import NcppError, Warnings
    from ncpp.program.parser import parse_stream

    warnings, events, error = io.StringIO(), None, ""
    start = time.perf_counter()
    with open(path, "rb") as stream:
        counted = _Counter(parse_stream(stream, str(path)))
        try:
            if interpret is None:
                for _ in counted:
                    pass
            else:
                events = sum(
                    1 for _ in interpret(counted, file=str(path), warnings=Warnings(stream=warnings))
                )
        except NcppError as err:
            error = str(err)
    seconds = time.perf_counter() - start
    return {
        "lines": counted.count,
        "seconds": seconds,
        "lines_per_s": counted.count / seconds,
        "events": events,
        "warnings": warnings.getvalue().splitlines()[:5],
        "error": error,
    }


class _Counter:
    """Passes blocks through and counts them."""

    def __init__(self, blocks: Iterable):
        self.blocks, self.count = blocks, 0

    def __iter__(self):
        for block in self.blocks:
            self.count += 1
            yield block


def pygcode_rate(path: Path) -> dict[str, Any]:
    """pygcode `Line()` on every line; lines it refuses are counted, by error type."""
    import pygcode

    failures: dict[str, int] = {}
    lines = 0
    start = time.perf_counter()
    with open(path, "rb") as stream:
        for raw in stream:
            lines += 1
            try:
                pygcode.Line(raw.decode("latin-1").rstrip("\r\n"))
            except Exception as err:  # pygcode raises several types; all count as a refusal
                failures[type(err).__name__] = failures.get(type(err).__name__, 0) + 1
    seconds = time.perf_counter() - start
    return {
        "lines": lines,
        "seconds": seconds,
        "lines_per_s": lines / seconds,
        "failed_lines": sum(failures.values()),
        "failures": failures,
        "version": getattr(pygcode, "__version__", "?"),
    }


def rs274_rate(path: Path, lines: int) -> dict[str, Any]:
    """Wall time of the whole rs274 process (canonical calls to /dev/null)."""
    start = time.perf_counter()
    proc = subprocess.run([str(RS274), str(path)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    seconds = time.perf_counter() - start
    message = proc.stderr.decode("latin-1").replace("executing", "").strip()
    return {
        "lines": lines,
        "seconds": seconds,
        "lines_per_s": lines / seconds,
        "completed": proc.returncode == 0,
        "error": message if proc.returncode else "",
    }


# Runs a command and writes its peak RSS (kB) to argv[1].  Needed because Linux
# carries ru_maxrss across fork/vfork + exec: a child spawned straight from this
# (large) benchmark process reports this process's RSS whenever that is larger
# than its own.  Spawned from this small probe, the child's figure is its own.
_RSS_PROBE = """
import os, subprocess, sys
child = subprocess.Popen(sys.argv[2:])
_, status, usage = os.wait4(child.pid, 0)
open(sys.argv[1], "w").write(str(usage.ru_maxrss))
sys.exit(os.waitstatus_to_exitcode(status))
"""


def peak_rss(path: Path, command: list[str] | None = None) -> dict[str, Any]:
    """Peak RSS of `python -m ncpp [command] < path > /dev/null`, measured by a small probe process."""
    report = path.with_name(path.name + ".rss")
    start = time.perf_counter()
    with open(path, "rb") as stdin:
        proc = subprocess.run(
            [sys.executable, "-c", _RSS_PROBE, str(report), sys.executable, "-m", "ncpp", *(command or [])],
            stdin=stdin,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            cwd=path.parent,  # no ./ncpp.toml there: the filter passes the program through (after interpreting it)
            env={**{k: v for k, v in os.environ.items() if k != "NCPP_MACHINE"}, "PYTHONPATH": str(ROOT)},
        )
    seconds = time.perf_counter() - start
    kilobytes = int(report.read_text())
    report.unlink()
    return {
        "rss_mb": kilobytes / 1024,  # Linux reports kB
        "seconds": seconds,
        "exit": proc.returncode,
        "stderr_tail": proc.stderr.decode("latin-1")[-300:],
    }


# -- sections -----------------------------------------------------------------


def throughput(ctx: Context) -> Section:
    """Lines/s of ncpp, pygcode and rs274 on the same files."""
    lines_generated = 250_000 if ctx.quick else 1_000_000
    ctx.programs = {
        "stellabee1.ngc": STELLABEE,
        f"generated {lines_generated:,} lines": ctx.generated(lines_generated),
    }
    interpret = interpreter()
    rows, data = [], {}
    for label, path in {**ctx.programs, "3D_Chips_abort.ngc (expressions)": PARAMETRIC}.items():
        lines = count_lines(path)
        parse = ncpp_rate(path, None)
        full = ncpp_rate(path, interpret) if interpret else None
        ours = full or parse
        pyg = pygcode_rate(path)
        rs = rs274_rate(path, lines)
        data[label] = {
            "path": str(path),
            "lines": lines,
            "ncpp_parse": parse,
            "ncpp_parse_interpret": full,
            "pygcode": pyg,
            "rs274": rs,
            "ratio_ncpp_pygcode": ours["lines_per_s"] / pyg["lines_per_s"],
            "ratio_ncpp_rs274": ours["lines_per_s"] / rs["lines_per_s"],
        }
        rows.append([label, "ncpp parse", _rate(parse), _stopped(parse, lines).lstrip("; ")])
        if full:
            rows.append(
                [
                    label,
                    "ncpp parse+interpret",
                    _rate(full),
                    f"{full['events'] or 0:,} events" + _stopped(full, lines),
                ]
            )
        rows.append([label, "pygcode Line()", _rate(pyg), f"{pyg['failed_lines']:,} lines refused"])
        rows.append(
            [
                label,
                "rs274 (process)",
                _rate(rs),
                "completed" if rs["completed"] else f"STOPPED: {rs['error']}",
            ]
        )
        what = "parse+interpret" if full else "parse"
        ratio = data[label]["ratio_ncpp_pygcode"]
        floor = (
            f"floor {PYGCODE_FLOOR:.2f}x: " + ("ok" if ratio >= PYGCODE_FLOOR else "SHORT") if full else ""
        )
        if label not in ctx.programs:  # not a core file: pygcode refuses its expressions
            floor = "no floor (pygcode refuses the expression lines)"
        rows.append([label, f"ratio ncpp {what} / pygcode", f"{ratio:.2f}x", floor])
        rows.append([label, f"ratio ncpp {what} / rs274", f"{data[label]['ratio_ncpp_rs274']:.2f}x", ""])
    notes = [] if interpret else ["ncpp.motion.interpret is not importable yet: ncpp figures are parse only."]
    data["interpreter_available"] = interpret is not None
    return Section(
        "Throughput (lines/s, one pass over each file)",
        ["program", "tool", "lines/s", "note"],
        rows,
        data,
        notes,
    )


def memory(ctx: Context) -> Section:
    """Peak RSS of the `ncpp` filter process for growing program lengths."""
    sizes = [10_000, 300_000, 1_000_000] if ctx.quick else [10_000, 1_000_000, 10_000_000]
    rows, data = [], {}
    for lines in sizes:
        path = ctx.generated(lines)
        size_mb = path.stat().st_size / 1e6
        result = peak_rss(path)
        if lines >= 10_000_000:
            path.unlink()  # ~300 MB
        data[str(lines)] = {"lines": lines, "file_mb": size_mb, **result}
        status = (
            "ok" if result["exit"] == 0 else f"exit {result['exit']}: {result['stderr_tail'].strip()[-120:]}"
        )
        rows.append(
            [
                f"{lines:,}",
                f"{size_mb:.0f}",
                f"{result['rss_mb']:.1f}",
                f"{lines / result['seconds']:,.0f}",
                status,
            ]
        )
    rss = [v["rss_mb"] for v in data.values()]
    data["growth_mb"] = rss[-1] - rss[1]  # the smallest program does not fill the filter's 8 MB output spool
    notes = [
        f"peak RSS from {sizes[1]:,} to {sizes[-1]:,} lines grows by {data['growth_mb']:+.1f} MB",
        f"{sizes[0]:,} lines stay under the filter's 8 MB in-memory output spool; longer programs spill it to a file",
    ]
    return Section(
        "Memory: `python -m ncpp < program > /dev/null`",
        ["lines", "file MB", "peak RSS MB", "lines/s", "status"],
        rows,
        data,
        notes,
    )


# Add later benchmarks (compensation throughput, accuracy) here.
SECTIONS: list[Callable[[Context], Section]] = [throughput, memory]


def _compensation_sections() -> list[Callable[[Context], Section]]:
    from accuracy import accuracy
    from compensate_speed import compensate_speed, dialect_speed
    from instructions import instructions

    return [compensate_speed, instructions, dialect_speed, accuracy]


SECTIONS += _compensation_sections()


# -- running and reporting --------------------------------------------------------


def _stopped(result: dict[str, Any], lines: int) -> str:
    if result["lines"] >= lines and not result["error"]:
        return ""
    why = result["error"] or (result["warnings"] or ["?"])[0]
    return f"; STOPPED after {result['lines']:,} lines: {why}"


def _rate(result: dict[str, Any]) -> str:
    return f"{result['lines_per_s']:,.0f}"


def render(section: Section) -> str:
    table = [section.columns] + [[str(c) for c in row] for row in section.rows]
    widths = [max(len(row[i]) for row in table) for i in range(len(section.columns))]
    lines = [f"\n## {section.title}", ""]
    for n, row in enumerate(table):
        lines.append(
            "  ".join(cell.rjust(w) if cell[:1].isdigit() else cell.ljust(w) for cell, w in zip(row, widths))
        )
        if n == 0:
            lines.append("  ".join("-" * w for w in widths))
    lines += [f"  * {note}" for note in section.notes]
    return "\n".join(lines)


def cpu() -> str:
    """The processor as Linux names it, with its family and model: a VM may name only the
    vendor, and the same code's ratio to pygcode differs from one processor to another."""
    try:
        facts = dict(
            line.split(":", 1) for line in Path("/proc/cpuinfo").read_text().splitlines() if ":" in line
        )
    except OSError:
        return platform.processor() or platform.machine()
    facts = {key.strip(): value.strip() for key, value in facts.items()}
    return f"{facts.get('model name', '?')} (family {facts.get('cpu family', '?')}, model {facts.get('model', '?')})"


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description="ncpp throughput and memory benchmarks")
    p.add_argument(
        "--quick",
        action="store_true",
        help="smaller programs, no 10M-line run (throughput and memory in about 2 minutes; compensate_speed about 5)",
    )
    p.add_argument("--only", nargs="*", help="names of sections to run (default: all)")
    p.add_argument("--out", type=Path, default=OUT, help=f"JSON results (default: {OUT.relative_to(ROOT)})")
    args = p.parse_args(argv)
    unknown = sorted(set(args.only or ()) - {run.__name__ for run in SECTIONS})
    if unknown:  # a misspelt name would run nothing and say nothing
        p.error(
            f"no section named {', '.join(unknown)} (sections: {', '.join(run.__name__ for run in SECTIONS)})"
        )

    started = time.perf_counter()
    results: dict[str, Any] = {
        "quick": args.quick,
        "python": sys.version.split()[0],
        "machine": platform.platform(),
        "cpu": cpu(),
        "cpus": os.cpu_count(),
        "started": time.strftime("%Y-%m-%dT%H:%M:%S"),
        "sections": {},
    }
    print(f"{results['cpu']}, {results['cpus']} cores; Python {results['python']}", flush=True)
    with tempfile.TemporaryDirectory(prefix="ncpp-bench-") as tmp:
        ctx = Context(quick=args.quick, workdir=Path(tmp))
        for run in SECTIONS:
            if args.only and run.__name__ not in args.only:
                continue
            began = time.perf_counter()
            section = run(ctx)
            took = time.perf_counter() - began
            section.notes.append(f"section took {took:.0f} s")
            print(render(section), flush=True)
            results["sections"][run.__name__] = {
                "title": section.title,
                "notes": section.notes,
                "seconds": took,
                **section.data,
            }
    results["seconds"] = time.perf_counter() - started
    print(f"\ntotal {results['seconds']:.0f} s; results in {args.out}")

    from ncpp.fileio import write_text_atomic

    args.out.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(args.out, json.dumps(results, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
