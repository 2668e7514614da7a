"""Every ISO program of the corpus that LinuxCNC runs, compensated on the wide test machine,
judged by an oracle ncpp did not write: `shared/tools/pathcheck` runs LinuxCNC's rs274 on the
original and on ncpp's output and checks the same actions in the same order, the path within
its tolerance, rapids as rapids and feeds as feeds.

No program is skipped for not fitting a machine: wide.toml's travel holds them all at work
offset 0.  A program rs274 runs that ncpp refuses fails the test, unless the refusal is one of
ncpp's documented scope limits (`SCOPE_LIMITS`, matched by its message).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from ncpp.program.dialects import SNIFF_BYTES, detect
from tests import rs274
from tests.conftest import CORPUS, SHARED, corpus_files, corpus_id

pytestmark = [pytest.mark.oracle, pytest.mark.slow]

PATHCHECK = SHARED / "tools" / "pathcheck"
WIDE = SHARED / "machines" / "wide.toml"
# Refusals that are ncpp's documented scope, not faults (docs/conformance.md): the message
# ncpp gives, matched against its error line.
SCOPE_LIMITS: dict[str, str] = {
    # ncpp models the linear axes; wide.toml does not say its X Y Z are axis positions
    # (docs/guide.md, "Rotary axes")
    "a move that turns a rotary axis": r"this move turns [ABC]( and [ABC])*, and ncpp models the linear axes only",
    "tool-centre-point control": r"turns tool-centre-point control on",
}


def tool_table(folder: Path) -> Path:
    """Tools 1-99 with lengths of 10.7-60.5 mm and diameters of 0.5-1 mm, for rs274 and ncpp
    alike (in inches: the stand-alone rs274 reads its tool table so, ncpp is told --var-units inch)."""
    path = folder / "tools.tbl"
    if not path.exists():
        path.write_text(
            "".join(
                f"T{n} P{n} Z{0.4 + 0.02 * n:.2f} D{0.02 + 0.005 * (n % 5):.3f} ;tool {n}\n"
                for n in range(1, 100)
            )
        )
    return path


def rs274_environment(home: Path) -> dict[str, str]:
    """rs274 keeps its tool data in $HOME/.tool.mmap: a home of its own for each test, so that
    runs side by side do not truncate each other's (a bus error)."""
    unpacked = os.environ.get("RS274_HOME") or str(Path.home() / ".cache" / "ncpp-rs274")
    return dict(os.environ, HOME=str(home), RS274_HOME=unpacked)


def rs274_runs(program: Path, tools: Path, env: dict[str, str]) -> bool:
    proc = rs274.run(program, tool_table=tools, home=Path(env["HOME"]), cwd=program.parent, timeout=600)
    if not rs274.ran(proc):
        pytest.skip(f"rs274 oracle did not run: {proc.stderr.strip()[:200]}")
    errors = rs274.messages(proc)
    return not errors or errors[0].startswith("File ended with no percent sign or program end")


def as_linuxcnc_reads(program: Path, folder: Path) -> Path:
    """The program for rs274: a grbl program's arcs without the K word grbl ignores in G17 (its
    gcode.c clears I J K as used), which rs274 refuses; any other program as it is."""
    text = program.read_bytes()
    if detect(text[:SNIFF_BYTES], program.name) != "grbl":
        return program
    lines = text.decode("latin-1").splitlines(keepends=True)
    plain = folder / program.name
    plain.write_bytes(
        "".join(_NORMAL_K.sub("", line) if _ARC_OFFSET.search(line) else line for line in lines).encode(
            "latin-1"
        )
    )
    return plain


_ARC_OFFSET = re.compile(r"\b[IJ][-+.\d]")
_NORMAL_K = re.compile(r"\s*\bK[-+]?[\d.]+")


def tolerance_mm(report: Path) -> float:
    """How far the compensated path may lie from the original's: twice the largest correction ncpp
    made (a reversal step spans the corrections of both directions; a loop left as programmed runs
    from a corrected point) and 10 µm for rs274's printed digits and the arcs' refit, at most the
    machine file's max_correction_mm (wide.toml: 0.5).  A move the program makes that compensation
    did not ask for (a µm step under cutter compensation swings the tool centre by the radius) lies
    further off than that."""
    largest_um = json.loads(report.read_text())["largest_correction_um"]
    return min(0.5, 2 * largest_um / 1000 + 0.01)


def programs() -> list[Path]:
    return corpus_files("iso_gcode") if CORPUS.is_dir() else []


@pytest.fixture(scope="module")
def tools(tmp_path_factory) -> Path:
    return tool_table(tmp_path_factory.mktemp("tools"))


@pytest.mark.parametrize("program", programs(), ids=corpus_id)
def test_pathcheck_passes_on_the_compensated_program(program: Path, tools: Path, tmp_path: Path):
    if not (PATHCHECK.exists() and WIDE.exists()):
        pytest.skip(f"pathcheck or wide.toml not found under {SHARED}")
    env = rs274_environment(tmp_path)
    original = as_linuxcnc_reads(program, tmp_path)
    if not rs274_runs(original, tools, env):
        pytest.skip("rs274 refuses the original: nothing to compare")
    written, report = tmp_path / (program.name + ".out.ngc"), tmp_path / "report.json"
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(WIDE), "--tool-table", str(tools),
                           "--var-units", "inch", str(program), "-o", str(written), "--report", str(report)],
                          capture_output=True, text=True, errors="replace", timeout=1800, stdin=subprocess.DEVNULL)  # fmt: skip
    if proc.returncode != 0:
        error = next((line for line in proc.stderr.splitlines() if ": warning: " not in line), proc.stderr)
        limit = next((name for name, pattern in SCOPE_LIMITS.items() if re.search(pattern, error)), None)
        assert limit is not None, f"ncpp refuses a program rs274 runs: {error}"
        return
    check = subprocess.run([sys.executable, str(PATHCHECK), str(original), str(written), "--tool-table", str(tools),
                            "--tol-mm", f"{tolerance_mm(report):.4f}"],
                           capture_output=True, text=True, timeout=1800, env=env)  # fmt: skip
    assert check.returncode == 0, check.stdout + check.stderr
