"""`ncpp analyze`: tables, JSON under the standard symbols, plots, error messages."""

from __future__ import annotations

import json

import numpy as np
import pytest

from ncpp.cli import main
from ncpp.instruments.analysis import analyze
from ncpp.instruments.files import make_measurement, read_measurement

ISO230_2 = {"A", "A_up", "A_down", "E", "E_up", "E_down", "M", "B", "B_mean", "R", "R_up", "R_down"}
ISO230_4 = {"G", "G_cw", "G_ccw", "H", "F_max", "F_min"}


def test_json_for_one_laser_file(samples_dir, tmp_path, capsys):
    out = tmp_path / "laser.json"
    assert main(["analyze", str(samples_dir / "laser_X_position.csv"), "--json", str(out)]) == 0
    data = json.loads(out.read_text())
    assert ISO230_2 <= set(data) and data["instrument"] == "laser" and data["standard"] == "ISO 230-2"
    assert all(isinstance(data[k], float) for k in ISO230_2)
    text = capsys.readouterr().out
    assert "A↑" in text and "target_mm" in text and "ISO 230-2" in text


def test_json_for_several_files_is_a_list(samples_dir, tmp_path):
    out = tmp_path / "all.json"
    files = [
        samples_dir / "ballbar_XY_R150.csv",
        samples_dir / "comparator_X.csv",
        samples_dir / "level_X_roll.csv",
    ]
    assert main(["analyze", *map(str, files), "--json", str(out)]) == 0
    ballbar, comparator, level = json.loads(out.read_text())
    assert ISO230_4 <= set(ballbar)
    for key in (
        "squareness_um_per_m",
        "scale_mismatch_um_per_m",
        "servo_mismatch_ms",
        "backlash_X_um",
        "backlash_Y_um",
        "reversal_spike_X_um",
    ):
        assert key in ballbar
    assert ballbar["squareness_um_per_m"] == pytest.approx(40.0, abs=1.0)  # the sample was made with 40
    assert ballbar["backlash_X_um"] == pytest.approx(4.0, abs=0.3) and ballbar[
        "servo_mismatch_ms"
    ] == pytest.approx(0.5, abs=0.05)
    assert ISO230_2 <= set(comparator) and "straightness_um" in comparator
    assert level["range_um_per_m"] > 0


def test_unidirectional_ballbar_json_has_nulls(tmp_path):
    a = np.arange(0.0, 360.0, 5.0)
    m = make_measurement(
        "ballbar",
        {"radius_mm": 100},
        {"direction": ["CW"] * a.size, "angle_deg": a, "deviation_um": np.sin(np.radians(2 * a))},
    )
    path = tmp_path / "cw.csv"
    from ncpp.instruments.files import write_measurement

    write_measurement(m, path)
    assert main(["analyze", str(path), "--json", str(tmp_path / "o.json")]) == 0
    data = json.loads((tmp_path / "o.json").read_text())
    assert data["G_ccw"] is None and data["H"] is None and data["servo_mismatch_ms"] is None
    assert data["G"] == pytest.approx(2.0, abs=0.01)


def test_plot_writes_a_png_for_every_kind(samples_dir, tmp_path):
    out = tmp_path / "all.png"
    assert main(["analyze", *map(str, sorted(samples_dir.glob("*.csv"))), "--plot", str(out)]) == 0
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 50_000


def test_bad_file_prints_location_not_traceback(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text(
        "# instrument: ballbar\n# radius_mm: 150\ndirection,angle_deg,deviation_um\nCCW,0,0\nCCW,12,oops\n"
    )
    assert main(["analyze", str(bad)]) == 2
    assert f"{bad}:5:8:" in capsys.readouterr().err


def test_profiles_of_straightness_angle_and_level(samples_dir):
    straight = analyze(read_measurement(samples_dir / "laser_X_straightness_y.csv")).figures
    assert straight["straightness_um"] == pytest.approx(8.0, abs=0.6)  # made with an 8 µm bow
    assert straight["slope_um_per_m"] == pytest.approx(4.0, abs=0.5)
    pitch = analyze(read_measurement(samples_dir / "laser_X_pitch.csv")).figures
    assert pitch["range_urad"] == pytest.approx(12.0, abs=1.5)
    # Level pitch: a constant 10 µm/m slope over 500 mm is a straight tilted line, no straightness.
    x = np.linspace(0, 500, 11)
    level = analyze(
        make_measurement(
            "level", {"quantity": "pitch"}, {"position_mm": x, "inclination_um_per_m": np.full(11, 10.0)}
        )
    )
    assert level.figures["integrated_straightness_um"] == pytest.approx(0.0, abs=1e-9)
    assert level.profiles["height"].value[-1] == pytest.approx(5.0)  # 10 µm/m × 0.5 m


def test_polar_trace_is_closed_only_for_a_full_circle():
    from ncpp.instruments.plots import _closed_or_open

    full = np.arange(0.0, 360.0, 10.0)
    th, r = _closed_or_open(full, full)
    assert len(th) == len(full) + 1 and r[-1] == r[0]
    arc = np.r_[np.arange(340.0, 360.0, 10.0), np.arange(0.0, 181.0, 10.0)]
    th, r = _closed_or_open(arc, arc)
    assert len(th) == len(arc) and r[0] == 340.0 and r[-1] == 180.0
