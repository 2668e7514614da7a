"""Compensation throughput, memory and `--jobs` across programs: a section of `benchmarks/run.py`.

On the core benchmark's files (stellabee1.ngc and the generated G1/G2/G3 program) one run
times, each run in a new process (`in_fresh_process`): `ncpp` passthrough (no machine),
`ncpp compensate` in one process with the HR5B sample machine at 1 µm, pygcode's `Line()`
parse and LinuxCNC's rs274.  Across programs: `ncpp compensate -o FOLDER` over PROGRAMS
generated programs with `--jobs 1` and with `--jobs 2`.  Memory: peak RSS of `ncpp
compensate FILE` on two program lengths.

The floors (FLOORS) are judged here, not in the tests: compensation in one process at
least 0.5x pygcode's parse rate, passthrough at least 2x, `--jobs 2` across programs at
least 1.5x `--jobs 1`, and peak RSS flat in program length (the longer program's at most
1.1x the shorter's).  The figures also go to a markdown table, PERFORMANCE_TABLE, which
docs/performance.md shows.
"""

from __future__ import annotations

import io
import math
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
MACHINE = ROOT / "samples/machines/hr5b.toml"
TOLERANCE = 0.001
VERIFY_TARGET = 0.30  # the verifier's CPU at most this share of compensation's without it
PERFORMANCE_TABLE = HERE / "out" / "performance.md"
PROGRAMS = 4  # generated programs compensated across processes
FLOORS = {
    "one process / pygcode": 0.5,
    "passthrough / pygcode": 2.0,
    "--jobs 2 / --jobs 1": 1.5,
    "peak RSS growth": 1.1,
}


def work_offset(path: Path) -> tuple[float, float, float]:
    """Centre of HR5B's travel minus the centre of the program's extent (first 20k lines suffice:
    the generated program stays in a fixed box; stellabee's extent is the file's)."""
    import numpy as np
    from accuracy import events_of, machine, placement

    from ncpp.simulate import sample_events

    with open(path, "rb") as f:
        head = b"".join(line for _, line in zip(range(20_000), f))
    offset = placement(sample_events(events_of(head, str(path)), step_mm=5.0), machine("hr5b"))
    return tuple(float(v) for v in np.asarray(offset))  # type: ignore[return-value]


def ncpp_process_rate(
    path: Path, offset: tuple[float, float, float] | None, verify: bool = True
) -> dict[str, Any]:
    """`process` over the whole file into a null sink: passthrough (offset None) or compensation,
    verified (the default, as every command runs it) or not."""
    from accuracy import QUIET

    import ncpp.verify  # noqa: F401  (imported here, not in the timed run: its scipy import is no work)
    from ncpp.motion.offsets import WorkOffsets
    from ncpp.pipeline import ErrorSource, process

    source = None if offset is None else ErrorSource.from_machine_file(str(MACHINE))
    offsets = None if offset is None else WorkOffsets.at(offset)
    with open(os.devnull, "wb") as sink, open(path, "rb") as stream:
        cpu, start = time.process_time(), time.perf_counter()
        stats = process(
            stream,
            sink,
            file=str(path),
            source=source,
            tolerance=TOLERANCE,
            warnings=QUIET,
            offsets=offsets,
            verify=verify,
        )
        seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    return {
        "lines": stats.lines_in,
        "lines_out": stats.lines_out,
        "seconds": seconds,
        "lines_per_s": stats.lines_in / seconds,
        "cpu_s": cpu,
    }


def pygcode_rate(path: Path) -> dict[str, Any]:
    import run as bench

    return bench.pygcode_rate(path)


# A function of this module run in a new Python process: its arguments and result go as pickles
_FRESH = """
import pickle, sys
path, name, args = pickle.load(sys.stdin.buffer)
sys.path[:0] = path
replies, sys.stdout = sys.stdout.buffer, sys.stderr  # a stray print must not corrupt the result
import compensate_speed
pickle.dump(getattr(compensate_speed, name)(*args), replies)
"""


def in_fresh_process(name: str, *args: Any) -> dict[str, Any]:
    """`name(*args)`, a function of this module, run in a new Python process, for every
    timed run of every tool: none inherits the heap, the imports and the collector's load
    of the runs before it.  What the function times is the work, not the start or the imports."""
    import pickle

    from ncpp.runtime import one_blas_thread

    payload = pickle.dumps(([str(HERE), str(ROOT), *sys.path], name, args))
    env = one_blas_thread(dict(os.environ))  # as the `ncpp` command starts numpy
    done = subprocess.run(
        [sys.executable, "-c", _FRESH], input=payload, capture_output=True, check=False, env=env
    )
    if done.returncode != 0:
        raise RuntimeError(f"{name} failed in its process: {done.stderr.decode(errors='replace')[-2000:]}")
    return pickle.loads(done.stdout)


REPEATS = 3  # runs per tool; the fastest counts (the same for every tool: a shared machine's timing is noisy)


def fastest(
    runs: dict[str, Callable[[], dict[str, Any]]], repeats: int = REPEATS
) -> dict[str, dict[str, Any]]:
    """Per tool, the run with the fewest seconds of `repeats` runs, with how many were made
    and each round's seconds.  The tools take turns (round robin): a shared machine's speed
    drifts over minutes, and a tool whose runs all fell in a slow spell would be judged by it."""
    results: dict[str, list[dict[str, Any]]] = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            results[name].append(run())
    return {
        name: {
            **min(done, key=lambda result: result["seconds"]),
            "runs": repeats,
            "all_seconds": [r["seconds"] for r in done],
        }
        for name, done in results.items()
    }


def paired_ratios(best: dict[str, dict[str, Any]], tool: str, baseline: str) -> list[float]:
    """Rate ratio tool / baseline of each round, from two runs next to each other in the round
    (they read the same lines: the ratio of their seconds inverted)."""
    return [b / t for t, b in zip(best[tool]["all_seconds"], best[baseline]["all_seconds"])]


def verdict(ratio: float, rounds: list[float], floor: float) -> str:
    """Met when the fastest runs' ratio and every round's reach the floor."""
    return f"per round {', '.join(f'{r:.2f}' for r in rounds)}; floor {floor:.2f}x: " + (
        "met" if ratio >= floor and min(rounds) >= floor else "SHORT"
    )


def stage_seconds(
    path: Path, offset: tuple[float, float, float], lines: int = 100_000, repeats: int = 2
) -> dict[str, float]:
    """CPU seconds of each stage of compensation alone on the program's first `lines` lines:
    where the time goes.  Each stage reads the previous stage's output from a list and runs
    `repeats` times; the fastest run counts; the collector is off while a stage runs."""
    import gc
    from itertools import islice

    from accuracy import QUIET

    from ncpp.motion.offsets import WorkOffsets
    from ncpp.passes import PASSES
    from ncpp.pipeline import ErrorSource, dialect_tools, make_context
    from ncpp.program.dialects import parse_program

    source = ErrorSource.from_machine_file(str(MACHINE))
    offsets = WorkOffsets.at(offset)
    with open(path, "rb") as stream:
        head = b"".join(islice(stream, lines))

    def parse() -> Iterable:
        return parse_program(io.BytesIO(head), str(path), None)[1]

    interpret, writer = dialect_tools(parse_program(io.BytesIO(head[:4096]), str(path), None)[0])
    stages: list[tuple[str, Callable[[list], Iterable]]] = [
        ("parse", lambda _: parse()),
        (
            "interpret",
            lambda blocks: interpret(iter(blocks), file=str(path), warnings=QUIET, offsets=offsets),
        ),
        *(
            (
                step.__name__,
                lambda events, step=step: step(events, make_context(source, TOLERANCE, QUIET, str(path))),
            )
            for step in PASSES
        ),
        ("writer", lambda events: writer().write(events)),
    ]
    seconds: dict[str, float] = {}
    previous: list = []
    for name, stage in stages:
        best = math.inf
        for _ in range(repeats):
            gc.collect()
            gc.disable()
            try:
                start = time.process_time()
                out = list(stage(previous))
                best = min(best, time.process_time() - start)
            finally:
                gc.enable()
        seconds[name], previous = best, out
    return seconds


def files_rate(
    paths: list[Path], offset: tuple[float, float, float], jobs: int, folder: Path
) -> dict[str, Any]:
    """Wall time of `ncpp compensate --jobs N -o folder PATHS...` (a fresh command: its
    processes' start and imports count, as a shop's run pays them)."""
    from ncpp.runtime import one_blas_thread

    shutil.rmtree(folder, ignore_errors=True)
    command = [
        sys.executable,
        "-m",
        "ncpp",
        "compensate",
        "--machine",
        str(MACHINE),
        "--work-offset",
        ",".join(map(str, offset)),
        "--jobs",
        str(jobs),
        "-o",
        str(folder),
        *map(str, paths),
    ]
    env = one_blas_thread({**os.environ, "PYTHONPATH": str(ROOT)})
    start = time.perf_counter()
    done = subprocess.run(command, capture_output=True, text=True, env=env, check=False, cwd=folder.parent)
    seconds = time.perf_counter() - start
    if done.returncode != 0:
        raise RuntimeError(f"ncpp compensate --jobs {jobs} failed: {done.stderr[-2000:]}")
    import run as bench

    lines = sum(bench.count_lines(path) for path in paths)
    return {"lines": lines, "seconds": seconds, "lines_per_s": lines / seconds}


def compensate_rss(path: Path, offset: tuple[float, float, float]) -> dict[str, Any]:
    """Peak RSS (MB) of `ncpp compensate ... path > /dev/null`, through run.peak_rss's probe
    (a child's ru_maxrss would inherit this big benchmark process's own)."""
    import run as bench

    return bench.peak_rss(
        path,
        ["compensate", "--machine", str(MACHINE), "--work-offset", ",".join(map(str, offset)), str(path)],
    )


def compensate_speed(ctx):
    import run as bench
    from generate import generate

    load_before = os.getloadavg()
    lines_generated = 250_000 if ctx.quick else 1_000_000
    programs = ctx.programs or {
        "stellabee1.ngc": bench.STELLABEE,
        f"generated {lines_generated:,} lines": ctx.generated(lines_generated),
    }
    rows, data, table = [], {}, []
    for label, path in programs.items():
        offset = work_offset(path)
        lines = bench.count_lines(path)
        # each round: pygcode between the two ncpp runs it is compared with, seconds apart
        best = fastest(
            {
                "passthrough": lambda: in_fresh_process("ncpp_process_rate", path, None),
                "pygcode": lambda: in_fresh_process("pygcode_rate", path),
                "compensate": lambda: in_fresh_process("ncpp_process_rate", path, offset),
                "unverified": lambda: in_fresh_process("ncpp_process_rate", path, offset, False),
            }
        )
        passthrough, compensated, pyg = best["passthrough"], best["compensate"], best["pygcode"]
        unverified = best["unverified"]
        verifying = compensated["cpu_s"] / max(unverified["cpu_s"], 1e-9) - 1
        rs = bench.rs274_rate(path, lines)
        ratios = {
            "one process / pygcode": ("compensate", compensated),
            "passthrough / pygcode": ("passthrough", passthrough),
        }
        stages = stage_seconds(path, offset)
        table.append(
            [
                "verifier's cost (CPU, against --no-verify)",
                label,
                f"{100 * verifying:.0f}%",
                f"≤ {100 * VERIFY_TARGET:.0f}%",
                "met" if verifying <= VERIFY_TARGET else "short",
            ]
        )
        data[label] = {
            "work_offset_mm": offset,
            "unverified": unverified,
            "verifier_cost": verifying,
            "passthrough": passthrough,
            "compensate": compensated,
            "pygcode": pyg,
            "rs274": rs,
            "stage_cpu_seconds": stages,
        }
        growth = compensated["lines_out"] / max(compensated["lines"], 1)
        rows += [
            [label, "ncpp passthrough", f"{passthrough['lines_per_s']:,.0f}", ""],
            [
                label,
                "ncpp compensate 1 µm (HR5B), one process",
                f"{compensated['lines_per_s']:,.0f}",
                f"lines out/in {growth:.2f}; "
                f"CPU {1e6 * compensated['cpu_s'] / max(lines, 1):.0f} µs per line in",
            ],
            [
                label,
                "ncpp compensate --no-verify, one process",
                f"{unverified['lines_per_s']:,.0f}",
                f"the verifier costs {100 * verifying:.0f}% of this CPU (target at most {100 * VERIFY_TARGET:.0f}%)",
            ],
            [label, "pygcode Line()", f"{pyg['lines_per_s']:,.0f}", ""],
            [
                label,
                "rs274 (process)",
                f"{rs['lines_per_s']:,.0f}",
                "completed" if rs["completed"] else "STOPPED",
            ],
        ]
        for measure, (tool, result) in ratios.items():
            ratio, rounds = result["lines_per_s"] / pyg["lines_per_s"], paired_ratios(best, tool, "pygcode")
            judged = verdict(ratio, rounds, FLOORS[measure])
            data[label][measure] = {"ratio": ratio, "rounds": rounds}
            rows.append([label, f"ratio {measure}", f"{ratio:.2f}x", judged])
            table.append(
                [
                    measure,
                    label,
                    f"{ratio:.2f}× (ncpp {result['lines_per_s']:,.0f} lines/s, "
                    f"pygcode {pyg['lines_per_s']:,.0f}; "
                    f"rounds {min(rounds):.2f}-{max(rounds):.2f}×)",
                    f"≥ {FLOORS[measure]:g}×",
                    judged.rsplit(": ", 1)[1],
                ]
            )
        rows.append(
            [
                label,
                "compensate CPU s by stage",
                f"{sum(stages.values()):.2f} s",
                f"each alone, first {min(lines, 100_000):,} lines: "
                + ", ".join(f"{k} {v:.2f}" for k, v in stages.items()),
            ]
        )

    each = 50_000 if ctx.quick else 250_000
    paths = [generate(ctx.workdir / f"program-{seed}.ngc", each, seed) for seed in range(1, PROGRAMS + 1)]
    offset = work_offset(paths[0])  # (every generated program stays in one box)
    across = fastest(
        {
            f"--jobs {jobs}": lambda jobs=jobs: files_rate(paths, offset, jobs, ctx.workdir / "out")
            for jobs in (1, 2)
        },
        repeats=2,
    )
    speedup = across["--jobs 2"]["lines_per_s"] / across["--jobs 1"]["lines_per_s"]
    rounds = [
        one / two for one, two in zip(across["--jobs 1"]["all_seconds"], across["--jobs 2"]["all_seconds"])
    ]
    judged = verdict(speedup, rounds, FLOORS["--jobs 2 / --jobs 1"])
    data["across programs"] = {**across, "speedup": speedup, "rounds": rounds}
    label = f"{PROGRAMS} generated programs of {each:,} lines"
    for jobs in ("--jobs 1", "--jobs 2"):
        rows.append(
            [
                label,
                f"ncpp compensate {jobs} -o FOLDER",
                f"{across[jobs]['lines_per_s']:,.0f}",
                f"{across[jobs]['seconds']:.1f} s, the command's start included",
            ]
        )
    rows.append([label, "ratio --jobs 2 / --jobs 1", f"{speedup:.2f}x", judged])
    table.append(
        [
            "--jobs 2 / --jobs 1 across programs",
            label,
            f"{speedup:.2f}× ({across['--jobs 2']['lines_per_s']:,.0f} against "
            f"{across['--jobs 1']['lines_per_s']:,.0f} lines/s; "
            f"rounds {min(rounds):.2f}-{max(rounds):.2f}×)",
            f"≥ {FLOORS['--jobs 2 / --jobs 1']:g}×",
            judged.rsplit(": ", 1)[1],
        ]
    )

    sizes = (
        [100_000, 300_000] if ctx.quick else [1_000_000, 10_000_000]
    )  # past the parser's read-ahead, which saturates at ~32k lines
    memory = {}
    for n in sizes:
        path = ctx.generated(n)
        memory[str(n)] = result = compensate_rss(path, work_offset(path))
        if n >= 10_000_000:
            path.unlink()
        status = (
            "ok" if result["exit"] == 0 else f"exit {result['exit']}: {result['stderr_tail'].strip()[-100:]}"
        )
        rows.append(
            [
                f"generated {n:,} lines",
                "peak RSS, ncpp compensate",
                f"{result['rss_mb']:.1f} MB",
                f"{n / result['seconds']:,.0f} lines/s; {status}",
            ]
        )
    rss = [m["rss_mb"] for m in memory.values()]
    growth = rss[-1] / rss[0]
    flat = (
        "met"
        if growth <= FLOORS["peak RSS growth"] and all(m["exit"] == 0 for m in memory.values())
        else "SHORT"
    )
    data["memory"] = memory
    table.append(
        [
            "peak RSS, one process",
            f"generated {sizes[0]:,} / {sizes[-1]:,} lines",
            f"{rss[0]:.1f} / {rss[-1]:.1f} MB ({growth:.2f}×)",
            f"≤ {FLOORS['peak RSS growth']:g}×",
            flat,
        ]
    )
    notes = [
        f"peak RSS of `ncpp compensate` grows {growth:.2f}x from {sizes[0]:,} to {sizes[-1]:,} lines: {flat}"
    ]
    written = write_table(table, bench.cpu(), ctx.quick, load_before, os.getloadavg())
    notes.append(f"performance table written to {written}")
    return bench.Section(
        "Compensation throughput (lines in/s), --jobs across programs, memory",
        ["program", "tool", "rate", "note"],
        rows,
        data,
        notes,
    )


def write_table(table: list[list[str]], cpu: str, quick: bool, load_before: tuple, load_after: tuple) -> Path:
    """The floors' table as markdown, at PERFORMANCE_TABLE."""
    from ncpp.fileio import write_text_atomic

    lines = [
        f"Measured {time.strftime('%Y-%m-%d %H:%M %Z')} by "
        f"`python benchmarks/run.py{' --quick' if quick else ''} --only compensate_speed` "
        f"on {cpu}, {os.cpu_count()} cores, Python {sys.version.split()[0]}; "
        f"load average {load_before[0]:.1f} before, "
        f"{load_after[0]:.1f} after: the machine is shared with other work, "
        "and figures move from run to run with its load.  "
        "Each ratio is of the fastest of three runs (two across programs), each in a fresh process, "
        "the tools taking turns; "
        "a floor is met when the fastest runs and every round reach it.",
        "",
        "| measure | program | figure | floor | |",
        "|---|---|---|---|---|",
        *(f"| {' | '.join(row)} |" for row in table),
    ]
    PERFORMANCE_TABLE.parent.mkdir(parents=True, exist_ok=True)
    write_text_atomic(PERFORMANCE_TABLE, "\n".join(lines) + "\n")
    return PERFORMANCE_TABLE


def posted(source: Path, lines: int, dialect: str, workdir: Path) -> Path:
    """The first `lines` lines of an ISO program written as a `dialect` program by ncpp's
    own post generator (the same moves, spelled as that control's CAM output would)."""
    from itertools import islice

    from accuracy import QUIET

    from ncpp.motion import interpret
    from ncpp.post import GENERATORS
    from ncpp.program.parser import parse_stream

    path = workdir / f"{source.stem}-{lines}.{ {'heidenhain': 'h', 'sinumerik': 'mpf'}[dialect] }"
    with open(source, "rb") as stream, open(path, "w", encoding="latin-1") as out:
        events = interpret(parse_stream(islice(stream, lines), str(source)), file=str(source), warnings=QUIET)
        out.writelines(line + "\n" for line in GENERATORS[dialect](QUIET).write(events, lambda event: None))
    return path


def dialect_speed(ctx):
    """Compensation throughput in the other dialects and on expression lines (no floor: pygcode
    reads none of them): the generated program posted as Klartext and as Sinumerik, and
    LinuxCNC's 3D_Chips sample (a parameter expression in every line)."""
    import run as bench

    lines = 40_000 if ctx.quick else 100_000
    generated = ctx.generated(250_000 if ctx.quick else 1_000_000)
    offset = work_offset(generated)  # the posted programs make the same moves
    programs = {
        f"generated, first {lines:,} lines, as Klartext": (
            posted(generated, lines, "heidenhain", ctx.workdir),
            offset,
        ),
        f"generated, first {lines:,} lines, as Sinumerik": (
            posted(generated, lines, "sinumerik", ctx.workdir),
            offset,
        ),
        "LinuxCNC 3D_Chips_abort.ngc (expressions)": (bench.PARAMETRIC, work_offset(bench.PARAMETRIC)),
    }
    rows, data = [], {}
    for label, (path, placed) in programs.items():
        best = fastest(
            {
                "passthrough": lambda: in_fresh_process("ncpp_process_rate", path, None),
                "compensate": lambda: in_fresh_process("ncpp_process_rate", path, placed),
            },
            repeats=2,
        )
        compensated = best["compensate"]
        data[label] = {"work_offset_mm": placed, **best}
        rows += [
            [label, "ncpp passthrough", f"{best['passthrough']['lines_per_s']:,.0f}", ""],
            [
                label,
                "ncpp compensate 1 µm (HR5B), one process",
                f"{compensated['lines_per_s']:,.0f}",
                f"lines out/in {compensated['lines_out'] / max(compensated['lines'], 1):.2f}",
            ],
        ]
    return bench.Section(
        "Compensation throughput in other dialects (lines in/s, no floor)",
        ["program", "tool", "rate", "note"],
        rows,
        data,
    )
