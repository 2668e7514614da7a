"""Compensation sees geometry plus the position-only effects, nothing that needs motion."""

from __future__ import annotations

import numpy as np
import pytest

from ncpp.machine import load_machine
from ncpp.machine.effects import Backlash, Scale, Straightness
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def machine():
    return load_machine(ROOT / "samples/machines/hr5b.toml")


def test_static_effects_add_to_the_geometry(machine):
    warm = machine.replace(effects=(Scale(axis="X", um_per_m=25.0), Backlash(axis="Y", um=8.0)))
    P = np.array([[100.0, 200.0, 300.0], [700.0, 200.0, 300.0]])
    extra = warm.static_deviation(P) - machine.deviation(P)
    # 25 µm/m over the 600 mm between the two points; backlash (needs motion) is left out
    assert (extra[1, 0] - extra[0, 0]) * 1000 == pytest.approx(15.0, abs=1e-6)
    assert np.allclose(extra[:, 1:], 0.0)


def test_straightness_without_range_bows_over_the_travel(machine):
    bowed = machine.replace(effects=(Straightness(axis="X", direction="Y", um=6.0),))
    lo, hi = machine.limits["X"]
    P = np.array([[lo, 0.0, 0.0], [(lo + hi) / 2, 0.0, 0.0], [hi, 0.0, 0.0]])
    bow = (bowed.static_deviation(P) - machine.deviation(P))[:, 1] * 1000
    assert bow == pytest.approx([0.0, 6.0, 0.0], abs=1e-9)
    # one point at a time gives the same (no dependence on the sampled extent)
    assert bowed.static_deviation(P[1])[1] * 1000 - machine.deviation(P[1])[1] * 1000 == pytest.approx(6.0)
