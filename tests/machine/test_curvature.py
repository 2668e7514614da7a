"""The bound of the error's bow along a segment (`ncpp/machine/curvature.py`): an upper
bound wherever it is given, none where the error may not be smooth, and lines it keeps
whole are those the samples keep whole."""

from __future__ import annotations

import numpy as np
import pytest

from ncpp.machine import load_machine
from ncpp.machine.components import Table
from ncpp.machine.effects import Scale
from ncpp.motion.segments import Context, Line
from ncpp.passes.context import PassContext
from ncpp.passes.subdivide import PieceCounts, _with_rows
from ncpp.pipeline import MachineMap
from ncpp.program.blocks import Block
from tests.conftest import ROOT


@pytest.fixture(scope="module")
def hr5b():
    return load_machine(ROOT / "samples/machines/hr5b.toml")


@pytest.fixture(scope="module")
def bumpy(hr5b):
    """HR5B with a straightness of X and a pitch of Z that bend every 50 mm, large enough
    for lines of some tens of mm to need splitting at 1 µm."""
    rng = np.random.default_rng(3)
    x, z = np.arange(0.0, 801.0, 50.0), np.arange(0.0, 701.0, 50.0)
    components = dict(hr5b.components)
    components["EYX"] = Table(tuple(x), tuple(rng.normal(0.0, 0.02, len(x))), interpolation="smooth")
    components["EBZ"] = Table(
        tuple(z),
        tuple(rng.normal(0.0, 4e-5, len(z))),
        tuple(rng.normal(0.0, 4e-5, len(z))),
        interpolation="smooth",
    )
    return hr5b.replace(components=components)


def _bow(machine, start, end, direction, tool, samples=201):
    t = np.linspace(0.0, 1.0, samples)[:, None]
    P = start + t * (end - start)
    e = machine.static_deviation(P, np.broadcast_to(direction, P.shape), np.broadcast_to(tool, P.shape))
    return float(np.linalg.norm(e - (e[0] + t * (e[-1] - e[0])), axis=1).max())


@pytest.mark.parametrize("which", ["hr5b", "bumpy"])
def test_the_bound_holds_along_random_segments(which, request):
    machine = request.getfixturevalue(which)
    bound = machine.bow_bound
    assert bound is not None
    rng = np.random.default_rng(7)
    n = 300
    start = rng.uniform([20.0, 20.0, 20.0], [780.0, 680.0, 680.0], (n, 3))
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    length = rng.uniform(1.0, 60.0, n)
    end = np.clip(start + u * length[:, None], 0.0, [800.0, 700.0, 700.0])
    length = np.linalg.norm(end - start, axis=1)
    tools = np.zeros((n, 3))
    tools[::3, 2] = rng.uniform(-150.0, 150.0, len(tools[::3]))  # some with a tool length offset
    kappa = bound(start, end, tools)
    assert np.isfinite(kappa).all()
    ratios = [
        _bow(machine, start[i], end[i], np.sign(end[i] - start[i]), tools[i])
        / (length[i] ** 2 / 8 * kappa[i])
        for i in range(n)
    ]
    assert max(ratios) <= 1.0
    assert max(ratios) > 0.02  # (a bound that says something)


def test_no_bound_where_the_error_may_not_be_smooth(hr5b):
    x = (0.0, 400.0, 800.0)
    linear = dict(hr5b.components, EYX=Table(x, (0.0, 0.005, 0.0), interpolation="linear"))
    assert hr5b.replace(components=linear).bow_bound is None  # a kink at 400
    assert (
        hr5b.replace(effects=(Scale(axis="X", um_per_m=10.0),)).bow_bound is None
    )  # a static effect the bound does not know
    assert load_machine(ROOT / "samples/machines/valmet.toml").bow_bound is None


def test_outside_a_table_there_is_no_bound(hr5b):
    bound = hr5b.bow_bound
    inside, outside = (
        np.array([[100.0, 100.0, 100.0]]),
        np.array([[900.0, 100.0, 100.0]]),
    )  # X's tables end at 800
    assert np.isfinite(bound(inside, inside + 10.0))
    assert bound(inside, outside) == np.inf


def test_lines_the_bound_keeps_whole_are_those_the_samples_keep_whole(bumpy):
    rng = np.random.default_rng(11)
    block, context = Block("G1 X1", "\n", (), 1), Context()
    start = rng.uniform([20.0, 20.0, 20.0], [780.0, 680.0, 680.0], (400, 3))
    u = rng.normal(size=(400, 3))
    u /= np.linalg.norm(u, axis=1)[:, None]
    end = np.clip(start + u * rng.uniform(1.0, 80.0, (400, 1)), 0.0, [800.0, 700.0, 700.0])
    lines = [
        Line(tuple(a), tuple(b), False, 500.0, block, context) for a, b in zip(start.tolist(), end.tolist())
    ]
    ctx = PassContext(model=MachineMap(bumpy), tolerance=0.001, directional=True)
    sampled = _with_rows(lines, ctx)
    bounded = _with_rows(lines, ctx, bumpy.bow_bound)
    counts = dict(zip(sampled[1], PieceCounts(ctx)(sampled[3]).tolist()))
    kept = set(sampled[1]) - set(bounded[1])
    assert 0 < len(kept) < len(sampled[1])  # some left unsampled, some not
    assert all(counts[k] == 1 for k in kept)
    assert any(n > 1 for n in counts.values())  # (lines that the samples split are sampled)
