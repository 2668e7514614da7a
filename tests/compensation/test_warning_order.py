"""Warnings come out in the order of their lines, though the stages of a run meet the lines at
different times (the interpreter reads ahead of the writer)."""

from __future__ import annotations

import io
import re

import pytest

from ncpp.errors import _HELD_MOST, Location, NcppError, Warnings
from ncpp.pipeline import ErrorSource, process
from tests.conftest import SHARED

WIDE = SHARED / "machines" / "wide.toml"

# The writer warns at line 3 (Y not positioned yet) when it writes it; the interpreter at line 5
# (G38.2, probing, out of its scope) when it reads it, ahead of the writer
PROGRAM = "G21 G90\nG0 Z5\nG1 X10 F100\nG1 X20\nG38.2 Z-5 F10\nG1 X30\nM2\n"


def said_lines(text: str) -> list[int]:
    return [int(n) for n in re.findall(r"^p\.ngc:(\d+):\d+: warning", text, re.M)]


@pytest.mark.skipif(not WIDE.exists(), reason="no shared machine file")
@pytest.mark.parametrize("verify", [True, False])
def test_the_writers_warning_comes_before_a_later_lines_of_the_interpreter(verify):
    said = io.StringIO()
    source = ErrorSource.from_machine_file(str(WIDE))
    process(io.BytesIO(PROGRAM.encode()), io.BytesIO(), file="p.ngc", source=source,
            warnings=Warnings(stream=said), verify=verify)  # fmt: skip
    assert said_lines(said.getvalue()) == [3, 5]


@pytest.mark.skipif(not WIDE.exists(), reason="no shared machine file")
def test_the_warnings_held_are_said_when_the_run_is_refused():
    said = io.StringIO()
    program = PROGRAM.replace("G38.2 Z-5 F10\n", "").replace("G1 X30", "G1 X30 F-1")
    with pytest.raises(NcppError, match="Negative f word"):
        process(io.BytesIO(program.encode()), io.BytesIO(), file="p.ngc",
                source=ErrorSource.from_machine_file(str(WIDE)), warnings=Warnings(stream=said))  # fmt: skip
    assert said_lines(said.getvalue()) == [3]


def test_the_warnings_held_stay_bounded_and_come_out_in_order_within_the_bound():
    said = io.StringIO()
    warnings = Warnings(stream=said)
    lines = [*range(2 * _HELD_MOST, 0, -1)]  # (each text once, the lines backwards)
    with warnings.in_line_order() as release:
        for n in lines[:10]:
            warnings.warn(f"w{n}", Location("p.ngc", n, 1))
        release(lines[9])  # (the run is past the earliest of them: it goes, the others wait)
        assert said_lines(said.getvalue()) == [lines[9]]
        for n in lines[10:]:
            warnings.warn(f"w{n}", Location("p.ngc", n, 1))
            assert len(warnings._held or ()) <= _HELD_MOST
    out = said_lines(said.getvalue())
    assert sorted(out) == sorted(lines)
    assert out[-_HELD_MOST:] == sorted(out[-_HELD_MOST:])  # (the last held, in order)
