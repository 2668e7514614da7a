"""Controller compensation tables: formats, limits, signs, read-back."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from ncpp.cli import main
from ncpp.errors import NcppError
from ncpp.export import axis_error, export_table
from ncpp.export.fanuc import read_fanuc_pitch, write_fanuc_pitch
from ncpp.export.heidenhain import read_heidenhain_com
from ncpp.export.linuxcnc import flag_outliers, read_linuxcnc_comp
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
    return Machine(
        "long", "XYFZ", limits={"X": (0, 1200)}, components={"EXX": Table(x, plus, plus + 0.004, "linear")}
    )


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
    assert forward == pytest.approx(
        nominal + axis_error(machine, "X").forward(np.array([nominal]))[0], abs=1e-6
    )


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
    first_comment = next(i for i, line in enumerate(lines) if line.startswith("#"))
    assert all(len(line.split()) == 3 for line in lines[:first_comment])
    assert all(line.startswith("#") for line in lines[first_comment:])


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


# Sources for the three formats below (full list in each writer's docstring):
FANUC_0I_PB = "FANUC 0i-PB parameter manual B-63980EN/01 p.100, http://cncmanuals.com/fanuc/217/series-0i-pb-parameter-manual/page/108"
FANUC_A77810E = "FANUC technical report A-77810E, 16i/18i bidirectional pitch error compensation (parameter list 3620-3627)"
K3_EXAMPLE = "SINUMERIK K3 6FC5397-1BP40-3BA1 p.242, https://manual.onestart.ai/manuals/Siemens-SINUMERIK-Series-Function-Manual-5628364?page=242"
K3_CEC = "SINUMERIK K3 6FC5397-1BP40-3BA1 p.248-249, https://www.easymanua.ls/siemens/sinumerik-series/manual/275710?p=248"
K3_802D_CEC = (
    "SINUMERIK 802D sl K3 example, https://www.easymanua.ls/siemens/sinumerik-802d-sl/manual/592298?p=222"
)
S808D_SIGN = "SINUMERIK 808D Function Manual 01/2017 p.106, https://www.easymanua.ls/siemens/sinumerik-808d/manual/217421?p=106"
HH_COM = "HEIDENHAIN MANUALplus 620 Technical Manual p.716, https://www.easymanua.ls/heidenhain/manualplus-620/manual/506189?p=716"
HH_TNC407 = "HEIDENHAIN TNC 407 Technical Manual, module 9095, https://azmanual.top/manuals/797826/heidenhain-tnc-407-243-020-technical-manual.html?page=622"
HH_LAYOUT = "drunsinn/pyLSV2 pyLSV2/table_reader.py and tests/test_files/palletmag.tab"


def fanuc_correction(params: dict[int, int], points: dict[int, int], reference: float, du: float = 0.001):
    """Where each section ends (mm) and the correction there relative to the reference, mm,
    read the way FANUC describes it: each number's value is output in its section."""
    ref, first, last, mag, interval = (params[n] for n in (3620, 3621, 3622, 3623, 3624))
    numbers = np.arange(first - 1, last + 1)  # first - 1: where the first section starts
    ends = reference + (numbers - ref) * interval * du
    total = np.concatenate([[0], np.cumsum([points[n] for n in range(first, last + 1)])]) * mag * du
    at_ref = np.interp(reference, ends, total)
    return ends, total - at_ref


def test_fanuc_increments_rebuild_the_correction(machine):
    err = axis_error(machine, "X")
    text, _ = write_fanuc_pitch(err, reference=400.0, spacing=50.0)
    params, points = read_fanuc_pitch(text)
    # 3620..3624 are the reference, most negative, most positive point, magnification, interval.
    # Source: FANUC_A77810E (table (a), data numbers 3620-3624).
    assert params[3623] >= 1 and params[3624] * 0.001 == pytest.approx(50.0)
    # One number per 50 mm section: 0..400 mm is 8 sections below the reference (numbers 3621..3620),
    # 400..800 mm 8 above (3620+1..3622); no number is spent below the table start.
    # Source: FANUC_0I_PB ("output at the compensation position No. corresponding to each section").
    assert params[3620] - params[3621] + 1 == 8 and params[3622] - params[3620] == 8
    assert sorted(points) == list(range(params[3621], params[3622] + 1))
    # Values are small signed integer increments whose running sum is the compensation amount.
    # Source: FANUC_0I_PB (example values +2 +1 +1 -2 0 -1 ... and their "absolute value" curve).
    # The +-7 limit and the sign (value = correction to add, -e) are NOT verified: from memory.
    assert all(isinstance(v, int) and abs(v) <= 7 for v in points.values())
    ends, correction = fanuc_correction(params, points, 400.0)
    assert ends[0] == pytest.approx(0.0) and ends[-1] == pytest.approx(800.0)
    wanted = -(err.forward(ends) - err.forward(np.array([400.0]))[0])
    assert np.max(np.abs(correction - wanted)) <= 0.5 * params[3623] * 0.001 + 1e-12
    assert params[1851] == round(np.mean(err.reverse(ends) - err.forward(ends)) * 1000)  # 1851: unverified
    # No nested parentheses: a FANUC comment ends at the first ')'.
    for line in text.splitlines():
        inside = line.split("(", 1)[1] if "(" in line else ""
        assert inside.count("(") == 0 and inside.count(")") <= 1


def test_fanuc_reference_at_the_table_start_needs_no_section_below_it(machine):
    text, _ = write_fanuc_pitch(axis_error(machine, "X"), reference=0.0, spacing=100.0)
    params, points = read_fanuc_pitch(text)
    # Reference at the negative end: the first section starts there, so 3621 = 3620 + 1.
    # Source: FANUC_0I_PB (one number per section); the +1 rule itself is from memory.
    assert (params[3620], params[3621], params[3622]) == (0, 1, 8)
    assert len(points) == 8


def test_fanuc_magnification_grows_for_a_steep_error():
    x = np.linspace(0, 1000, 11)
    m = Machine("steep", "XYFZ", limits={"X": (0, 1000)}, components={"EXX": Table(x, 2e-4 * x)})  # 200 um/m
    text, notes = write_fanuc_pitch(axis_error(m, "X"), spacing=100.0)
    params, points = read_fanuc_pitch(text)
    # 3623 multiplies every value. Source: FANUC_A77810E ("pitch error compensation magnification").
    assert params[3623] >= 3  # 20 um per 100 mm interval needs x3 at least (with the unverified +-7 limit)
    assert max(abs(v) for v in points.values()) <= 7
    ends, correction = fanuc_correction(params, points, 0.0)
    assert np.max(np.abs(correction + 2e-4 * ends)) <= 0.5 * params[3623] * 0.001 + 1e-12
    assert notes == []


def test_sinumerik_tables(machine):
    text, _ = export_table(machine, "X", "sinumerik", spacing=50.0)
    lines = text.splitlines()
    # Framing of the leadscrew table. Source: K3_EXAMPLE (%_N_AX_EEC_INI, CHANDATA(1), ..., M17).
    assert lines[:2] == ["%_N_AX_EEC_INI", "CHANDATA(1)"]
    enc_end = lines.index("M17")
    assert lines[enc_end + 1 : enc_end + 3] == ["%_N_NC_CEC_INI", "CHANDATA(1)"]  # Source: K3_802D_CEC
    assert lines[-1] == "M17"
    var = read_sinumerik(text)
    err = axis_error(machine, "X")
    enc = var["$AA_ENC_COMP"]
    n = len(enc)
    # $AA_ENC_COMP[0,N,axis] for N = 0..n-1, with _STEP, _MIN, _MAX, _IS_MODULO[0,axis], in mm.
    # Source: K3_EXAMPLE ($AA_ENC_COMP[0,0,X1]=0.003 ; +3 um; _STEP=1.0 ; 1.0 mm; _MIN=-200.0; _MAX=600.0).
    assert set(enc) == {("0", str(i), "AX1") for i in range(n)}
    step, lo, hi = (var[f"$AA_ENC_COMP_{k}"][("0", "AX1")] for k in ("STEP", "MIN", "MAX"))
    assert var["$AA_ENC_COMP_IS_MODULO"][("0", "AX1")] == 0
    assert hi == pytest.approx(lo + step * (n - 1))
    x = lo + step * np.arange(n)
    values = np.array([enc[("0", str(i), "AX1")] for i in range(n)])
    # MSEC value = the error: "A positive compensation value causes the machine axis to move in the
    # negative direction". Source: S808D_SIGN.
    assert np.max(np.abs(values - err.mean(x))) <= 0.5e-4 + 1e-12
    # Two direction-dependent tables for position-dependent backlash: _DIRECTION 1 and -1.
    # Source: K3_CEC ($AN_CEC_DIRECTION; "using two tables").
    assert var["$AN_CEC_DIRECTION"][("0",)] == 1 and var["$AN_CEC_DIRECTION"][("1",)] == -1
    # Axes given as (AXn). Source: K3_802D_CEC ($AN_CEC_INPUT_AXIS[0]=(AX2)).
    outputs = {var["$AN_CEC_OUTPUT_AXIS"][(str(t),)] for t in range(4)}
    assert outputs == {"AX1", "AX2", "AX3"}  # reversal on X, straightness EYX on Y, EZX on Z
    assert (
        var["$AN_CEC_MULT_BY_TABLE"][("2",)] == 0 and var["$AN_CEC_IS_MODULO"][("2",)] == 0
    )  # Source: K3_CEC
    eyx = axis_error(machine, "X", "EYX")
    cec2 = np.array([var["$AN_CEC"][("2", str(i))] for i in range(n)])
    # CEC adds -e to the output axis: NOT verified (no source states the CEC sign).
    assert np.max(np.abs(cec2 + eyx.mean(x))) <= 0.5e-4 + 1e-12


def test_sinumerik_reference_shift_makes_the_reference_value_zero(machine):
    text, _ = export_table(machine, "X", "sinumerik", spacing=50.0, reference=400.0)
    var = read_sinumerik(text)
    # "The compensation value at the reference point should be zero". Source: S808D_SIGN.
    assert var["$AA_ENC_COMP"][("0", "8", "AX1")] == 0.0  # 400 mm = point 8 at 50 mm spacing


def test_heidenhain_com(machine):
    text, notes = export_table(machine, "X", "heidenhain", spacing=2.0)  # 401 points wanted, 256 allowed
    # At most 256 entries per .COM table. Source: HH_TNC407 (error 3 of module 9095); newer controls unverified.
    assert any("256" in n for n in notes) and "256" in text.split("[END]")[1]
    lines = text.splitlines()
    # BEGIN <NAME>.COM MM first, [END] last of the table. Source: HH_LAYOUT.
    assert re.fullmatch(r"BEGIN [A-Z_0-9]+\.COM MM", lines[0]) and "[END]" in lines
    # Columns AXISPOS, the axis's own name, BACKLASH. Source: HH_COM. (NR: HH_LAYOUT's tables number
    # their rows; that .COM has one is NOT verified.)
    header, rows = read_heidenhain_com(text)
    assert header == ["NR", "AXISPOS", "X", "BACKLASH"]
    # Fixed-width columns: every value starts where its column name starts. Source: HH_LAYOUT.
    starts = [m.start() for m in re.finditer(r"\S+", lines[1])]
    for line in lines[2 : lines.index("[END]")]:
        assert all(line[s] != " " and (s == 0 or line[s - 1] == " ") for s in starts)
    assert len(rows) <= 256 and rows[0, 1] == 0 and rows[-1, 1] >= 800
    assert np.array_equal(rows[:, 0], np.arange(len(rows)))
    err = axis_error(machine, "X")
    # Values in mm (the MM of the BEGIN line); the axis column holds e (+), BACKLASH the values
    # "measured in the negative direction of traverse". Source: HH_COM. Sign NOT verified.
    assert np.max(np.abs(rows[:, 2] - err.forward(rows[:, 1]))) <= 0.5e-5
    assert np.max(np.abs(rows[:, 3] - err.reverse(rows[:, 1]))) <= 0.5e-5


def test_cli_writes_file_and_reports_resampling(tmp_path, capsys):
    out = tmp_path / "x.comp"
    assert (
        main(
            [
                "export-table",
                "--machine",
                str(HR5B),
                "--axis",
                "X",
                "--format",
                "linuxcnc",
                "--spacing",
                "1",
                "-o",
                str(out),
            ]
        )
        == 0
    )
    assert "256" in capsys.readouterr().err
    assert len(read_linuxcnc_comp(out).nominal) <= 256


def test_missing_component_is_a_clear_error(tmp_path, capsys):
    m = long_axis_machine()
    with pytest.raises(NcppError, match="no EYY"):
        export_table(m, "Y", "fanuc")


# One positioning error of X, 20 µm/m from X0, written three ways in a machine file: as the EXX
# table, as a `scale` effect beside a zero EXX, and as the effect alone (machine-file.md, [[effects]]).
SCALE_WAYS = {
    "table": 'chain = "XYFZ"\n[errors.EXX]\nkind = "table"\npositions = [0.0, 250.0, 500.0]\n'
             "values_um = [0.0, 5.0, 10.0]\n",
    "effect": 'effects = [{ kind = "scale", axis = "X", um_per_m = 20.0 }]\n[machine]\nchain = "XYFZ"\n'
              '[errors.EXX]\nkind = "table"\npositions = [0.0, 250.0, 500.0]\nvalues_um = [0.0, 0.0, 0.0]\n',
    "effect alone": 'effects = [{ kind = "scale", axis = "X", um_per_m = 20.0 }]\n'
                    '[machine]\nchain = "XYFZ"\n',
}  # fmt: skip


@pytest.mark.parametrize("fmt", ["linuxcnc", "fanuc", "sinumerik", "heidenhain"])
def test_a_scale_effect_is_exported_as_the_same_error_in_a_table_is(tmp_path, fmt):
    tables = {}
    for way, text in SCALE_WAYS.items():
        path = tmp_path / f"{way}.toml"
        body = text if way != "table" else "[machine]\n" + text
        path.write_text(body.replace("[machine]", '[machine]\nname = "m"') + "[limits]\nX = [0.0, 500.0]\n")
        machine = load_machine(path)
        err = axis_error(machine, "X")
        x = np.linspace(0.0, 500.0, 11)
        assert np.allclose(err.forward(x), 20e-6 * x, atol=1e-12)  # (closed form: 20 µm/m)
        assert np.allclose(err.forward(x), machine.static_deviation(np.c_[x, 0 * x, 0 * x])[:, 0])
        text_out, _ = export_table(machine, "X", fmt, spacing=50.0)
        tables[way] = [
            line for line in text_out.splitlines() if not re.search(r"EXX|effect|ncpp", line, re.I)
        ]
    assert tables["effect"] == tables["table"] == tables["effect alone"]


def test_a_cyclic_effect_adds_to_exx_and_backlash_does_not(tmp_path):
    path = tmp_path / "m.toml"
    path.write_text('effects = [{ kind = "cyclic", axis = "X", um = 2.0, period_mm = 100.0 },\n'
                    '           { kind = "backlash", axis = "X", um = 8.0 }]\n'
                    '[machine]\nname = "m"\nchain = "XYFZ"\n[limits]\nX = [0.0, 500.0]\n'
                    '[errors.EXX]\nkind = "table"\npositions = [0.0, 500.0]\n'
                    'values_um = [0.0, 10.0]\n')  # fmt: skip
    err = axis_error(load_machine(path), "X")
    x = np.array([0.0, 25.0, 75.0, 250.0])
    assert np.allclose(err.forward(x), 20e-6 * x + 2e-3 * np.sin(2 * np.pi * x / 100.0), atol=1e-12)
    assert np.allclose(err.reverse(x), err.forward(x))  # (backlash is the control's own parameter)
    assert err.name == "EXX + cyclic effect"
