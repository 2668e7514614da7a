"""Forward models: each instrument's reading against a hand-derived expectation."""

from __future__ import annotations

import numpy as np
import pytest

from ncpp.instruments.analysis import analyze
from ncpp.instruments.files import read_measurement, write_measurement
from ncpp.instruments.forward import (
    predict,
    predict_ballbar,
    predict_comparator,
    predict_cutting,
    predict_grid,
    predict_laser,
    predict_level,
    predict_like,
    reading_component,
)
from ncpp.machine import Machine, Polynomial, Table
from ncpp.machine.effects import Backlash, ServoMismatch

TARGETS = np.arange(0.0, 801.0, 50.0)
EXX = Table((0.0, 400.0, 800.0), (0.0, 0.006, -0.004), interpolation="smooth")  # mm
EBX = Polynomial((0.0, 2e-8))  # 20 µrad/m of travel: 16 µrad at 800 mm
EYX = Polynomial((0.0, 0.0, 1e-8))  # bow, mm


def plain(**components) -> Machine:
    return Machine(name="test", chain="XYFZ", components=components)


def test_laser_position_is_exx_at_zero_abbe_offset():
    m = plain(EXX=EXX, EBX=EBX)
    reading = predict_laser(m, "X", "position", TARGETS, fixed="Y=0 Z=0")
    expected = (EXX(reading["target_mm"]) - EXX(0.0)) * 1e3
    assert np.allclose(reading["deviation_um"], expected, atol=1e-4)


def test_laser_position_picks_up_pitch_times_offset():
    m = plain(EXX=EXX, EBX=EBX)
    at_tool = predict_laser(m, "X", "position", TARGETS, fixed="Y=0 Z=0")
    raised = predict_laser(m, "X", "position", TARGETS, fixed="Y=0 Z=0", offset_mm=(0, 0, 120))
    # ε = (0, EBX, 0) × lever (0, 0, 120 mm) = +120·EBX along X (eqs. 31–34)
    abbe = 120.0 * EBX(raised["target_mm"]) * 1e3
    assert np.allclose(raised["deviation_um"] - at_tool["deviation_um"], abbe, atol=1e-4)
    assert np.max(np.abs(abbe)) > 1.5  # the test means something: 1.9 µm at 800 mm


def test_laser_angles_and_straightness_read_their_components():
    m = plain(EBX=EBX, EYX=EYX)
    pitch = predict_laser(m, "X", "pitch", TARGETS)
    assert pitch.meta["component"] == "EBX" and "deviation_urad" in pitch.columns
    assert np.allclose(pitch["deviation_urad"], EBX(pitch["target_mm"]) * 1e6, atol=1e-4)
    straight = predict_laser(m, "X", "straightness_y", TARGETS)
    assert np.allclose(straight["deviation_um"], EYX(straight["target_mm"]) * 1e3, atol=1e-4)
    assert reading_component("Y", "yaw") == "ECY" and reading_component("Z", "straightness_x") == "EXZ"


def test_laser_cycle_layout_and_backlash():
    m = plain(EXX=EXX).replace(effects=(Backlash("X", 4.0),))
    reading = predict_laser(m, "X", "position", TARGETS, runs=3)
    assert len(reading) == 3 * 2 * len(TARGETS)
    assert set(reading["direction"]) == {"+", "-"} and reading["run"].max() == 3
    figures = analyze(reading).figures
    assert figures["B"] == pytest.approx(4.0, abs=1e-3)
    assert figures["B_mean"] == pytest.approx(-4.0, abs=1e-3)  # lagging behind in both directions
    assert figures["R_up"] == pytest.approx(0.0, abs=1e-3)


def test_comparator_linear_is_laser_position_at_the_same_offset():
    m = plain(EXX=EXX, EBX=EBX, EYX=EYX, ECX=Polynomial((0.0, -1e-8)))
    setup = dict(fixed="Y=100 Z=50", offset_mm=(10, 20, 80), runs=2)
    comp = predict_comparator(m, "X", "Y", TARGETS, **setup)
    laser = predict_laser(m, "X", "position", TARGETS, **setup)
    straight = predict_laser(m, "X", "straightness_y", TARGETS, **setup)
    assert np.array_equal(comp["linear_um"], laser["deviation_um"])
    assert np.array_equal(comp["transverse_um"], straight["deviation_um"])


def test_level_reads_the_member_rotation():
    EAX, EAZ = Polynomial((0.0, 1e-8)), Polynomial((0.0, -3e-8))
    m = plain(EAX=EAX, EAZ=EAZ)
    # X rides on the workpiece side of XYFZ: its carriage turns by −EAX.
    roll = predict_level(m, "X", TARGETS, quantity="roll")
    assert np.allclose(roll["inclination_um_per_m"], -EAX(TARGETS) * 1e6, atol=1e-4)
    # Z carries the tool: its carriage turns by +EAZ (pitch of Z).
    pitch = predict_level(m, "Z", TARGETS, quantity="pitch")
    assert np.allclose(pitch["inclination_um_per_m"], EAZ(TARGETS) * 1e6, atol=1e-4)
    assert np.allclose(
        pitch["inclination_um_per_m"],
        m.member_rotation("Z", np.c_[0 * TARGETS, 0 * TARGETS, TARGETS])[:, 0] * 1e6,
        atol=1e-4,
    )


def test_ballbar_of_a_pure_squareness_machine():
    s, R = 40e-6, 150.0
    m = plain().with_components(C0Y=s)
    bb = predict_ballbar(m, "XY", R, (300, 200, 100), step_deg=5.0)
    theta = np.radians(bb["angle_deg"])
    # C0Y > 0: Y motion carries δx = −C0Y·y, so ΔR = −(C0Y·R/2)·sin 2θ
    assert np.allclose(bb["deviation_um"], -(s * R * 1e3 / 2) * np.sin(2 * theta), atol=1e-4)
    assert analyze(bb).figures["squareness_um_per_m"] == pytest.approx(-40.0, abs=0.01)


def test_ballbar_cw_ccw_differ_only_with_direction_dependent_effects():
    static = plain(EXX=EXX, EBX=EBX, EYX=EYX)
    centre = (400, 0, 0)
    bb = predict_ballbar(static, "XY", 100, centre, step_deg=2.0)
    ccw, cw = (bb["direction"] == d for d in ("CCW", "CW"))
    by_angle = lambda rows: bb["deviation_um"][rows][np.argsort(bb["angle_deg"][rows])]  # noqa: E731
    assert np.allclose(by_angle(ccw), by_angle(cw), atol=1e-9)
    for machine in (
        static.replace(effects=(Backlash("Y", 5.0),)),
        static.replace(effects=(ServoMismatch("XY", 1.0),)),
        static.with_components(EXX=Table(EXX.positions, EXX.values, np.add(EXX.values, 0.003))),
    ):
        bb = predict_ballbar(machine, "XY", 100, centre, step_deg=2.0)
        assert np.max(np.abs(by_angle(bb["direction"] == "CCW") - by_angle(bb["direction"] == "CW"))) > 1.0


def test_ballbar_servo_mismatch_is_recovered_by_the_diagnosis():
    m = plain().replace(effects=(ServoMismatch("XY", 0.8),))
    figures = analyze(predict_ballbar(m, "XY", 150, (0, 0, 0), feed_mm_min=2000)).figures
    assert figures["servo_mismatch_ms"] == pytest.approx(0.8, rel=0.05)


def test_ballbar_planes_and_offset():
    m = plain(EBX=EBX, EXX=EXX)
    for plane in ("XY", "YZ", "ZX"):
        bb = predict_ballbar(m, plane, 100, (400, 0, 0), step_deg=10.0, directions="CCW")
        assert bb.meta["plane"] == plane and len(bb) == 36
    flat = predict_ballbar(m, "XY", 100, (400, 0, 0), step_deg=10.0)
    tall = predict_ballbar(m, "XY", 100, (400, 0, 0), step_deg=10.0, offset_mm=(0, 0, 300))
    assert not np.allclose(flat["deviation_um"], tall["deviation_um"], atol=0.1)  # pitch × 300 mm


def test_cutting_circularity_matches_ballbar_g():
    m = plain(EXX=EXX, EYX=EYX).with_components(C0Y=30e-6).replace(effects=(Backlash("X", 3.0),))
    centre = (400, 0, 0)
    cut = analyze(predict_cutting(m, "XY", 50, centre, feed_mm_min=1000, direction="CCW")).figures
    bar = analyze(
        predict_ballbar(m, "XY", 50, centre, feed_mm_min=1000, directions="CCW", step_deg=0.5)
    ).figures
    assert cut["G"] == pytest.approx(bar["G"], rel=0.1)


def test_grid_square_and_circle():
    s = 25e-6
    m = plain().with_components(C0Y=s)
    square = predict_grid(m, "XY", "square", (300, 200, 0), 50.0, step_mm=10.0)
    assert "direction" not in square.columns and square.meta["side_mm"] == "100"
    assert np.allclose(square["dev_x_um"], -s * (square["y_mm"] - 200) * 1e3, atol=1e-4)
    circle = predict_grid(m, "XY", "circle", (300, 200, 0), 100.0, step_deg=1.0)
    bar = predict_ballbar(m, "XY", 100, (300, 200, 0), step_deg=1.0, directions="CCW")
    assert analyze(circle).figures["G"] == pytest.approx(analyze(bar).figures["G"], abs=1e-3)


def test_noise_is_seeded():
    m = plain(EXX=EXX)
    a = predict_laser(m, "X", "position", TARGETS, runs=5, noise_um=0.5, seed=3)
    b = predict_laser(m, "X", "position", TARGETS, runs=5, noise_um=0.5, seed=3)
    c = predict_laser(m, "X", "position", TARGETS, runs=5, noise_um=0.5, seed=4)
    clean = predict_laser(m, "X", "position", TARGETS, runs=5)
    assert a == b and a != c
    assert np.std(a["deviation_um"] - clean["deviation_um"]) == pytest.approx(0.5, rel=0.2)


@pytest.mark.parametrize(
    "instrument, setup",
    [
        ("laser", dict(axis="Y", quantity="yaw", targets=TARGETS, runs=2)),
        ("comparator", dict(axis="X", targets=TARGETS)),
        ("level", dict(axis="X", positions=TARGETS)),
        ("ballbar", dict(radius_mm=100, center_mm=(400, 0, 0), step_deg=3.0)),
        ("grid", dict(center_mm=(400, 0, 0), radius_mm=80)),
        ("cutting", dict(center_mm=(400, 0, 0), radius_mm=40)),
    ],
)
def test_files_round_trip_and_predict_like(tmp_path, instrument, setup):
    m = plain(EXX=EXX, EBX=EBX, EYX=EYX, ECY=Polynomial((0.0, 1e-8)), EAX=EBX).with_components(C0Y=1e-5)
    path = tmp_path / f"{instrument}.csv"
    predicted = predict(m, instrument, **setup)
    write_measurement(predicted, path)
    back = read_measurement(path)
    assert back == predicted
    analyze(back)  # evaluable as it is
    again = predict_like(m, back)
    for column, values in predicted.columns.items():
        if values.dtype.kind == "f":
            assert np.allclose(again[column], values, atol=0.02), column
