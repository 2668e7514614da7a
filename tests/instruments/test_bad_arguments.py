"""Bad options and bad measurement files: a message naming the option or the file, exit 2,
no traceback and no file with NaN in it (analyze, predict, fit, diagnose, export-table)."""

from __future__ import annotations

from pathlib import Path

import pytest

from ncpp.cli import main

ROOT = Path(__file__).resolve().parents[2]
MACHINE = str(ROOT / "samples/machines/hr5b.toml")
SAMPLES = ROOT / "samples/measurements"
LASER = str(SAMPLES / "laser_X_position.csv")
BALLBAR = str(SAMPLES / "ballbar_XY_R150.csv")


def refused(argv: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run `ncpp argv`; assert it exits 2 without a traceback and return stderr."""
    try:
        code = main(argv)
    except SystemExit as exit:  # argparse's option errors
        code = exit.code
    err = capsys.readouterr().err
    assert code == 2, err
    assert "Traceback" not in err
    return err


def first_rows(tmp_path: Path, sample: str, rows: int) -> str:
    """The sample file cut to its metadata, header and `rows` readings."""
    lines = (SAMPLES / sample).read_text().splitlines()
    header = next(i for i, line in enumerate(lines) if not line.startswith("#"))
    path = tmp_path / f"{rows}_{sample}"
    path.write_text("\n".join(lines[: header + 1 + rows]) + "\n")
    return str(path)


# -- analyze -------------------------------------------------------------------------------
@pytest.mark.parametrize("sample", ["level_X_roll.csv", "laser_X_pitch.csv"])
def test_analyze_profile_of_one_target(sample, tmp_path, capsys):
    path = first_rows(tmp_path, sample, 1)
    err = refused(["analyze", path], capsys)
    assert f"{path}:1:1: " in err and "needs at least two" in err


@pytest.mark.parametrize("width", ["0", "nan", "-3", "1e9"])
def test_analyze_spike_width(width, capsys):
    assert "--spike-width" in refused(["analyze", "--spike-width", width, BALLBAR], capsys)


# -- huge or unmatched targets ----------------------------------------------------------------
def test_target_beyond_what_a_number_resolves(tmp_path, capsys):
    text = Path(LASER).read_text().replace("\n300,", "\n1e17,")
    path = tmp_path / "far.csv"
    path.write_text(text)
    line = text.splitlines().index(next(r for r in text.splitlines() if r.startswith("1e17,"))) + 1
    for command in (["analyze", str(path)], ["diagnose", "--machine", MACHINE, str(path)]):
        assert f"{path}:{line}:1: target_mm: 1e17 is out of range" in refused(command, capsys)


def test_diagnose_matches_targets_numpy_rounds_otherwise(tmp_path, capsys):
    # round(np.float64(100.0000015), 6) != round(100.0000015, 6): the readings were not found
    path = tmp_path / "near.csv"
    path.write_text(Path(LASER).read_text().replace("\n100,", "\n100.0000015,"))
    assert main(["diagnose", "--machine", MACHINE, str(path)]) == 0
    assert "Traceback" not in capsys.readouterr().err


def test_angle_past_half_a_turn(tmp_path, capsys):
    path = tmp_path / "level.csv"
    path.write_text((SAMPLES / "level_X_roll.csv").read_text().replace("\n150,0.13", "\n150,1e300"))
    err = refused(["fit", str(path), "-o", str(tmp_path / "m.toml")], capsys)
    assert f"{path}:12:5: inclination_um_per_m: 1e300 is out of range" in err


# -- predict -------------------------------------------------------------------------------
BALLBAR_SETUP = ["predict", "--machine", MACHINE, "--instrument", "ballbar"]
LASER_SETUP = ["predict", "--machine", MACHINE, "--instrument", "laser", "--axis", "X"]


@pytest.mark.parametrize(
    "args, option",
    [
        (["--step", "1000"], "--step"),
        (["--step", "0"], "--step"),
        (["--radius", "0"], "--radius"),
        (["--radius", "1e308"], "--radius"),
        (["--center", "1e9,0,0"], "--center must be finite numbers within"),
        (["--feed", "0"], "--feed"),
        (["--center", "nan,350,350"], "--center"),
        (["--start", "nan"], "--start"),
        (["--overshoot", "-45"], "--overshoot"),
        (["--noise", "nan"], "--noise"),
    ],
)  # fmt: skip
def test_predict_ballbar_options(args, option, tmp_path, capsys):
    out = tmp_path / "bb.csv"
    assert option in refused([*BALLBAR_SETUP, *args, "-o", str(out)], capsys)
    assert not out.exists()


@pytest.mark.parametrize(
    "args, expected",
    [
        (["--targets", "0:1e6:0.001"], "--targets 0:1e6:0.001: 1,000,000,001 targets"),
        (["--targets", "0,1e308"], "within ±1e+06 mm"),
        (["--fixed", "Y=nan"], "--fixed: fixed positions must be finite numbers within ±1e+06 mm, got [nan]"),
        (["--fixed", "Y=1e7"], "--fixed: fixed positions must be finite numbers"),
        (["--offset", "1e308,0,0"], "--offset must be finite numbers within ±1e+06 mm"),
        (["--targets", "nan,1,2"], "--targets"),
        (["--targets", "0:1:0.0001"], "closer than 1 µm"),
        (["--runs", "0"], "--runs"),
        (["--quantity", "pitch", "--component", "EQQ"], "EAX, EBX, ECX"),
    ],
)  # fmt: skip
def test_predict_laser_options(args, expected, tmp_path, capsys):
    assert expected in refused([*LASER_SETUP, *args, "-o", str(tmp_path / "x.csv")], capsys)


def test_predict_from_files_with_a_bad_chain(tmp_path, capsys):
    argv = [
        "predict",
        "--from",
        LASER,
        "--chain",
        "QQQ",
        "--instrument",
        "ballbar",
        "-o",
        str(tmp_path / "bb.csv"),
    ]
    assert "ncpp predict: chain 'QQQ'" in refused(argv, capsys)


# -- fit and diagnose ------------------------------------------------------------------------
@pytest.mark.parametrize(
    "args, option", [(["--knots", "5000"], "--knots 5000"), (["--smoothing", "-1"], "--smoothing")]
)
def test_fit_ballbar_options(args, option, tmp_path, capsys):
    out = tmp_path / "m.toml"
    assert option in refused(["fit", BALLBAR, "--base", MACHINE, *args, "-o", str(out)], capsys)
    assert not out.exists()


def test_fit_says_a_given_smoothing_is_given(tmp_path, capsys):
    assert main(["fit", BALLBAR, "--base", MACHINE, "--smoothing", "1", "-o", str(tmp_path / "m.toml")]) == 0
    assert "λ = 1 (given)" in capsys.readouterr().out


def test_fit_refuses_a_smoothing_that_diverges(tmp_path, capsys):
    err = refused(
        ["fit", BALLBAR, "--base", MACHINE, "--smoothing", "1e-12", "-o", str(tmp_path / "m.toml")], capsys
    )
    assert "diverged" in err and "--smoothing" in err


@pytest.mark.parametrize("rows", [1, 2])
def test_ballbar_of_too_few_points(rows, tmp_path, capsys):
    path = first_rows(tmp_path, "ballbar_XY_R150.csv", rows)
    for command in (["fit", path, "-o", str(tmp_path / "m.toml")], ["diagnose", "--machine", MACHINE, path]):
        assert f"{path}:1:1: a circular test needs at least three points per direction" in refused(
            command, capsys
        )


def test_fit_table_of_one_target(tmp_path, capsys):
    path = first_rows(tmp_path, "laser_X_position.csv", 1)
    assert f"{path}:1:1: a table needs readings at two or more targets" in refused(
        ["fit", path, "-o", str(tmp_path / "m.toml")], capsys
    )


def test_diagnose_a_circle_of_less_than_a_micron(tmp_path, capsys):
    """A grid encoder reads circles of a micron: the straightness candidates had an extent of lo == hi
    (rounded to 1 µm) and ended in a ValueError."""
    path = tmp_path / "tiny.csv"
    path.write_text(Path(BALLBAR).read_text().replace("# radius_mm: 150", "# radius_mm: 0.0001"))
    assert main(["diagnose", "--machine", MACHINE, str(path)]) == 0
    assert "Traceback" not in capsys.readouterr().err


def test_diagnose_alpha(capsys):
    assert "argument --alpha" in refused(["diagnose", "--machine", MACHINE, "--alpha", "1", BALLBAR], capsys)


# -- export-table ----------------------------------------------------------------------------
@pytest.mark.parametrize("fmt", ["linuxcnc", "fanuc", "sinumerik", "heidenhain"])
@pytest.mark.parametrize(
    "args, option",
    [
        (["--spacing", "nan"], "--spacing"),
        (["--spacing", "0"], "--spacing"),
        (["--reference", "nan"], "--reference"),
    ],
)
def test_export_options(fmt, args, option, tmp_path, capsys):
    out = tmp_path / "table"
    argv = ["export-table", "--machine", MACHINE, "--axis", "X", "--format", fmt, *args, "-o", str(out)]
    assert f"argument {option}" in refused(argv, capsys)
    assert not out.exists()


def test_export_fanuc_with_the_finest_spacing_fits_its_point_numbers(tmp_path, capsys):
    argv = ["export-table", "--machine", MACHINE, "--axis", "X", "--format", "fanuc", "--spacing", "1e-6"]
    assert main([*argv, "-o", str(tmp_path / "x.tape")]) == 0
    assert "widened" in capsys.readouterr().err


def test_export_error_beyond_the_machines_correction_limit(tmp_path, capsys):
    text = Path(MACHINE).read_text().replace("max_correction_mm = 0.5", "max_correction_mm = 0.001")
    machine = tmp_path / "m.toml"
    machine.write_text(text)
    err = refused(["export-table", "--machine", str(machine), "--axis", "X", "--format", "linuxcnc"], capsys)
    assert f"{machine}: EXX reaches" in err and "max_correction_mm" in err


@pytest.mark.parametrize("fmt", ["linuxcnc", "fanuc", "sinumerik", "heidenhain"])
def test_export_spacing_longer_than_the_travel(fmt, capsys):
    """--spacing 1e308 was an OverflowError in the FANUC writer."""
    err = refused(
        ["export-table", "--machine", MACHINE, "--axis", "X", "--format", fmt, "--spacing", "1e308"], capsys
    )
    assert "--spacing 1e+308 mm is longer than the X travel, 0 to 800 mm" in err


@pytest.mark.parametrize("fmt", ["fanuc", "sinumerik"])
def test_export_reference_outside_the_travel_is_moved_onto_it_with_a_note(fmt, tmp_path, capsys):
    out = tmp_path / "table"
    assert (
        main(
            [
                "export-table",
                "--machine",
                MACHINE,
                "--axis",
                "X",
                "--format",
                fmt,
                "--reference",
                "1e308",
                "-o",
                str(out),
            ]
        )
        == 0
    )
    assert "reference position 1e+308 mm lies outside the table range; 800 mm used" in capsys.readouterr().err
