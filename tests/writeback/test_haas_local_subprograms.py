"""Haas's local subprograms (`M97 P<n> L<runs>`, Haas Mill Operator's Manual, "M97 Local Sub-Program
Call": the lines from Nn of the same program to its M99, placed after M30) compensated: with --expand
each run is written where it runs; without it a subprogram run once (one M97 without L, from the
main program's straight code) is compensated where its text stands, and one run again stays as
programmed, with the warning.

Judged by oracles ncpp did not write: rs274 cannot read M97, so each program is given to it written
out by the manual's rule (`_inlined`: each call replaced by L copies of the lines from Nn to the line
before its M99, the text after M30 cut), the original by hand (`BY_HAND`); its feed moves' end points
are mapped through the machine written here by hand (`square`: scales and squareness), and every
programmed point must be reached within 0.5 µm.  The same measure finds microns where the runs are
left as programmed: the test can fail."""

from __future__ import annotations

import io
import re
from pathlib import Path

import pytest

from ncpp.errors import Warnings
from tests.motion.test_haas_local_calls import BY_HAND, ONCE
from tests.writeback.conftest import compensate_file
from tests.writeback.test_compensated_holes import MACHINE
from tests.writeback.test_expand_flow import _pathcheck, _worst_point_um

# Three passes of a profile, each a millimetre deeper
PASSES = ONCE.replace("M97 P1000", "M97 P1000 L3").replace(
    "N1000 (THE PROFILE)\n", "N1000 (A PASS)\nG91 G1 Z-1. F150\nG90\n"
)
_PASS = "G91 G1 Z-1. F150\nG90\nG1 X160. Y120. F500\nG1 X100. Y-140.\nG2 X160. Y-80. I0 J60.\n"
PASSES_BY_HAND = BY_HAND["one run"][1].replace("G1 X160. Y120. F500\nG1 X100. Y-140.\nG2 X160. Y-80. I0 J60.\n",
                                               _PASS * 3)  # fmt: skip


def _inlined(text: str) -> str:
    """The program as Haas runs it, written out by the manual's rule: each `M97 Pn Lk` line
    replaced by k copies (1 without L) of the lines from the line `Nn` to the one before its M99;
    the text after M30 cut (calls do not nest here)."""
    lines = text.splitlines()
    end = next(n for n, line in enumerate(lines) if re.match(r"\s*M30\b", line))
    out: list[str] = []
    for line in lines[: end + 1]:
        call = re.match(r"\s*M97\s*P(\d+)(?:\s*L(\d+))?", line)
        if call is None:
            out.append(line)
            continue
        start = next(n for n, line in enumerate(lines) if re.match(rf"\s*N{call[1]}\b", line))
        stop = next(n for n in range(start, len(lines)) if re.match(r"\s*M99\b", lines[n]))
        out += lines[start:stop] * int(call[2] or 1)
    return "\n".join(out) + "\n"


def _written(tmp_path: Path, program: str, by_hand: str, **options) -> tuple[Path, Path, str, str]:
    """(the original written out by hand, the output written out by the manual's rule, the output,
    what ncpp said)."""
    source, original, inlined = tmp_path / "p.nc", tmp_path / "by_hand.ngc", tmp_path / "output.ngc"
    source.write_text(program)
    original.write_text(by_hand)
    warned = io.StringIO()
    output = compensate_file(source, MACHINE, tmp_path, warnings=Warnings(stream=warned), **options)
    text = output.read_text()
    inlined.write_text(_inlined(text))
    return original, inlined, text, warned.getvalue()


def test_the_manuals_rule_writes_the_programs_out_as_by_hand():
    """The rule the outputs are read by gives the programs written out by hand (the judge's own check)."""
    unlabelled = [re.sub(r"^N1000 \(.*\)\n", "", _inlined(p), flags=re.M) for p in (ONCE, PASSES)]
    assert unlabelled == [BY_HAND["one run"][1], PASSES_BY_HAND]


def test_a_subprogram_run_once_is_compensated_where_it_stands(tmp_path):
    original, inlined, output, warned = _written(tmp_path, ONCE, BY_HAND["one run"][1])
    assert _worst_point_um(original, inlined) <= 0.5
    assert "loop or subroutine" not in warned and "M97 P1000\n" in output
    assert output.index("G2 X") > output.index("M30") and output.count("G2 X") == 1  # (at its text)
    check = _pathcheck(original, inlined, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


def test_expanded_each_run_lands_where_programmed(tmp_path):
    original, inlined, output, warned = _written(tmp_path, PASSES, PASSES_BY_HAND, expand=True)
    assert _worst_point_um(original, inlined) <= 0.5
    assert not re.search("^M97", output, re.M) and output.split("M30\n")[1] == PASSES.split("M30\n")[1]
    check = _pathcheck(original, inlined, "--tol-mm", "0.02")
    assert check.returncode == 0, check.stdout + check.stderr


@pytest.mark.parametrize("program, by_hand", [(PASSES, PASSES_BY_HAND),
                                              (ONCE.replace("M97 P1000\n", "M97 P1000\nM97 P1000\n"), None)])  # fmt: skip
def test_runs_again_stay_as_programmed_with_the_warning(tmp_path, program, by_hand):
    """L3, or a second call: the text runs more than once, so it carries no one run's corrections."""
    by_hand = by_hand or _inlined(program)
    original, inlined, output, warned = _written(tmp_path, program, by_hand)
    assert _worst_point_um(original, inlined) > 2.0
    assert "warning: loop or subroutine" in warned and output.endswith(program.split("M30\n")[1])
