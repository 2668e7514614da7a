"""Fuzzing every command that reads a file: no traceback, no hang, bounded memory, and a
refusal that names `file:line:col:`.

The default run tries NCPP_FUZZ_CASES cases (12: a few seconds) from seed NCPP_FUZZ_SEED (0);
a longer run: `NCPP_FUZZ_CASES=3000 NCPP_FUZZ_SEED=7 pytest tests/hostile/test_fuzz.py`.
"""

from __future__ import annotations

import json
import os
import random
import re
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import CORPUS, NOT_PROGRAMS, ROOT, SHARED
from tests.hostile.constructs import case as construct
from tests.hostile.constructs import write_called_files
from tests.hostile.fuzz import mutate

MACHINE = SHARED / "machines/wide.toml"
CASES = int(os.environ.get("NCPP_FUZZ_CASES", "12"))
SEED = int(os.environ.get("NCPP_FUZZ_SEED", "0"))
SECONDS_PER_CASE = 60.0  # (a loop that never ends is refused after MAX_RERUN lines: under a minute)
MEMORY_MB = 1536  # the worker's address space (a compensation run maps under 200 MB)
LOCATED = re.compile(r"^(?!ncpp: )(?P<file>[^:\n]+):\d+:\d+: ")
USAGE = re.compile(
    r"^ncpp[\w -]*: error: argument "
)  # argparse refusing an option's value (`--work-offset nan,0,0`)


def _files(folder: Path, *suffixes: str) -> list[Path]:
    """Files under `folder` with one of the suffixes, else its programs (oracles left out)."""
    found = [p for p in sorted(folder.rglob("*")) if p.is_file()]
    if suffixes:
        return [p for p in found if p.suffix.lower() in suffixes]
    return [p for p in found if not any(s in p.name for s in NOT_PROGRAMS)]


def _seeds() -> dict[str, list[Path]]:
    programs = [
        p
        for p in (
            *_files(CORPUS / "iso_gcode"),
            *_files(CORPUS / "heidenhain"),
            *_files(CORPUS / "sinumerik"),
            *_files(CORPUS / "malformed"),
            ROOT / "samples/programs/pocket.ngc",
        )
        if p.stat().st_size < 400_000
    ]
    return {
        "program": programs,
        "cl": _files(CORPUS / "apt_cldata"),
        "measurement": _files(ROOT / "samples/measurements", ".csv"),
        "machine": [*_files(ROOT / "samples/machines", ".toml"), MACHINE],
    }


def _argv(kind: str, path: Path, out: Path, rng: random.Random) -> list[str]:
    machine, output = ["--machine", str(MACHINE)], ["-o", str(out)]
    if kind == "program":
        return rng.choice(
            [[str(path), *output], ["compensate", *machine, str(path), *output], ["motion", str(path)]]
        )
    if kind == "cl":
        return [
            "post",
            "--dialect",
            rng.choice(["linuxcnc", "heidenhain", "sinumerik"]),
            *machine,
            str(path),
            *output,
        ]
    if kind == "measurement":
        return ["analyze", str(path)]
    return ["compensate", "--machine", str(path), str(ROOT / "samples/programs/pocket.ngc"), *output]


def _cases(folder: Path, count: int, seed: int) -> list[dict]:
    rng = random.Random(seed)
    seeds = _seeds()
    texts = {kind: [p.read_bytes() for p in paths] for kind, paths in seeds.items()}
    write_called_files(folder / "subs")
    cases = []
    for n in range(count):
        kind = rng.choice([*sorted(seeds), "construct"])
        if kind == "construct":  # (a program built of the constructs each dialect's interpreter follows)
            argv = construct(rng, folder, n)
            if rng.random() < 0.5:  # (and damaged)
                program = next(Path(a) for a in argv if Path(a).stem == f"gen{n}")
                program.write_bytes(mutate(program.read_bytes(), rng, [program.read_bytes()]))
            cases.append({"id": n, "kind": kind, "source": "constructs.py", "argv": argv})
            continue
        k = rng.randrange(len(seeds[kind]))
        source = seeds[kind][k]
        mutated = folder / f"case{n}{''.join(source.suffixes[-1:])}"
        mutated.write_bytes(mutate(texts[kind][k], rng, texts[kind]))
        cases.append(
            {
                "id": n,
                "kind": kind,
                "source": str(source),
                "argv": _argv(kind, mutated, folder / f"out{n}.nc", rng),
            }
        )
    return cases


def _problems(case: dict, result: dict | None) -> list[str]:
    if result is None:
        return ["the worker died on it (memory past the limit, or a crash)"]
    found = []
    if result["exception"] == "timeout":
        found.append(f"ran past {SECONDS_PER_CASE:.0f} s")
    elif result["exception"]:
        found.append("traceback:\n" + result["exception"])
    elif result["status"] not in (0, 2):
        found.append(f"exit status {result['status']}")
    elif result["status"] == 2:
        last = [line for line in result["stderr"].splitlines() if line.strip()][-1:]
        if not last or not (LOCATED.match(last[0]) or USAGE.match(last[0])):
            found.append(f"not a located error: {last}")
    elif _passed_through(case["argv"]) is False:
        found.append("without a machine file the output is not the input byte for byte")
    return found


def _passed_through(argv: list[str]) -> bool | None:
    """Whether plain `ncpp IN -o OUT` (no machine file) wrote its input unchanged (None: another command)."""
    if argv[0] in ("compensate", "motion", "post", "analyze") or "--machine" in argv:
        return None
    output = Path(argv[argv.index("-o") + 1])
    return output.read_bytes() == Path(argv[argv.index("-o") - 1]).read_bytes()


@pytest.mark.skipif(
    not CORPUS.is_dir() or not MACHINE.exists(), reason="corpus or shared machine file not found"
)
def test_fuzzed_inputs_are_refused_located_in_bounded_time_and_memory(tmp_path):
    cases = _cases(tmp_path, CASES, SEED)
    (tmp_path / "cases.json").write_text(json.dumps(cases))
    results_file = tmp_path / "results.jsonl"
    results: dict[int, dict] = {}
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NCPP_CACHE": str(tmp_path / "cache")}
    while len(results) < len(cases):  # (a worker that dies is restarted after the case it died on)
        todo = [c for c in cases if c["id"] not in results]
        (tmp_path / "todo.json").write_text(json.dumps(todo))
        subprocess.run(
            [
                sys.executable,
                "-m",
                "tests.hostile.fuzz",
                str(tmp_path / "todo.json"),
                str(MEMORY_MB),
                str(SECONDS_PER_CASE),
                str(results_file),
            ],
            env=env,
            cwd=ROOT,
            timeout=60 + SECONDS_PER_CASE * len(todo),
            capture_output=True,
        )
        done = (
            [json.loads(line) for line in results_file.read_text().splitlines()]
            if results_file.exists()
            else []
        )
        results.update((r["id"], r) for r in done)
        if len(results) < len(cases):
            died = next(c for c in cases if c["id"] not in results)
            results[died["id"]] = None  # type: ignore[assignment]
    failures = [(case, problem) for case in cases for problem in _problems(case, results[case["id"]])]
    peak = max((r["peak_kb"] for r in results.values() if r), default=0)
    print(
        f"fuzz: {len(cases)} cases from seed {SEED}, {len(failures)} problems, worker peak {peak // 1024} MB"
    )
    report = "\n\n".join(
        f"case {c['id']} ({c['kind']}, from {c['source']}): ncpp {' '.join(c['argv'])}\n{p}"
        for c, p in failures[:12]
    )
    assert not failures, f"{len(failures)} of {len(cases)} cases:\n{report}"
