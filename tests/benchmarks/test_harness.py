"""The benchmarks' own machinery: how a floor is judged, how rounds are paired, and
that a timed run in a fresh process returns what the tables are made of.

The figures themselves are not tested (they are the machine's); the verdict that
the floors are judged by, and the harness that feeds it, are.
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"
sys.path.insert(0, str(BENCHMARKS))

import compensate_speed as speed  # noqa: E402
import run as bench  # noqa: E402
from generate import generate  # noqa: E402


@pytest.mark.parametrize(
    ("ratio", "rounds", "met"),
    [
        (1.00, [1.00, 1.00, 1.00], True),
        (1.53, [1.67, 1.68, 1.45], True),
        (1.22, [1.42, 0.97, 1.39], False),  # one slow round is enough to fall short
        (0.98, [1.07, 1.09, 1.10], False),  # and so is the ratio of the fastest runs
    ],
)
def test_the_floor_is_met_by_the_fastest_runs_and_by_every_round(ratio, rounds, met):
    verdict = speed.verdict(ratio, rounds, 1.0)
    assert verdict.endswith("met" if met else "SHORT")
    assert "per round " + ", ".join(f"{r:.2f}" for r in rounds) in verdict


def test_each_round_compares_the_two_runs_made_in_it():
    best = {"compensate": {"all_seconds": [2.0, 4.0, 3.0]}, "pygcode": {"all_seconds": [4.0, 2.0, 3.0]}}
    assert speed.paired_ratios(best, "compensate", "pygcode") == [2.0, 0.5, 1.0]


def test_tools_take_turns_and_the_fastest_run_of_each_counts():
    calls: list[str] = []
    seconds = {"a": iter([3.0, 1.0, 2.0]), "b": iter([5.0, 6.0, 4.0])}

    def tool(name):
        def timed():
            calls.append(name)
            return {"seconds": next(seconds[name]), "round": len(calls)}

        return timed

    best = speed.fastest({"a": tool("a"), "b": tool("b")}, repeats=3)
    assert calls == ["a", "b"] * 3  # round robin: a slow spell of the machine falls on both
    assert best["a"]["seconds"] == 1.0 and best["a"]["round"] == 3
    assert best["b"]["seconds"] == 4.0 and best["b"]["all_seconds"] == [5.0, 6.0, 4.0]
    assert best["a"]["runs"] == best["b"]["runs"] == 3


def test_a_timed_run_in_a_fresh_process(tmp_path):
    program = tmp_path / "small.ngc"
    generate(program, 600)
    offset = speed.work_offset(program)
    compensated = speed.in_fresh_process("ncpp_process_rate", program, offset)
    passthrough = speed.in_fresh_process("ncpp_process_rate", program, None)
    pygcode = speed.in_fresh_process("pygcode_rate", program)
    assert compensated["lines"] == passthrough["lines"] == pygcode["lines"] == 600
    assert passthrough["lines_out"] == 600  # no passes: line for line
    assert compensated["lines_out"] > 600  # HR5B's reversal steps and quadrant cuts
    assert pygcode["failed_lines"] == 0
    for result in (compensated, passthrough, pygcode):
        assert result["seconds"] > 0 and result["lines_per_s"] == pytest.approx(600 / result["seconds"])
    assert compensated["cpu_s"] > 0


def test_a_failing_run_reports_its_error():
    with pytest.raises(RuntimeError, match="pygcode_rate failed in its process"):
        speed.in_fresh_process("pygcode_rate", Path("/nonexistent/program.ngc"))


def test_an_unknown_section_is_refused(capsys):
    with pytest.raises(SystemExit) as stop:
        bench.main(["--only", "throughput", "no_such_section"])
    assert stop.value.code == 2
    assert "no_such_section" in capsys.readouterr().err


def test_programs_compensated_across_processes_are_timed_and_counted(tmp_path):
    paths = [generate(tmp_path / f"p{seed}.ngc", 300, seed) for seed in (1, 2)]
    result = speed.files_rate(paths, speed.work_offset(paths[0]), 2, tmp_path / "out")
    assert result["lines"] == 600 and result["seconds"] > 0
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["p1.ngc", "p2.ngc"]


def test_the_table_names_its_machine_and_its_floors(monkeypatch, tmp_path):
    monkeypatch.setattr(speed, "PERFORMANCE_TABLE", tmp_path / "performance.md")
    written = speed.write_table(
        [["one process / pygcode", "p.ngc", "0.61×", "≥ 0.5×", "met"]],
        "a CPU",
        True,
        (1.0, 0, 0),
        (2.0, 0, 0),
    )
    text = written.read_text()
    assert (
        "a CPU" in text and "shared with other work" in text and "load average 1.0 before, 2.0 after" in text
    )
    assert "| one process / pygcode | p.ngc | 0.61× | ≥ 0.5× | met |" in text
