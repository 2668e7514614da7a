"""ISO 230-4 figures on hand cases; diagnosis recovers simulated effects with the right sign."""

from __future__ import annotations

import numpy as np
import pytest

from ncpp.errors import NcppError
from ncpp.instruments.files import make_measurement, read_measurement
from ncpp.instruments.iso230_4 import (
    CircularTest,
    Trace,
    circular_test,
    diagnose_circular,
    evaluate_circular,
    evaluate_measurement,
    lsc_centre,
)

ANGLES = np.array([0.0, 90.0, 180.0, 270.0])


def test_hand_case_two_directions():
    # CCW: 1,-1,1,-1 (already centred); CW: 3,0,1,0 = 2,0,2,0 shifted by a 1 µm centre offset in X.
    ccw = Trace("CCW", ANGLES, np.array([1.0, -1.0, 1.0, -1.0]))
    cw = Trace("CW", ANGLES, np.array([3.0, 0.0, 1.0, 0.0]))
    result = evaluate_circular(CircularTest((ccw, cw), radius_mm=100.0))
    assert result.G_ccw == pytest.approx(2.0, abs=1e-4)  # 1 - (-1)
    assert result.G_cw == pytest.approx(2.0, abs=1e-4)  # centred: 2,0,2,0
    # Common centre of all 8 points: cx = Σd·cosθ / Σcos²θ = (1-1+3-1)/4 = 0.5.
    # Centred: CCW 0.5,-1,1.5,-1 and CW 2.5,0,1.5,0.
    np.testing.assert_allclose(result.common_centre_um, [0.5, 0.0], atol=1e-4)  # exact LSC: to 2nd order
    assert result.G == pytest.approx(3.5, abs=1e-4)  # 2.5 - (-1)
    assert result.H == pytest.approx(2.0, abs=1e-4)  # |0.5 - 2.5|
    assert result.F_max == pytest.approx(2.0, abs=1e-4)  # CW about its own centre
    assert result.F_min == pytest.approx(-1.0, abs=1e-4)


def test_one_direction_has_no_hysteresis():
    result = evaluate_circular(CircularTest((Trace("CW", ANGLES, np.array([0.0, 2.0, 0.0, 2.0])),), 50.0))
    assert result.G_ccw is None and result.H is None
    assert result.G == result.G_cw == pytest.approx(2.0, abs=1e-4)
    assert (result.F_max, result.F_min) == pytest.approx((2.0, 0.0), abs=1e-4)


def test_lsc_removes_a_large_setup_offset_exactly():
    # A perfect circle seen from a ball 50 µm off its centre: exact bar lengths.
    theta = np.radians(np.arange(0.0, 360.0, 2.0))
    R, off = 150.0, np.array([0.05, -0.03])
    pts = R * np.column_stack([np.cos(theta), np.sin(theta)])
    length = np.hypot(*(pts - off).T)
    angle = np.degrees(np.arctan2(*(pts - off).T[::-1])) % 360
    trace = Trace("CCW", angle, (length - R) * 1000)
    np.testing.assert_allclose(lsc_centre([trace], R), -off * 1000, atol=1e-6)
    assert evaluate_circular(CircularTest((trace,), R)).G < 1e-6


def test_hysteresis_interpolates_to_common_angles():
    a = np.arange(0.0, 360.0, 10.0)
    ccw = Trace("CCW", a, np.sin(np.radians(4 * a)))
    cw = Trace("CW", a + 5.0, np.sin(np.radians(4 * (a + 5.0))))  # same path, other angles
    assert evaluate_circular(CircularTest((ccw, cw), 100.0)).H < 0.1


def simulate(generator, direction, **effects):
    angle, dev, _ = generator.simulate_circle(150.0, direction, feed_mm_min=1200.0, **effects)
    return Trace(direction, angle, dev)


def diagnose(generator, plane="XY", both=True, **effects):
    traces = tuple(simulate(generator, d, **effects) for d in (("CCW", "CW") if both else ("CCW",)))
    return diagnose_circular(CircularTest(traces, 150.0, plane, 1200.0)).figures


def test_pure_squareness_gives_half_sR_sin2theta(generator):
    # First principles: δx = s·y on a circle of radius R reads ΔR = (sR/2)·sin 2θ.
    s = 50e-6
    angle, dev, _ = generator.simulate_circle(150.0, "CCW", squareness_um_per_m=50.0)
    np.testing.assert_allclose(
        dev, s * 150.0 * 1000 / 2 * np.sin(np.radians(2 * angle)), atol=1e-3
    )  # + (sy)²/2R


@pytest.mark.parametrize("value", [40.0, -25.0])
def test_squareness_is_recovered_with_its_sign(generator, value):
    f = diagnose(generator, squareness_um_per_m=value)
    assert f["squareness_um_per_m"] == pytest.approx(value, abs=0.2)
    assert abs(f["servo_mismatch_ms"]) < 0.01 and abs(f["backlash_X_um"]) < 0.05


def test_scale_mismatch_is_first_minus_second_axis(generator):
    f = diagnose(generator, scale_um_per_m=(30.0, 10.0))
    assert f["scale_mismatch_um_per_m"] == pytest.approx(20.0, abs=0.2)
    assert f["radius_deviation_um"] == pytest.approx(150.0 * 20.0e-3, abs=0.05)  # mean scale 20 µm/m
    assert abs(f["squareness_um_per_m"]) < 0.2


def test_servo_mismatch_flips_with_direction_and_is_told_from_squareness(generator):
    f = diagnose(generator, lag_ms=(1.0, 0.4), squareness_um_per_m=20.0)
    assert f["servo_mismatch_ms"] == pytest.approx(0.6, abs=0.02)
    assert f["squareness_um_per_m"] == pytest.approx(20.0, abs=0.5)


@pytest.mark.parametrize("backlash", [(5.0, 0.0), (0.0, 3.0), (4.0, 1.5)])
def test_backlash_per_axis(generator, backlash):
    f = diagnose(generator, backlash_um=backlash)
    assert f["backlash_X_um"] == pytest.approx(backlash[0], abs=0.15)
    assert f["backlash_Y_um"] == pytest.approx(backlash[1], abs=0.15)
    assert abs(f["servo_mismatch_ms"]) < 0.02 and abs(f["squareness_um_per_m"]) < 1.0


def test_reversal_spikes_per_axis(generator):
    f = diagnose(generator, spike_um=(0.0, 4.0), backlash_um=(2.0, 2.0))
    assert f["reversal_spike_Y_um"] == pytest.approx(4.0, abs=0.3)
    assert abs(f["reversal_spike_X_um"]) < 0.3
    assert f["backlash_Y_um"] == pytest.approx(2.0, abs=0.3)


def test_axis_names_follow_the_plane(generator):
    f = diagnose(generator, plane="ZX", backlash_um=(3.0, 0.0))
    assert f["backlash_Z_um"] == pytest.approx(3.0, abs=0.15) and abs(f["backlash_X_um"]) < 0.15
    assert "centre_offset_Z_um" in f


def test_centre_offset_and_noise(generator):
    rng = np.random.default_rng(1)
    f = diagnose(generator, setup_offset_um=(8.0, -5.0), squareness_um_per_m=30.0, noise_um=0.3, rng=rng)
    assert (f["centre_offset_X_um"], f["centre_offset_Y_um"]) == pytest.approx((-8.0, 5.0), abs=0.1)
    assert f["squareness_um_per_m"] == pytest.approx(30.0, abs=1.0)
    assert f["residual_rms_um"] == pytest.approx(0.3, abs=0.05)


def test_one_direction_cannot_separate_servo(generator):
    f = diagnose(generator, both=False, squareness_um_per_m=10.0)
    assert f["servo_mismatch_ms"] is None and f["squareness_um_per_m"] == pytest.approx(10.0, abs=0.3)


def test_sample_files(samples_dir):
    ballbar = read_measurement(samples_dir / "ballbar_XY_R150.csv")
    result = evaluate_measurement(ballbar)
    assert result.G > 10 and result.G_cw > 4 and result.H > 5  # 40 µm/m squareness, backlash, lag
    grid = circular_test(read_measurement(samples_dir / "grid_XY_circle.csv"))
    assert [t.direction for t in grid.traces] == ["CCW"]  # deduced from the path order
    cutting = evaluate_measurement(read_measurement(samples_dir / "cutting_XY_R50.csv"))
    assert cutting.F_max < 0 and 2.0 < cutting.G < 5.0


def test_partial_arcs_compare_only_where_both_were_measured(generator):
    # Vertical-plane style partial arcs: CCW over 0..200 deg, CW over 340..180 deg.
    ccw_a = np.arange(0.0, 201.0, 2.0)
    cw_a = np.arange(-20.0, 181.0, 2.0) % 360
    shape = lambda a: 2 * np.sin(np.radians(2 * a))  # noqa: E731
    ccw = Trace("CCW", ccw_a, shape(ccw_a))
    cw = Trace("CW", cw_a, shape(cw_a) + 0.5)
    test = CircularTest((ccw, cw), 100.0, "ZX", 1000.0)
    result = evaluate_circular(test)
    assert result.H == pytest.approx(0.5, abs=0.05)  # no interpolation across the open arc
    f = diagnose_circular(test).figures
    assert f["squareness_um_per_m"] == pytest.approx(2 * 2 * 1000 / 100.0, rel=0.05)  # (sR/2) = 2 µm


def test_cyclic_error_is_found_with_its_lead(generator):
    rng = np.random.default_rng(3)
    f = diagnose(
        generator, cyclic_um=(0.0, 1.5), cyclic_period_mm=16.0, backlash_um=(2.0, 2.0), noise_um=0.2, rng=rng
    )
    assert f["cyclic_Y_um"] == pytest.approx(1.5, abs=0.15) and f["cyclic_Y_period_mm"] == 16.0
    assert f["cyclic_X_um"] is None  # nothing there, nothing reported
    assert f["backlash_X_um"] == pytest.approx(2.0, abs=0.2)


def test_ballbar_built_without_a_radius_is_refused_with_its_name():
    # loading refuses such a file; one built in memory reaches circular_test, which names
    # the missing radius (not a TypeError from float(None))
    columns = {"angle_deg": list(ANGLES), "deviation_um": [1.0, -1.0, 1.0, -1.0], "direction": ["CCW"] * 4}
    m = make_measurement("ballbar", {"plane": "XY"}, columns, source="bare.csv")
    with pytest.raises(NcppError, match="radius_mm"):
        circular_test(m)
