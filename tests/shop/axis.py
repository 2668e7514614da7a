"""LinuxCNC's AXIS running a [FILTER] program: its own `filter_program`, taken from the
`axis` script of Debian's linuxcnc-uspace (unpacked by tools/rs274), with the screen
stubbed out.  What the filter meets there: `sh -c "FILTER 'PROGRAM'"`, standard input
a closed pipe, standard output the file AXIS then loads, standard error read line by
line: `FILTER_PROGRESS=N` lines move the progress bar, all others are the message
AXIS shows in its "Filter failed" dialog when the exit code is not 0."""

from __future__ import annotations

import ast
import os
import re
import select
import sys
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from tests.rs274 import linuxcnc_root


@dataclass
class Filtered:
    """What AXIS got from the filter."""

    exit_code: int
    message: str  # standard error without the progress lines (AXIS's dialog text)
    progress: list[int] = field(default_factory=list)  # the FILTER_PROGRESS values, in order
    closed: bool = False  # the progress bar was taken down


def filter_program(scratch: Path) -> Callable[[str, Path, Path], Filtered]:
    """AXIS's `filter_program(program_filter, infilename, outfilename)`, returning `Filtered`."""
    axis = linuxcnc_root(scratch) / "usr/bin/axis"
    if not axis.exists():
        pytest.skip("the linuxcnc-uspace package has no AXIS script")
    tree = ast.parse(axis.read_text(encoding="utf-8"), str(axis))
    wanted = [node for node in tree.body if _defines(node, "filter_program", "progress_re")]
    if len(wanted) != 2:
        pytest.fail(f"{axis}: filter_program or progress_re not found (a LinuxCNC that filters otherwise)")
    code = compile(ast.Module(body=wanted, type_ignores=[]), str(axis), "exec")

    def run(program_filter: str, infile: Path, outfile: Path) -> Filtered:
        bars: list[_Progress] = []

        def progress(phases: int, total: int) -> _Progress:
            bars.append(_Progress())
            return bars[-1]

        namespace = {
            "os": os,
            "re": re,
            "select": select,
            "sys": sys,
            "_": str,
            "t": _Screen(),
            "Progress": progress,
        }
        exec(code, namespace)
        exit_code, message = namespace["filter_program"](program_filter, str(infile), str(outfile))
        (bar,) = bars
        return Filtered(exit_code, message, bar.values, bar.closed)

    return run


def _defines(node: ast.stmt, function: str, name: str) -> bool:
    if isinstance(node, ast.FunctionDef):
        return node.name == function
    return isinstance(node, ast.Assign) and any(
        isinstance(t, ast.Name) and t.id == name for t in node.targets
    )


class _Screen:
    """AXIS's text widget `t`: the filter loop redraws it between reads."""

    def update(self) -> None:
        pass


class _Progress:
    """AXIS's `Progress` bar: what the filter moved it to."""

    def __init__(self) -> None:
        self.values: list[int] = []
        self.closed = False

    def set_text(self, text: str) -> None:
        pass

    def update(self, count: int, force: int = 0) -> None:
        self.values.append(count)

    def done(self) -> None:
        self.closed = True
