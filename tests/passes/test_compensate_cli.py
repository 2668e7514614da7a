"""`ncpp compensate` end to end: header, refusal, limits, accuracy, valid arcs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from tests import rs274
from tests.conftest import ROOT, RS274

MACHINE = ROOT / "samples/machines/hr5b.toml"
POCKET = ROOT / "samples/programs/pocket.ngc"
OFFSET = "400,350,300"


def ncpp(*args: str, input: bytes | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "ncpp", *args], input=input, capture_output=True)


@pytest.fixture(scope="module")
def compensated(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("comp") / "pocket.ngc"
    # (no placement guard: rs274 runs it from G54 at 0)
    proc = ncpp(
        "compensate",
        "--machine",
        str(MACHINE),
        "--work-offset",
        OFFSET,
        "--no-guard",
        str(POCKET),
        "-o",
        str(out),
    )
    assert proc.returncode == 0, proc.stderr.decode()
    return out


def test_header_names_machine_and_hash_after_tape_mark(compensated):
    lines = compensated.read_text().splitlines()
    assert lines[0] == "%"
    assert lines[1].startswith("(ncpp compensated for hr5b.toml sha256:")


def test_untouched_blocks_are_byte_identical(compensated):
    out = compensated.read_text().splitlines()
    for line in (
        "(ncpp sample: a 60 x 40 mm pocket with R10 corners and a finishing circle)",
        "G21 G17 G90 G54",
        "M2",
    ):
        assert line in out


def test_second_compensation_is_refused_unless_forced(compensated, tmp_path):
    proc = ncpp("compensate", "--machine", str(MACHINE), "--work-offset", OFFSET, str(compensated))
    assert proc.returncode != 0 and b"already compensated" in proc.stderr and proc.stdout == b""
    forced = ncpp(
        "compensate", "--force", "--machine", str(MACHINE), "--work-offset", OFFSET, str(compensated)
    )
    assert forced.returncode == 0


def test_command_outside_travel_is_refused_with_line_and_no_output(tmp_path):
    out = tmp_path / "out.ngc"
    proc = ncpp("compensate", "--machine", str(MACHINE), str(POCKET), "-o", str(out))
    assert proc.returncode != 0
    # at machine zero (no work offset) the first move stands at the X travel's end (X0: stays
    # there); the second (`X-20. Y-10.`, line 5) leaves the travel: the program's first fault,
    # before the arc of line 8 that leaves the Y travel
    assert proc.stderr.decode().startswith(f"{POCKET}:5:1: command X-20.0045 mm is outside the X travel")
    assert not out.exists()


def test_contour_error_shrinks_on_the_virtual_machine(compensated, tmp_path):
    def simulate(program: Path) -> float:
        report = tmp_path / f"{program.stem}-{len(list(tmp_path.iterdir()))}.json"
        proc = ncpp(
            "simulate",
            "--machine",
            str(MACHINE),
            "--work-offset",
            OFFSET,
            "--reference",
            str(POCKET),
            str(program),
            "--json",
            str(report),
        )
        assert proc.returncode == 0, proc.stderr.decode()
        import json

        return json.loads(report.read_text())["contour_error_max_um"]

    before, after = simulate(POCKET), simulate(compensated)
    assert before > 20.0
    assert after < before / 5


@pytest.mark.skipif(not RS274.exists(), reason="rs274 oracle not available")
def test_linuxcnc_accepts_every_compensated_arc(compensated):
    proc = rs274.run(compensated)
    assert "ARC_FEED" in proc.stdout
    assert "error" not in (proc.stdout + proc.stderr).lower()


def test_compensate_from_ballbar_file(tmp_path):
    program = tmp_path / "circle.ngc"
    program.write_text("G21 G17 G90\nG0 X550. Y-200. Z350.\nG1 F1000.\nG2 X550. Y-200. I-150. J0.\nM2\n")
    ballbar = ROOT / "samples/measurements/ballbar_XY_R150.csv"
    proc = ncpp("compensate", "--from", str(ballbar), str(program))
    assert proc.returncode == 0, proc.stderr.decode()
    text = proc.stdout.decode()
    assert "ballbar_XY_R150.csv" in text.splitlines()[0]
    assert text.count("G2") + text.count("G3") >= 1 and len(text.splitlines()) > 6


def test_thesis_reference_case_from_a_ballbar_file(tmp_path):
    """Section 6.5.2.1 of M. Rahman, *Modeling and measurement of multi-axis machine tools to
    improve positioning accuracy in a software way*, University of Oulu, 2004, through the
    command: ΔR(θ) = 9.1·sin 2θ µm from a ball-bar file, a full R150 circle in G91, one arc per
    quadrant (blocks N201-N204)."""
    import numpy as np

    angles = np.arange(0.0, 360.0, 1.0)
    rows = [f"{d},{a:g},{9.1 * np.sin(2 * np.radians(a)):.4f}" for d in ("CCW", "CW") for a in angles]
    ballbar = tmp_path / "bb.csv"
    ballbar.write_text(
        "# instrument: ballbar\n# plane: XY\n# radius_mm: 150\n# center_mm: 400,-200,350\n# feed_mm_min: 500\n"
        "direction,angle_deg,deviation_um\n" + "\n".join(rows) + "\n"
    )
    program = tmp_path / "circle.ngc"
    program.write_text(
        "G21 G17 G90\nG0 X550.000 Y-200.000 Z350.000\nG91\nN200 G02 X0 Y0 I-150.000 J0 F500\nG90\nM2\n"
    )
    proc = ncpp("compensate", "--from", str(ballbar), "--tolerance", "0.004", str(program))
    assert proc.returncode == 0, proc.stderr.decode()
    lines = proc.stdout.decode().splitlines()
    arcs = [ln for ln in lines if "I" in ln]
    assert len(arcs) == 4
    from ncpp.program.parser import parse_text

    # N201 is the thesis's block; N202-N204 follow from the symmetry of sin 2θ
    # (quadrants where ΔR > 0 get centres moved outward, radius 150.022).
    thesis = [
        (-150, -150, -149.978, -0.022),
        (-150, 150, 0.022, 150.022),
        (150, 150, 149.978, 0.022),
        (150, -150, -0.022, -150.022),
    ]
    for text, (x, y, i, j) in zip(arcs, thesis):
        words = {w.letter: w.value for w in parse_text(text + "\n")[0].words()}
        assert (words["X"], words["Y"]) == pytest.approx((x, y), abs=0.001)
        assert (words["I"], words["J"]) == pytest.approx((i, j), abs=0.001)
    # at least 4 decimals (0.1 µm) whatever the input wrote, so rounding stays far below tolerance
    assert arcs[0].startswith("N200 G02 X-150.0000 Y-150.0000 I-149.97")


@pytest.mark.parametrize(
    "program, turns", [("G2 X0 Y0 I10 J0 Z1 P10001 F100", "10,001"), ("G2 X0 Y0 I10 J0 Z1 P10000 F100", None)]
)
def test_an_arc_of_more_turns_than_compensation_holds_is_refused_with_its_line(tmp_path, program, turns):
    path = tmp_path / "helix.ngc"
    path.write_text(f"G17 G21 G90\nG0 X0 Y0 Z0\n{program}\nM2\n")
    # (a path lying over itself 10,000 times is more than the verifier looks at: `verify._Nearby`)
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(MACHINE), "--work-offset", "400,350,300", str(path),
                           "--no-verify"], capture_output=True, text=True)  # fmt: skip
    if turns is None:  # (10,000 turns: 80,000 lines)
        assert proc.returncode == 0 and proc.stdout.count("\n") > 80_000
    else:
        assert (
            proc.returncode == 2
            and proc.stdout == ""
            and proc.stderr.startswith(f"{path}:3:20: an arc of {turns} turns")
        )  # at its P word


def test_simulate_refuses_motion_outside_the_travel_and_paths_past_its_sample_budget(tmp_path):
    """The virtual machine cannot run a move past its travel (it reported a contour error
    from tables held past their ends), nor sample one of 10^13 mm (a 146 TiB array)."""
    program = tmp_path / "far.ngc"
    program.write_text("G21 G90\nG0 X0 Y0 Z0\nG1 X5000 F100\nM2\n")
    proc = ncpp("simulate", "--machine", str(MACHINE), "--work-offset", "400,350,370", str(program))
    assert proc.returncode == 2 and b"Traceback" not in proc.stderr
    assert (
        f"{program}:3:4: the motion reaches X800.5000 mm, outside the X travel [0, 800] mm".encode()
        in proc.stderr
    )
    program.write_text(
        "G21 G90\nG0 X0 Y0 Z0\nG1 Z-50 Y5000 F100\nG1 X5000\nM2\n"
    )  # the first line out, whichever axis
    proc = ncpp("simulate", "--machine", str(MACHINE), "--work-offset", "400,350,370", str(program))
    assert (
        f"{program}:3:9: the motion reaches Y700.".encode() in proc.stderr
        and b"outside the Y travel" in proc.stderr
    )
    program.write_text("G21 G90\nG0 X10 Y10\nG0 X9999999999999 Y10\n")
    proc = ncpp("simulate", "--machine", str(MACHINE), "--work-offset", "400,350,370", str(program))
    assert proc.returncode == 2 and b"Traceback" not in proc.stderr
    assert f"{program}:3:1: the path needs more than 20,000,000 samples".encode() in proc.stderr
