"""Controller compensation tables: formats, limits, signs, read-back."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ncpp.cli import main
from ncpp.errors import NcppError
from ncpp.export import axis_error, export_table
from ncpp.export.fanuc import read_fanuc_pitch, write_fanuc_pitch
from ncpp.export.heidenhain import read_heidenhain_com
from ncpp.export.linuxcnc import flag_outliers, read_linuxcnc_comp, write_linuxcnc_comp
from ncpp.export.sinumerik import read_sinumerik
from ncpp.machine import Machine, Table, load_machine

ROOT = Path(__file__).resolve().parents[2]
HR5B = ROOT / "samples/machines/hr5b.toml"
SCREWCOMP = Path("/work/shared/corpus/metrology/linuxcnc/screwcompX.dat")
if not SCREWCOMP.exists():
    SCREWCOMP = ROOT.parent / "shared/corpus/metrology/linuxcnc/screwcompX.dat"


@pytest.fixture(scope="module")
def machine() -> Machine:
    return load_machine(HR5B)


def long_axis_machine(n: int = 600) -> Machine:
    """A 1200 mm axis measured every 2 mm with reversal: more points than LinuxCNC holds."""
    x = np.linspace(0.0, 1200.0, n)
    plus = 0.02 * np.sin(x / 90.0) + 1e-5 * x
    return Machine("long", "XYFZ", limits={"X": (0, 1200)}, components={"EXX": Table(x, plus, plus + 0.004, "linear")})


@pytest.mark.parametrize("comp_type", [0, 1])
def test_linuxcnc_round_trip_cancels_the_error(tmp_path, machine, comp_type):
    text, notes = export_table(machine, "X", "linuxcnc", comp_type=comp_type)
    assert notes == []  # the 17 measured points fit: nothing resampled
    path = tmp_path / "x.comp"
    path.write_text(text)
    comp = read_linuxcnc_comp(path, comp_type)
    err = axis_error(machine, "X")
    assert len(comp.nominal) == 17 and np.all(np.diff(comp.nominal) > 0)
    # Reading back gives the same error, within the file's resolution...
    assert np.max(np.abs(comp.forward - err.forward(comp.nominal))) <= 0.5e-6 + 1e-12
    assert np.max(np.abs(comp.reverse - err.reverse(comp.nominal))) <= 0.5e-6 + 1e-12
    # ... and LinuxCNC's trim cancels the modelled error in both directions.
    for d, curve in ((1, err.forward), (-1, err.reverse)):
        assert np.max(np.abs(curve(comp.nominal) + comp.correction(comp.nominal, d))) <= 0.5e-6 + 1e-12
    # Reversal is really there (hr5b has 3.7..4.5 um).
    assert np.all(comp.reverse - comp.forward > 3e-3)


def test_linuxcnc_type0_sign_is_where_the_axis_is(machine):
    text, _ = export_table(machine, "X", "linuxcnc", comp_type=0)
    nominal, forward, _ = (float(v) for v in text.splitlines()[2].split())
    assert forward == pytest.approx(nominal + axis_error(machine, "X").forward(np.array([nominal]))[0], abs=1e-6)


def test_linuxcnc_resamples_to_256_and_says_so(tmp_path):
    m = long_axis_machine()
    text, notes = export_table(m, "X", "linuxcnc")
    assert any("256" in n for n in notes)
    assert "# " in text and "256" in text.split("#", 1)[1]
    path = tmp_path / "x.comp"
    path.write_text(text)
    comp = read_linuxcnc_comp(path)
    assert len(comp.nominal) <= 256
    assert comp.nominal[0] == 0 and comp.nominal[-1] >= 1200
    spacing = np.diff(comp.nominal)
    assert np.allclose(spacing, spacing[0])


def test_linuxcnc_notes_come_after_the_data(machine):
    text, _ = export_table(machine, "X", "linuxcnc")
    lines = text.splitlines()
    first_comment = next(i for i, l in enumerate(lines) if l.startswith("#"))
    assert all(len(l.split()) == 3 for l in lines[:first_comment])
    assert all(l.startswith("#") for l in lines[first_comment:])


def test_reader_refuses_what_linuxcnc_would_misread(tmp_path):
    bad = tmp_path / "bad.comp"
    bad.write_text("# header\n0 0 0\n1 1 1\n")
    with pytest.raises(NcppError) as err:
        read_linuxcnc_comp(bad)
    assert err.value.where.line == 2
    bad.write_text("0 0 0\n2 2 2\n1 1 1\n")
    with pytest.raises(NcppError, match="increase") as err:
        read_linuxcnc_comp(bad)
    assert err.value.where.line == 3


def test_screwcomp_outlier_is_flagged():
    comp = read_linuxcnc_comp(SCREWCOMP)
    assert len(comp.nominal) == 11 and comp.resolution == pytest.approx(0.001)
    flagged = flag_outliers(comp)
    assert [(o.line, o.column) for o in flagged] == [(4, "forward")]
    assert flagged[0].nominal == -4 and flagged[0].error == pytest.approx(-0.2)
    assert abs(flagged[0].expected) < 0.005


def test_outlier_detector_is_quiet_on_a_smooth_table(tmp_path, machine):
    path = tmp_path / "x.comp"
    path.write_text(export_table(machine, "X", "linuxcnc")[0])
    assert flag_outliers(read_linuxcnc_comp(path)) == []


def test_fanuc_increments_rebuild_the_correction(machine):
    err = axis_error(machine, "X")
    text, _ = write_fanuc_pitch(err, reference=400.0, spacing=50.0)
    params, points = read_fanuc_pitch(text)
    ref, first, last, mag = params[3620], params[3621], params[3622], params[3623]
    assert 1 <= mag <= 100 and all(abs(v) <= 7 for v in points.values())
    interval = params[3624] * 0.001
    assert interval == pytest.approx(50.0)
    x = 400.0 + (np.arange(first, last + 1) - ref) * interval
    rebuilt = np.cumsum([points[n] for n in range(first, last + 1)]) * mag * 0.001
    rebuilt -= rebuilt[ref - first]
    wanted = -(err.forward(x) - err.forward(np.array([400.0]))[0])
    assert np.max(np.abs(rebuilt - wanted)) <= 0.5 * mag * 0.001 + 1e-12
    assert params[1851] == round(np.mean(err.reverse(x) - err.forward(x)) * 1000)
    # No nested parentheses: a FANUC comment ends at the first ')'.
    for line in text.splitlines():
        inside = line.split("(", 1)[1] if "(" in line else ""
        assert inside.count("(") == 0 and inside.count(")") <= 1


def test_fanuc_magnification_grows_for_a_steep_error():
    x = np.linspace(0, 1000, 11)
    m = Machine("steep", "XYFZ", limits={"X": (0, 1000)}, components={"EXX": Table(x, 2e-4 * x)})  # 200 um/m
    text, notes = write_fanuc_pitch(axis_error(m, "X"), spacing=100.0)
    params, points = read_fanuc_pitch(text)
    assert params[3623] >= 3  # 20 um per 100 mm interval needs x3 at least
    assert max(abs(v) for v in points.values()) <= 7
    assert notes == []


def test_sinumerik_tables(machine):
    text, _ = export_table(machine, "X", "sinumerik", spacing=50.0)
    var = read_sinumerik(text)
    err = axis_error(machine, "X")
    enc = var["$AA_ENC_COMP"]
    n = len(enc)
    step, lo, hi = (var[f"$AA_ENC_COMP_{k}"][("0", "AX1")] for k in ("STEP", "MIN", "MAX"))
    assert hi == pytest.approx(lo + step * (n - 1))
    x = lo + step * np.arange(n)
    values = np.array([enc[("0", str(i), "AX1")] for i in range(n)])
    assert np.max(np.abs(values - err.mean(x))) <= 0.5e-4 + 1e-12  # MSEC value = error (actual value correction)
    assert var["$AN_CEC_DIRECTION"][("0",)] == 1 and var["$AN_CEC_DIRECTION"][("1",)] == -1
    outputs = {var["$AN_CEC_OUTPUT_AXIS"][(str(t),)] for t in range(4)}
    assert outputs == {"AX1", "AX2", "AX3"}  # reversal on X, straightness EYX on Y, EZX on Z
    eyx = axis_error(machine, "X", "EYX")
    cec2 = np.array([var["$AN_CEC"][("2", str(i))] for i in range(n)])
    assert np.max(np.abs(cec2 + eyx.mean(x))) <= 0.5e-4 + 1e-12  # CEC adds -e to the output axis


def test_heidenhain_com(machine):
    text, notes = export_table(machine, "X", "heidenhain", spacing=2.0)  # 401 points wanted, 256 allowed
    assert any("256" in n for n in notes) and "256" in text.split("[END]")[1]
    header, rows = read_heidenhain_com(text)
    assert text.startswith("BEGIN ") and "[END]" in text
    assert header == ["NR", "AXISPOS", "X", "BACKLASH"]
    assert len(rows) <= 256 and rows[0, 1] == 0 and rows[-1, 1] >= 800
    assert np.array_equal(rows[:, 0], np.arange(len(rows)))
    err = axis_error(machine, "X")
    assert np.max(np.abs(rows[:, 2] - err.forward(rows[:, 1]))) <= 0.5e-5


def test_cli_writes_file_and_reports_resampling(tmp_path, capsys):
    out = tmp_path / "x.comp"
    assert main(["export-table", "--machine", str(HR5B), "--axis", "X", "--format", "linuxcnc", "--spacing", "1", "-o", str(out)]) == 0
    assert "256" in capsys.readouterr().err
    assert len(read_linuxcnc_comp(out).nominal) <= 256


def test_missing_component_is_a_clear_error(tmp_path, capsys):
    m = long_axis_machine()
    with pytest.raises(NcppError, match="no EYY"):
        export_table(m, "Y", "fanuc")
