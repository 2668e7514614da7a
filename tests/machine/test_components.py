"""Error components: interpolation, end values, directions, names."""

import numpy as np
import pytest

from ncpp.machine import COMPONENTS, THESIS_NAMES, Polynomial, Table, canonical_name
from ncpp.machine.components import StackedTables


def test_there_are_21_components_plus_3_squarenesses():
    assert len(COMPONENTS) == 18  # 6 per axis; the 3 squarenesses are constants
    assert canonical_name("Yxy") == "EXY" and canonical_name("xy") == "EXY"
    assert canonical_name("cx") == "ECX" and canonical_name("Zbz") == "EBZ"
    assert (
        canonical_name("kxy") == "C0Y" and canonical_name("kzx") == "B0Z" and canonical_name("kyz") == "A0Z"
    )
    assert canonical_name("exx") == "EXX"
    assert all(canonical_name(t) == iso for t, iso in THESIS_NAMES.items())
    with pytest.raises(ValueError):
        canonical_name("Xqq")


def test_linear_and_smooth_hold_end_values():
    lin = Table([0, 10, 20], [0.0, 1.0, 0.0])
    smooth = Table([0, 10, 20, 30], [0.0, 1.0, 0.0, 2.0], interpolation="smooth")
    assert lin(5.0) == pytest.approx(0.5)
    assert lin(-100.0) == 0.0 and lin(100.0) == 0.0
    assert smooth(-5.0) == 0.0 and smooth(1e6) == 2.0
    assert smooth(10.0) == pytest.approx(1.0)
    # PCHIP does not overshoot the data between points
    x = np.linspace(0, 30, 301)
    assert smooth(x).max() <= 2.0 + 1e-12 and smooth(x).min() >= -1e-12


def test_table_validation():
    with pytest.raises(ValueError, match="increasing"):
        Table([0, 0], [1, 2])
    with pytest.raises(ValueError, match="values"):
        Table([0, 1], [1, 2, 3])
    with pytest.raises(ValueError, match="interpolation"):
        Table([0, 1], [1, 2], interpolation="cubic")


def test_polynomial_limits():
    p = Polynomial([1.0, 2.0], reference=1.0, limits=(0.0, 2.0))
    assert p(1.5) == pytest.approx(2.0) and p(10.0) == pytest.approx(3.0)


def test_stacked_evaluation_equals_each_table():
    rng = np.random.default_rng(5)
    tables = [
        Table([0, 50, 100, 150], rng.normal(size=4), interpolation="smooth"),
        Table([10, 40, 70, 95, 130], rng.normal(size=5)),
        Table([20, 60], rng.normal(size=2), rng.normal(size=2)),
        Table([30], [0.7]),
    ]
    p = rng.uniform(-20, 170, 500)
    d = rng.choice([-1.0, 0.0, 1.0], 500)
    for t, v in zip(tables, StackedTables(tables)(p, d)):
        assert np.allclose(v, t(p, d), atol=1e-14)
