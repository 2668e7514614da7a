"""The summary of a compensating run, and the warning of a run that compensates nothing."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys

import numpy as np
import pytest

from ncpp.pipeline import ErrorSource, process
from tests.conftest import ROOT

MACHINE = ROOT / "samples/machines/hr5b.toml"
# 3 plain moves after a rapid, a G81 cycle of two holes (compensated hole by hole), a G41 section (and the
# rapid after the cycle)
PROGRAM = b"""G21 G90 G17 G54
G0 X10 Y10 Z5
G1 Z-1 F300
G1 X40 Y10
G1 X40 Y30
G98 G81 X50 Y50 Z-3 R2 F100
X60
G80
G0 Z5
G41 D1 G1 X70 Y40 F200
G1 X80 Y40
G40 G1 X90 Y40
M2
"""


class Shift:
    """Every point lands 6 um off in X and -8 um in Y: each correction is 10 um."""

    def deviation(self, P, direction=None):
        return np.broadcast_to(np.array([0.006, -0.008, 0.0]), np.shape(P)).copy()


def test_the_figures_of_a_hand_made_program():
    source = ErrorSource(Shift(), "shift", "0" * 16, 0.5)
    stats = process(io.BytesIO(PROGRAM), io.BytesIO(), file="hand.ngc", source=source, warnings=None)
    s = stats.summary
    # G0 X10 Y10 Z5, G1 Z-1, X40 Y10, X40 Y30, G0 Z5; 4 a hole (up to R: the series started below it, over,
    # down, up); the G41, G1 and G40 moves (compensated where the tool centre stands)
    assert s.moves == 5 + 8 + 3
    # the feed moves: Z5 to Z-1, then 30 and 20 mm; each hole 5 mm down from R; 10√2, 10 and 10 mm
    assert s.feed_mm == pytest.approx(6 + 30 + 20 + 2 * 5 + 10 * 2**0.5 + 20)
    assert s.largest_mm == pytest.approx(0.010, abs=2e-7)
    assert s.left_moves == {} and s.left == {}
    assert (s.lines_in, s.lines_out) == (13, stats.lines_out)
    line = s.line()
    assert "compensated 16 moves (100.1 mm of feed path), largest correction 10.0 µm" in line
    assert "left as programmed: nothing;" in line


def test_out_of_scope_is_counted_from_its_line():
    program = b"G21 G90\nG0 X10 Y10 Z5\nG1 X20 F100\nG38.2 Z-5 F50\nG0 Z5\nG1 X30\nM2\n"
    source = ErrorSource(Shift(), "shift", "0" * 16, 0.5)
    s = process(io.BytesIO(program), io.BytesIO(), file="p.ngc", source=source).summary
    assert s.passed_on_from == 4 and s.moves == 2
    assert "everything from line 4 on (4 lines), out of scope" in s.line()
    assert s.as_dict()["left_as_programmed"]["out of scope"]["lines"] == [[4, 7]]


def _ncpp(*args: str, cwd=None, env=None, stdin: bytes | None = None) -> subprocess.CompletedProcess:
    environ = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME")}
    environ.update(PYTHONPATH=str(ROOT), HOME=str(cwd), **(env or {}))
    return subprocess.run(
        [sys.executable, "-m", *args], input=stdin, capture_output=True, cwd=cwd, env=environ, timeout=300
    )


@pytest.mark.parametrize("command", [("ncpp", "compensate"), ("ncpp",)])
def test_the_summary_is_on_stderr_without_a_terminal_and_in_the_report(tmp_path, command):
    (tmp_path / "hand.ngc").write_bytes(PROGRAM)
    proc = _ncpp(
        *command,
        "--machine",
        str(MACHINE),
        "--work-offset",
        "400,350,300",
        "hand.ngc",
        "-o",
        "out.ngc",
        "--report",
        "r.json",
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    summary = [ln for ln in proc.stderr.decode().splitlines() if ln.startswith("ncpp: hand.ngc: compensated")]
    assert len(summary) == 1 and "13 lines in" in summary[0]
    report = json.loads((tmp_path / "r.json").read_text())
    assert report["moves_compensated"] == 16 and report["feed_path_compensated_mm"] == 100.1421
    assert report["left_as_programmed"] == {}
    assert 1.0 < report["largest_correction_um"] < 100.0 and report["lines_in"] == 13


def test_the_post_tells_its_summary(tmp_path):
    proc = _ncpp(
        "ncpp",
        "post",
        str(ROOT / "samples/programs/pocket.cls"),
        "--dialect",
        "linuxcnc",
        "--machine",
        str(MACHINE),
        "--work-offset",
        "400,350,300",
        "-o",
        "out.ngc",
        cwd=tmp_path,
    )
    assert proc.returncode == 0, proc.stderr
    assert "pocket.cls: compensated" in proc.stderr.decode()


def test_without_a_machine_file_the_filter_warns_and_passes_the_program_through(tmp_path):
    proc = _ncpp("ncpp", cwd=tmp_path, stdin=PROGRAM)
    assert proc.returncode == 0 and proc.stdout == PROGRAM
    assert proc.stderr.decode().count("nothing was compensated") == 1
    (tmp_path / "hand.ngc").write_bytes(PROGRAM)
    lcnc = _ncpp("ncpp.integrations.linuxcnc", "hand.ngc", cwd=tmp_path)
    assert lcnc.returncode == 0 and lcnc.stdout == PROGRAM
    assert lcnc.stderr.decode().count("nothing was compensated") == 1


def test_compensate_and_simulate_find_the_machine_file_as_ncpp_does(tmp_path):
    (tmp_path / "hand.ngc").write_bytes(PROGRAM)
    env = {"NCPP_MACHINE": str(MACHINE)}
    proc = _ncpp(
        "ncpp",
        "compensate",
        "--work-offset",
        "400,350,300",
        "hand.ngc",
        "-o",
        "out.ngc",
        cwd=tmp_path,
        env=env,
    )
    assert proc.returncode == 0, proc.stderr
    assert (tmp_path / "out.ngc").read_text().startswith("(ncpp compensated for hr5b.toml")
    (tmp_path / "ncpp.toml").write_text(f'machine = "{MACHINE}"\n')
    sim = _ncpp(
        "ncpp", "simulate", "--work-offset", "400,350,300", "out.ngc", "--reference", "hand.ngc", cwd=tmp_path
    )
    assert sim.returncode == 0, sim.stderr
    assert b"contour error" in sim.stdout


def test_several_programs_each_tell_their_summary_and_the_report_lists_them(tmp_path):
    lathe = PROGRAM.replace(b"G41 D1", b"G18 G41.1 D2 L3")  # (a lathe tool: left as programmed)
    (tmp_path / "a.ngc").write_bytes(lathe)
    (tmp_path / "b.ngc").write_bytes(PROGRAM.replace(b"G41 D1 G1 X70 Y40 F200\n", b"G1 X70 Y40 F200\n"))
    proc = _ncpp(
        "ncpp", "compensate", "--machine", str(MACHINE), "--work-offset", "400,350,300",
        "-o", "out", "a.ngc", "b.ngc", "--report", "r.json", cwd=tmp_path,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    said = [ln for ln in proc.stderr.decode().splitlines() if ": compensated " in ln]
    assert [ln.split(":")[1].strip() for ln in said] == ["a.ngc", "b.ngc"]
    a, b = json.loads((tmp_path / "r.json").read_text())
    assert (a["file"], b["file"]) == ("a.ngc", "b.ngc")
    assert a["left_as_programmed"]["cutter compensation"]["moves"] == 3
    assert (
        "cutter compensation" not in b["left_as_programmed"]
        and b["moves_compensated"] == a["moves_compensated"] + 3
    )
