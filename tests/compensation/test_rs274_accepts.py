"""Every emitted arc is valid: LinuxCNC's rs274 accepts each compensated corpus
program it accepted before.

Programs: every ISO-family corpus program under 100 kB, and a representative
few of the large ones (3D_Chips, systems, spiral_tangent_test); the other
large files (bear, cameo, tball-pocket, 3D_Chips_abort: 5-13 s each, same
constructs) are left to the benchmark.  A program rs274 refuses only for a
missing program end (the short cncjs arc samples, G18/G19 among them) gets
`M2` appended.  rs274 reads a tool table of tools 1-99 (0.01 across, in the
stand-alone rs274's inches; length 0), so that programs changing tools or compensating the cutter radius
are checked too (the wrapper's table has T1 alone: 8 programs more).  Each is
placed in the HR5B's travel (the Valmet's when it is too large, wide.toml's beyond), every work
system at one zero (mmount.ngc cuts in G55), and compensated at 1 µm with the
HR5B's model, reversal included.
"""

from __future__ import annotations

import subprocess

import pytest

from ncpp.machine import load_machine
from ncpp.motion.offsets import SYSTEMS, WorkOffsets
from ncpp.simulate import sample_events
from tests import rs274 as oracle
from tests.compensation.conftest import compensate, events_of, placement
from tests.conftest import CORPUS, ROOT, RS274, SHARED, corpus_files, corpus_id

LARGE = ("linuxcnc/3D_Chips.ngc", "linuxcnc/systems.ngc", "linuxcnc/spiral_tangent_test.ngc")
MISSING_END = "File ended with no percent sign or program end"
WIDE = SHARED / "machines" / "wide.toml"


def programs() -> list:
    if not (CORPUS / "iso_gcode").is_dir():
        return []
    small = [p for p in corpus_files("iso_gcode") if p.stat().st_size < 100_000]
    return small + [CORPUS / "iso_gcode" / name for name in LARGE]


def rs274(path, tools) -> subprocess.CompletedProcess:
    return oracle.run(path, tool_table=tools)


@pytest.fixture(scope="module")
def tools(tmp_path_factory):
    """A tool table of tools 1-99 (rs274's last -t is the one it reads)."""
    path = tmp_path_factory.mktemp("tools") / "tools.tbl"
    path.write_text("".join(f"T{n} P{n} D0.01 Z0\n" for n in range(1, 100)))
    return path


@pytest.fixture(scope="module")
def machines():
    """The HR5B, the Valmet when a program is too large for it, and the wide test machine
    (`shared/machines/wide.toml`) for any larger still: no program is skipped for its size."""
    found = [load_machine(ROOT / f"samples/machines/{name}.toml") for name in ("hr5b", "valmet")]
    return found + ([load_machine(WIDE)] if WIDE.exists() else [])


@pytest.mark.skipif(not RS274.exists(), reason="rs274 oracle not available")
@pytest.mark.parametrize("path", programs(), ids=corpus_id)
def test_rs274_accepts_compensated_program(path, machines, tools, tmp_path):
    data = path.read_bytes()
    before = rs274(path, tools)
    if before.returncode != 0 and MISSING_END in before.stderr:
        data += b"\nM2\n"
        (tmp_path / "original.ngc").write_bytes(data)
        before = rs274(tmp_path / "original.ngc", tools)
    assert before.returncode < 128, (
        f"rs274 crashed (signal {before.returncode - 128}): {before.stderr[-300:]}"
    )
    if before.returncode != 0:
        pytest.skip(f"rs274 refuses the original: {before.stderr.strip().splitlines()[-2:]}")
    nominal = sample_events(events_of(data, str(path)), step_mm=5.0)
    for machine in machines:
        offset = placement(nominal, machine.limits)
        if offset is not None:
            break
    else:
        pytest.skip("no motion, or too large for every machine's travel")
    out = tmp_path / "compensated.ngc"
    machine = machine.replace(
        rotary_xyz_are_axis_positions=True
    )  # (b-index.ngc turns B: compensated with its pieces' shares)
    out.write_bytes(
        compensate(data, machine, WorkOffsets.of(dict.fromkeys(SYSTEMS, offset)), name=str(path))
    )  # (G55.. at G54's zero)
    after = rs274(out, tools)
    assert after.returncode == 0, after.stderr[-500:]
    assert "error" not in (after.stdout + after.stderr).lower()
