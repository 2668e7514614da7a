"""Compensation throughput and memory: a section of `benchmarks/run.py`.

On the core benchmark's files (stellabee1.ngc and the generated G1/G2/G3
program), one run times, each run in a new process (`in_fresh_process`): `ncpp` passthrough (no machine),
`ncpp compensate` with the HR5B sample machine at 1 µm (`--jobs 2`, as
`ncpp compensate` runs a program file over 2 MB on two cores: two parts, one
process each, `ncpp/parts.py`; and in one process), pygcode's `Line()` parse
and LinuxCNC's rs274.  Floor: compensation at least as fast as pygcode's
parse.  Memory: peak RSS of `ncpp compensate --jobs 2 FILE` on two program
lengths (1M and 10M lines; 20k and 60k with --quick).
"""

from __future__ import annotations

import io
import math
import os
import time
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, Iterable, Iterator

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
MACHINE = ROOT / "samples/machines/hr5b.toml"
TOLERANCE = 0.001


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


def ncpp_process_rate(path: Path, offset: tuple[float, float, float] | None, jobs: int = 1) -> dict[str, Any]:
    """`process` over the whole file into a null sink: passthrough (offset None) or compensation."""
    from accuracy import QUIET
    from ncpp.motion.offsets import WorkOffsets
    from ncpp.pipeline import ErrorSource, process

    source = None if offset is None else ErrorSource.from_machine_file(str(MACHINE))
    offsets = None if offset is None else WorkOffsets.at(offset)
    sink = open(os.devnull, "wb")
    children, faults = _children_cpu(), _faults()
    with _instructions() as count:
        cpu, start = time.process_time(), time.perf_counter()
        with open(path, "rb") as stream:
            stats = process(stream, sink, file=str(path), source=source, tolerance=TOLERANCE, warnings=QUIET, jobs=jobs, offsets=offsets)
        seconds, cpu = time.perf_counter() - start, time.process_time() - cpu
    worker = _children_cpu() - children  # the second process has exited (process() waits for it): its CPU is counted
    return {"lines": stats.lines_in, "lines_out": stats.lines_out, "seconds": seconds, "lines_per_s": stats.lines_in / seconds,
            "main_cpu_s": cpu, "worker_cpu_s": worker, "page_faults": _faults() - faults, **count}  # fmt: skip


@contextmanager
def _instructions() -> Iterator[dict[str, int]]:
    """`with _instructions() as count:` fills `count` with the instructions this process
    ("main_instructions") and the processes it started ("worker_instructions") ran
    meanwhile (counters.py); empty where the kernel does not count them."""
    from counters import counters

    count: dict[str, int] = {}
    both = counters()
    start = None if both is None else [c.read() for c in both]
    try:
        yield count
    finally:
        if both is not None:
            own, everything = (c.read() - s for c, s in zip(both, start))  # type: ignore[arg-type]
            count.update(main_instructions=own, worker_instructions=everything - own)
            for c in both:
                c.close()


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
    of the runs before it (this process holds all of them; a first part run here ran up to
    a sixth more CPU per line than the second part it started, at equal instructions).
    What the function times is unchanged: the work, not the start or the imports."""
    import pickle
    import subprocess
    import sys

    from ncpp.runtime import one_blas_thread

    payload = pickle.dumps(([str(HERE), str(ROOT), *sys.path], name, args))
    env = one_blas_thread(dict(os.environ))  # as the `ncpp` command starts numpy
    done = subprocess.run([sys.executable, "-c", _FRESH], input=payload, capture_output=True, check=False, env=env)
    if done.returncode != 0:
        raise RuntimeError(f"{name} failed in its process: {done.stderr.decode(errors='replace')[-2000:]}")
    return pickle.loads(done.stdout)


def pygcode_rate(path: Path) -> dict[str, Any]:
    """run.pygcode_rate, with the instructions it ran where they are counted."""
    import run as bench

    with _instructions() as count:
        result = bench.pygcode_rate(path)
    return {**result, **count}


def _instruction_split(result: dict[str, Any], pygcode: dict[str, Any]) -> tuple[str, str]:
    """(ratio, note): instructions per input line of each process beside pygcode's, and
    pygcode's over the larger (what the floor asks of each process, without the machine's load)."""
    if "main_instructions" not in result or "main_instructions" not in pygcode:
        return "", "not counted here (perf_event_open refused)"
    per_line = lambda n, of: n / max(of["lines"], 1) / 1000  # noqa: E731
    main, second = per_line(result["main_instructions"], result), per_line(result["worker_instructions"], result)
    theirs = per_line(pygcode["main_instructions"], pygcode)
    return f"{theirs / max(main, second):.2f}x", f"k per line in: the first process {main:.0f}, the second {second:.0f}; pygcode {theirs:.0f} (pygcode / the larger)"


def _children_cpu() -> float:
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def _faults() -> int:
    """Minor page faults of this process and of its children that have ended (a fault
    is a fresh page: ncpp/runtime.py keeps numpy's freed memory for reuse)."""
    import resource

    return sum(resource.getrusage(who).ru_minflt for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN))


def _cpu_split(result: dict[str, Any], pygcode: dict[str, Any] | None = None) -> str:
    """CPU per input line of each process, beside pygcode's when given: what the floor asks
    of each (both processes at or below pygcode's time per line); and page faults per line."""
    per_line = lambda seconds: 1e6 * seconds / max(result["lines"], 1)  # noqa: E731
    split = f"CPU µs per line in: the first process {per_line(result['main_cpu_s']):.0f}, the second {per_line(result['worker_cpu_s']):.0f}"
    faults = f"; page faults per line in {result['page_faults'] / max(result['lines'], 1):.2f}"
    apart = ""
    if "all_cpu_s" in result:  # how far apart the two processes' CPU was in each round: a run ends with the slower
        apart = "; the two apart per round " + ", ".join(f"{100 * (max(a, b) / min(a, b) - 1):.0f}%" for a, b in result["all_cpu_s"])
    return (split if pygcode is None else f"{split}; pygcode {per_line(pygcode['seconds']):.0f}") + apart + faults


REPEATS = 3  # runs per tool; the fastest counts (the same for every tool: this machine's timing is noisy)


def fastest(runs: dict[str, Callable[[], dict[str, Any]]], repeats: int = REPEATS) -> dict[str, dict[str, Any]]:
    """Per tool, the run with the fewest seconds of `repeats` runs, with how many were made.
    The tools take turns (round robin): this shared machine's speed drifts over minutes,
    and a tool whose runs all fell in a slow spell would be judged by it."""
    results: dict[str, list[dict[str, Any]]] = {name: [] for name in runs}
    for _ in range(repeats):
        for name, run in runs.items():
            results[name].append(run())
    return {name: {**min(done, key=lambda result: result["seconds"]), "runs": repeats, **_every_round(done)} for name, done in results.items()}


def _every_round(done: list[dict[str, Any]]) -> dict[str, list]:
    """Each round's seconds, and each round's CPU of the two processes where the tool ran two."""
    rounds: dict[str, list] = {"all_seconds": [r["seconds"] for r in done]}
    if all(r.get("worker_cpu_s") for r in done):
        rounds["all_cpu_s"] = [[r["main_cpu_s"], r["worker_cpu_s"]] for r in done]
    return rounds


def paired_ratios(best: dict[str, dict[str, Any]], tool: str, baseline: str) -> list[float]:
    """Rate ratio tool / baseline of each round, from two runs next to each other in the round
    (they read the same lines: the ratio of their seconds inverted).  Their median
    is steadier than the ratio of the fastest runs when the machine's speed drifts."""
    return [b / t for t, b in zip(best[tool]["all_seconds"], best[baseline]["all_seconds"])]


def stage_seconds(path: Path, offset: tuple[float, float, float], lines: int = 100_000, repeats: int = 2) -> dict[str, float]:
    """CPU seconds of each stage of compensation alone on the program's first `lines`
    lines: where the time goes, for whoever makes it faster.

    Each stage reads the previous stage's output from a list and runs `repeats`
    times; the fastest run counts.  The collector is off while a stage runs (its
    cost depends on how much the lists hold, not on the stage).  Differences of
    whole pipeline runs were tried first: on a shared machine whose speed drifts
    they came out negative."""
    import gc
    from itertools import islice

    from accuracy import QUIET
    from ncpp.passes import PASSES
    from ncpp.motion.offsets import WorkOffsets
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
        ("interpret", lambda blocks: interpret(iter(blocks), file=str(path), warnings=QUIET, offsets=offsets)),
        *((step.__name__, lambda events, step=step: step(events, make_context(source, TOLERANCE, QUIET, str(path)))) for step in PASSES),
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


def _verdict(ratio: float, paired: list[float]) -> str:
    return f"fastest runs; per round {', '.join(f'{r:.2f}' for r in paired)}; floor 1.00x: " + ("met" if ratio >= 1 and min(paired) >= 1 else "SHORT")


def compensate_rss(path: Path, offset: tuple[float, float, float]) -> dict[str, Any]:
    """Peak RSS (MB) of `ncpp compensate --jobs 2 ... path > /dev/null`, through run.peak_rss's
    probe (a child's ru_maxrss would inherit this big benchmark process's own).  Linux gives
    the larger of the two processes' peaks (the second is waited for)."""
    import run as bench

    return bench.peak_rss(path, ["compensate", "--jobs", "2", "--machine", str(MACHINE), "--work-offset", ",".join(map(str, offset)), str(path)])


def compensate_speed(ctx):
    import run as bench

    lines_generated = 250_000 if ctx.quick else 1_000_000
    programs = ctx.programs or {"stellabee1.ngc": bench.STELLABEE, f"generated {lines_generated:,} lines": ctx.generated(lines_generated)}
    rows, data = [], {}
    for label, path in programs.items():
        offset = work_offset(path)
        lines = bench.count_lines(path)
        # in this order each round: pygcode runs right after compensation and right before it in
        # one process, so each pair of runs a round's ratio compares is seconds apart, not a minute
        best = fastest({
            "passthrough": lambda: in_fresh_process("ncpp_process_rate", path, None),
            "compensate": lambda: in_fresh_process("ncpp_process_rate", path, offset, 2),
            "pygcode": lambda: in_fresh_process("pygcode_rate", path),
            "compensate, one process": lambda: in_fresh_process("ncpp_process_rate", path, offset, 1),
        })  # fmt: skip
        passthrough, compensated, alone, pyg = best["passthrough"], best["compensate"], best["compensate, one process"], best["pygcode"]
        rs = bench.rs274_rate(path, lines)
        ratio = compensated["lines_per_s"] / pyg["lines_per_s"]
        ratio_alone = alone["lines_per_s"] / pyg["lines_per_s"]
        paired = {tool: paired_ratios(best, tool, "pygcode") for tool in ("compensate", "compensate, one process")}
        stages = stage_seconds(path, offset)
        data[label] = {
            "work_offset_mm": offset, "passthrough": passthrough, "compensate": compensated, "compensate_one_process": alone, "pygcode": pyg,
            "rs274": rs, "ratio_compensate_pygcode": ratio, "ratio_one_process_pygcode": ratio_alone, "paired_ratios_pygcode": paired,
            "stage_cpu_seconds": stages,
        }  # fmt: skip
        growth = compensated["lines_out"] / max(compensated["lines"], 1)
        rows += [
            [label, "ncpp passthrough", f"{passthrough['lines_per_s']:,.0f}", ""],
            [label, "ncpp compensate 1 µm (HR5B), --jobs 2", f"{compensated['lines_per_s']:,.0f}", f"lines out/in {growth:.2f}; two parts, one process each"],
            [label, "ncpp compensate 1 µm (HR5B), --jobs 1", f"{alone['lines_per_s']:,.0f}", "one process"],
            [label, "pygcode Line()", f"{pyg['lines_per_s']:,.0f}", ""],
            [label, "rs274 (process)", f"{rs['lines_per_s']:,.0f}", "completed" if rs["completed"] else "STOPPED"],
            [label, "ratio compensate --jobs 2 / pygcode", f"{ratio:.2f}x", _verdict(ratio, paired["compensate"])],
            [label, "compensate --jobs 2, CPU by process", "", _cpu_split(compensated, pyg)],
            [label, "compensate --jobs 2, instructions", *_instruction_split(compensated, pyg)],
            [label, "ratio compensate --jobs 1 / pygcode", f"{ratio_alone:.2f}x", _verdict(ratio_alone, paired["compensate, one process"])],
            [label, "compensate CPU s by stage", f"{sum(stages.values()):.2f} s", f"each alone, first {min(lines, 100_000):,} lines: " + ", ".join(f"{k} {v:.2f}" for k, v in stages.items())],
        ]
    sizes = [20_000, 60_000] if ctx.quick else [1_000_000, 10_000_000]  # quick: keep the run short
    memory = {}
    for n in sizes:
        path = ctx.generated(n)
        memory[str(n)] = result = compensate_rss(path, work_offset(path))
        if n >= 10_000_000:
            path.unlink()
        status = "ok" if result["exit"] == 0 else f"exit {result['exit']}: {result['stderr_tail'].strip()[-100:]}"
        rows.append([f"generated {n:,} lines", "peak RSS, ncpp compensate --jobs 2", f"{result['rss_mb']:.1f} MB", f"{n / result['seconds']:,.0f} lines/s; {status}"])
    rss = [m["rss_mb"] for m in memory.values()]
    data["memory"] = memory
    notes = [f"peak RSS of `ncpp compensate` grows by {max(rss) - min(rss):.1f} MB from {sizes[0]:,} to {sizes[-1]:,} lines"]
    return bench.Section("Compensation throughput (lines in/s) and memory", ["program", "tool", "rate", "note"], rows, data, notes)


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
        f"generated, first {lines:,} lines, as Klartext": (posted(generated, lines, "heidenhain", ctx.workdir), offset),
        f"generated, first {lines:,} lines, as Sinumerik": (posted(generated, lines, "sinumerik", ctx.workdir), offset),
        "LinuxCNC 3D_Chips_abort.ngc (expressions)": (bench.PARAMETRIC, work_offset(bench.PARAMETRIC)),
    }
    rows, data = [], {}
    for label, (path, placed) in programs.items():
        best = fastest({
            "passthrough": lambda: in_fresh_process("ncpp_process_rate", path, None),
            "compensate": lambda: in_fresh_process("ncpp_process_rate", path, placed, 2),
        }, repeats=2)  # fmt: skip
        compensated = best["compensate"]
        data[label] = {"work_offset_mm": placed, **best}
        rows += [
            [label, "ncpp passthrough", f"{best['passthrough']['lines_per_s']:,.0f}", ""],
            [label, "ncpp compensate 1 µm (HR5B), --jobs 2", f"{compensated['lines_per_s']:,.0f}",
             f"lines out/in {compensated['lines_out'] / max(compensated['lines'], 1):.2f}; {_cpu_split(compensated)}"],
        ]  # fmt: skip
    return bench.Section("Compensation throughput in other dialects (lines in/s, no floor)", ["program", "tool", "rate", "note"], rows, data)
