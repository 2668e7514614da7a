"""ncpp's PCHIP coefficients are scipy's (computed without importing scipy.interpolate)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.interpolate import PchipInterpolator

from ncpp.machine.components import Table, pchip_pieces

values = st.lists(st.floats(-0.05, 0.05, allow_nan=False), min_size=3, max_size=25)


@settings(max_examples=300, deadline=None)
@given(values, st.integers(0, 3))
def test_pchip_pieces_are_scipys(ys, rounding):
    y = np.round(ys, 2 + rounding)  # rounded values make flat stretches and slope sign changes
    x = np.linspace(-400.0, 400.0, len(y)) + np.arange(len(y)) ** 1.5  # uneven spacing
    assert np.array_equal(pchip_pieces(x, y), PchipInterpolator(x, y).c.T)


def test_table_evaluates_the_pchip_curve_and_holds_its_ends():
    x, y = (0.0, 100.0, 250.0, 400.0), (0.0, 0.004, -0.002, 0.003)
    table = Table(x, y, interpolation="smooth")
    p = np.linspace(-50.0, 450.0, 101)
    want = PchipInterpolator(x, y, extrapolate=False)(np.clip(p, 0.0, 400.0))
    assert np.allclose(table(p), want, rtol=0, atol=1e-15)
