"""ISO 230-2 on small cases computed by hand (numbers in the comments)."""

from __future__ import annotations

import numpy as np
import pytest

from ncpp.errors import NcppError
from ncpp.instruments.files import make_measurement, read_measurement
from ncpp.instruments.iso230_2 import evaluate_measurement, evaluate_positioning

# target 0:   up 1,2,3 -> x̄↑=2, s↑=1      down 3,5,7 -> x̄↓=5, s↓=2     x̄=3.5  B=-3
#             R↑=4, R↓=8, R_i=max(2+4+3, 4, 8)=9
# target 100: up -2,-2,-2 -> x̄↑=-2, s↑=0  down 2,3,4 -> x̄↓=3, s↓=1    x̄=0.5  B=-5
#             R↑=0, R↓=4, R_i=max(0+2+5, 0, 4)=7
UP = {0.0: [1, 2, 3], 100.0: [-2, -2, -2]}
DOWN = {0.0: [3, 5, 7], 100.0: [2, 3, 4]}


def rows(up, down):
    t, d, x = [], [], []
    for direction, table in (("+", up), ("-", down)):
        for target, values in table.items():
            t += [target] * len(values)
            d += [direction] * len(values)
            x += values
    return np.array(t), np.array(d), np.array(x, dtype=float)


def test_bidirectional_hand_case():
    result = evaluate_positioning(*rows(UP, DOWN))
    np.testing.assert_allclose(result.up.mean, [2, -2])
    np.testing.assert_allclose(result.down.s, [2, 1])
    np.testing.assert_allclose(result.mean, [3.5, 0.5])
    np.testing.assert_allclose(result.reversal, [-3, -5])
    np.testing.assert_allclose(result.repeatability, [9, 7])
    expected = {
        "A_up": 6.0,  # max(2+2, -2+0) - min(2-2, -2-0) = 4 - (-2)
        "A_down": 8.0,  # max(5+4, 3+2) - min(5-4, 3-2) = 9 - 1
        "A": 11.0,  # max(4, -2, 9, 5) - min(0, -2, 1, 1)
        "E_up": 4.0,  # 2 - (-2)
        "E_down": 2.0,  # 5 - 3
        "E": 7.0,  # max(2, -2, 5, 3) - min(...)
        "M": 3.0,  # 3.5 - 0.5
        "B": 5.0,  # max |B_i|
        "B_mean": -4.0,  # (-3 - 5) / 2
        "R_up": 4.0,
        "R_down": 8.0,
        "R": 9.0,
    }
    figures = result.figures()
    assert set(figures) == set(expected)
    for key, value in expected.items():
        assert figures[key] == pytest.approx(value), key


def test_unidirectional_file_reduces_to_the_one_direction():
    figures = evaluate_positioning(*rows(UP, {})).figures()
    assert figures["B"] is None and figures["B_mean"] is None
    assert figures["A_down"] is None and figures["E_down"] is None and figures["R_down"] is None
    assert figures["A"] == pytest.approx(6.0) and figures["A_up"] == pytest.approx(6.0)
    assert figures["E"] == pytest.approx(4.0) and figures["M"] == pytest.approx(4.0)
    assert figures["R"] == pytest.approx(4.0)


def test_single_run_leaves_statistical_figures_undefined():
    figures = evaluate_positioning(*rows({0.0: [1], 10.0: [3]}, {0.0: [2], 10.0: [5]})).figures()
    assert figures["A"] is None and figures["R"] is None and figures["R_up"] is None
    assert figures["E"] == pytest.approx(4.0)  # 5 - 1
    assert figures["M"] == pytest.approx(2.5)  # 4 - 1.5
    assert figures["B"] == pytest.approx(2.0) and figures["B_mean"] == pytest.approx(-1.5)


def test_comparator_uses_the_linear_column():
    t, d, x = rows(UP, DOWN)
    m = make_measurement(
        "comparator",
        {"axis": "X"},
        {"target_mm": t, "run": [1] * len(t), "direction": d, "linear_um": x, "transverse_um": x * 100},
    )
    assert evaluate_measurement(m).figures()["A"] == pytest.approx(11.0)


def test_level_files_are_refused():
    m = make_measurement("level", {}, {"position_mm": [0, 1], "inclination_um_per_m": [0, 1]})
    with pytest.raises(NcppError, match="ISO 230-2"):
        evaluate_measurement(m)


def test_sample_laser_file_figures_are_consistent(samples_dir):
    result = evaluate_measurement(read_measurement(samples_dir / "laser_X_position.csv"))
    f = result.figures()
    # A bounds E, E bounds M and E↑; R bounds R↑ and R↓; the sample has a -3.2 µm reversal.
    assert f["A"] >= f["E"] >= max(f["E_up"], f["E_down"], f["M"])
    assert f["R"] >= max(f["R_up"], f["R_down"])
    assert -4.0 < f["B_mean"] < -2.5 and len(result.targets) == 11
