"""The inverse error map takes as few steps as keep its residual below a quarter of
the output's last digit (`iterations_for`), whatever the machine."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ncpp.machine import load_machine
from ncpp.passes.inverse import ITERATIONS, command_for, iterations_for
from ncpp.pipeline import INVERSE_BUDGET, MachineMap

MACHINES = sorted((Path(__file__).resolve().parents[2] / "samples/machines").glob("*.toml"))


@pytest.mark.parametrize("path", MACHINES, ids=lambda p: p.stem)
def test_the_chosen_steps_leave_the_command_within_the_budget(path):
    machine = load_machine(str(path))
    model = MachineMap(machine)  # what compensation inverts: geometry and position-only effects
    steps = iterations_for(model, machine.limits, INVERSE_BUDGET)
    rng = np.random.default_rng(7)  # other points than the estimate's
    lo, hi = np.array([machine.limits[a] for a in "XYZ"]).T
    wanted = lo + (hi - lo) * rng.random((20_000, 3))
    direction = rng.choice([-1.0, 0.0, 1.0], size=wanted.shape)
    tool = np.tile([0.0, 0.0, 150.0], (len(wanted), 1))  # a long tool: a longer Abbe arm than the estimate's

    def residual(k: int) -> float:
        c = command_for(model, wanted, direction, tool, k)
        return float(np.abs(c + model.deviation(c, direction, tool) - wanted).max())

    assert residual(steps) <= INVERSE_BUDGET
    assert steps == 1 or residual(steps - 1) > INVERSE_BUDGET / 2  # one step fewer would not do


class Scale:
    """E = s·P: a scale error, whose inverse gains only a factor s per step."""

    def __init__(self, s: float):
        self.s = s

    def deviation(self, P, direction=None):
        return self.s * np.asarray(P)


def test_a_steeper_map_takes_more_steps():
    travel = {axis: (0.0, 1000.0) for axis in "XYZ"}
    # residual after k steps: s^(k+1)·P, P up to 1000 mm; twice it must be within 25 nm
    assert iterations_for(Scale(1e-6), travel, INVERSE_BUDGET) == 1  # 1e-9 mm
    assert iterations_for(Scale(3e-4), travel, INVERSE_BUDGET) == 2  # 9e-5 mm after one step, 3e-8 after two
    assert iterations_for(Scale(3e-3), travel, INVERSE_BUDGET) == 3  # 9e-3, 2.7e-5, 8e-8 mm


def test_without_a_travel_the_inverse_takes_the_safe_count():
    assert iterations_for(Scale(1e-6), {}, INVERSE_BUDGET) == ITERATIONS
