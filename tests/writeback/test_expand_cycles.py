"""`--expand-cycles`: a canned cycle's block is written as G0/G1 blocks, each move compensated,
and G4 where G82 and G89 dwell, for controls without canned cycles.  Judged by LinuxCNC's rs274
on the output (the same dwells; no cycle left; every hole's bottom and R point where the
program puts them on a machine written here by hand), and the cycles that cannot be written so
are refused."""

from __future__ import annotations

import io
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.pipeline import ErrorSource, process
from tests.conftest import ROOT
from tests.writeback.conftest import compensate_file
from tests.writeback.test_compensated_holes import MACHINE, _rs274_text, drilled, square

PROGRAM = """G21 G90 G17
G0 X40 Y30 Z25
G1 X45 Y35 F300
G0 Z25
G99 G81 X100 Y120 R3 Z-16 F100
X30 Y40
G98 G83 X150 Y-50 R5 Z-20 Q4
X-80 Y60
G80
G0 X0 Y0
G99 G82 X200 Y10 R2 Z-5 P0.5 M8
G85 X210 R2.5 Z-7.5
G73 X220 Y100 Z-9 R1 Q2.5
G89 X240 Y120 Z-3 R1 P1
G91 G81 X10 Y-10 R-24 Z-5 L2
G90 G80
M9
M2
"""
HOLES = [
    (100, 120, -16, 3), (30, 40, -16, 3), (150, -50, -20, 5), (-80, 60, -20, 5), (200, 10, -5, 2),
    (210, 10, -7.5, 2.5), (220, 100, -9, 1), (240, 120, -3, 1), (250, 110, -4, 1), (260, 100, -4, 1),
]  # fmt: skip


def test_expanded_cycles_dwell_as_programmed_and_hit_every_hole(tmp_path):
    original = tmp_path / "holes.ngc"
    original.write_text(PROGRAM)
    output = compensate_file(original, MACHINE, tmp_path, expand_cycles=True)
    text = output.read_text()
    assert not re.search(r"G(7[34]|8[1-9])\b", text)  # no cycle left
    dwells = [re.findall(r"DWELL\(([^)]*)\)", _rs274_text(p)) for p in (original, output)]
    assert dwells[0] == dwells[1] == ["0.5000000", "1.0000000"]
    wanted = np.array(HOLES, dtype=float)
    assert np.allclose([tuple(b) + (r,) for b, r in drilled(original, None)], wanted, atol=1e-6)
    after = drilled(output, square)
    assert len(after) == len(HOLES)
    assert max(np.linalg.norm(b - h[:3]) for (b, _), h in zip(after, wanted)) * 1000 <= 0.5
    assert max(abs(r - h[3]) for (_, r), h in zip(after, wanted)) * 1000 <= 0.5


class Shift:
    """Every point lands 6 µm off in X."""

    def deviation(self, P, direction=None):
        return np.broadcast_to(np.array([0.006, 0.0, 0.0]), np.shape(P)).copy()


@pytest.mark.parametrize("cycle", ["G84 X2 Y2 Z-1 R1", "G74 X2 Y2 Z-1 R1", "G86 X2 Y2 Z-1 R1 P1",
                                   "G87 X2 Y2 Z-1 R1 I1 J0 K0", "fanuc G76 X2 Y2 Z-1 R1 Q0.1",
                                   "fanuc G98 G87 X2 Y2 Z1 R-1 I1"])  # fmt: skip
def test_the_cycles_g0_g1_cannot_do_are_refused(cycle):
    """(Fanuc's G76, fine boring, orients the spindle and shifts the tool at the bottom; its G87 orients it
    to shift the tool at the initial level.)"""
    dialect = "fanuc" if cycle.startswith("fanuc ") else None
    cycle = cycle.removeprefix("fanuc ")
    spindle = "M4" if cycle.startswith("G74") else "M3"
    program = f"G21 G90\nG0 X0 Y0 Z5\n{spindle} S100\nG1 X1 F100\n{cycle} F100\nG80\nM2\n"
    source = ErrorSource(Shift(), "shift", "0" * 16, 0.5)
    with pytest.raises(
        NcppError,
        match=rf"t\.ngc:5:\d+: --expand-cycles: {cycle.removeprefix('G98 ')[:3]} cannot be written as G0/G1",
    ):
        process(io.BytesIO(program.encode()), io.BytesIO(), file="t.ngc", source=source,
                warnings=Warnings(stream=open(os.devnull, "w")), expand_cycles=True, dialect=dialect)  # fmt: skip


@pytest.mark.parametrize("command", [("ncpp", "compensate"), ("ncpp",)])
def test_both_commands_take_the_option(tmp_path, command):
    (tmp_path / "machine.toml").write_text(MACHINE)
    (tmp_path / "p.ngc").write_text("G21 G90\nG0 X0 Y0 Z5\nG82 X10 Y10 Z-1 R1 P0.2 F100\nG80\nM2\n")
    environ = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    environ.update(PYTHONPATH=str(ROOT), HOME=str(tmp_path))
    proc = subprocess.run([sys.executable, "-m", *command, "--machine", "machine.toml", "--expand-cycles", "p.ngc",
                           "-o", "out.ngc"], capture_output=True, cwd=tmp_path, env=environ, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    written = (tmp_path / "out.ngc").read_text()
    assert "G82" not in written and "G4 P0.2" in written and "canned cycle" not in proc.stderr.decode()


def test_linuxcnc_dwells_keep_every_digit_of_their_seconds(tmp_path):
    """rs274ngc reads a cycle's P and a G4's P in seconds: the G4 dwells exactly as long, however small
    or large the P, and a P from an expression is written as its value."""
    original = tmp_path / "dwells.ngc"
    original.write_text("G21 G90\nG0 X0 Y0 Z5\nG82 X10 Y10 Z-1 R1 P0.0000125 F100\nX20 P1234567.25\n"
                        "G89 X30 Z-2 R1 P[2 * 0.75]\nG80\nM2\n")  # fmt: skip
    output = compensate_file(original, MACHINE, tmp_path, expand_cycles=True)
    dwells = [re.findall(r"DWELL\(([^)]*)\)", _rs274_text(p)) for p in (original, output)]
    assert dwells[0] == dwells[1] == ["0.0000125", "1234567.2500000", "1.5000000"]


def _expanded_text(program: str, dialect: str) -> str:
    out = io.BytesIO()
    process(io.BytesIO(program.encode()), out, file="t.nc", source=ErrorSource(Shift(), "shift", "0" * 16, 0.5),
            warnings=Warnings(stream=open(os.devnull, "w")), dialect=dialect, expand_cycles=True)  # fmt: skip
    return out.getvalue().decode()


FLAVOUR_DWELLS = (
    "%\nO1\nG21 G90 G17\nG0 X0 Y0 Z5\nG99 G82 X10 Y10 Z-1 R1 P{first} F100\nX20 P{second}\nG80\nM30\n%\n"
)


@pytest.mark.parametrize("dialect, first, second", [("fanuc", "12345678", "0500"), ("haas", "0.3", "2.")])
def test_fanuc_and_haas_dwells_are_written_with_the_programs_p(dialect, first, second):
    """Fanuc reads a G04's P as a cycle's, whole units of 0.001 s without a decimal point; Haas reads a
    G04's P with a decimal point in seconds, as a cycle's: the P as the program gave it is the same time."""
    text = _expanded_text(FLAVOUR_DWELLS.format(first=first, second=second), dialect)
    assert re.findall(r"^G4 (P\S*)$", text, re.M) == [f"P{first}", f"P{second}"]
    assert "G82" not in text


@pytest.mark.parametrize("dialect, p, why", [
    ("fanuc", "2.5", "only a P as a whole number, without a decimal point"),
    ("fanuc", "#1", "only a P as a whole number"),
    ("haas", "300", "only a P in seconds with a decimal point"),
    ("haas", "[0.1 * 3]", "only a P in seconds"),
])  # fmt: skip
def test_a_dwell_whose_g04_the_control_may_read_otherwise_is_refused(dialect, p, why):
    program = "%\nO1\n#1 = 2.5\nG21 G90\nG0 X0 Y0 Z5\nG82 X10 Y10 Z-1 R1 P" + p + " F100\nG80\nM30\n%\n"
    with pytest.raises(
        NcppError, match=rf"t\.nc:6:\d+: --expand-cycles: the canned cycle's dwell .*{re.escape(why)}"
    ):
        _expanded_text(program, dialect)


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_a_dwell_under_feed_per_revolution_is_refused(dialect):
    """With G95 a Fanuc G04 may count spindle revolutions (parameter DWL), not time."""
    p = "500" if dialect == "fanuc" else "0.5"
    program = FLAVOUR_DWELLS.format(first=p, second=p)
    program = program.replace("G17\n", "G17 G95\nM3 S1000\n").replace("F100", "F0.1")
    with pytest.raises(NcppError, match=r"t\.nc:6:\d+: --expand-cycles: .*G95"):
        _expanded_text(program, dialect)
    assert "G4 P" in _expanded_text(program.replace("G95", "G94"), dialect)
