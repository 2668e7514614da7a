"""The fast evaluation (stacked tables, in-place chain algebra) gives the same
bits as the plain formulas it replaces: compensated output must not change."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.typing import NDArray

from ncpp.machine import Polynomial, load_machine
from ncpp.machine.chain import AXES, Chain, direction_errors, exact_deviation, squareness_vectors
from ncpp.machine.components import StackedTables, Table, _chosen, _signs
from tests.conftest import ROOT

MACHINE = load_machine(ROOT / "samples/machines/hr5b.toml")
seeds = st.integers(0, 2**32 - 1)
sizes = st.integers(1, 300)


def _directions(rng: np.random.Generator, shape: tuple[int, ...]) -> NDArray | None:
    """None, or travel signs with standing axes, odd magnitudes and NaN mixed in."""
    if rng.random() < 0.2:
        return None
    return rng.choice(
        [-1.0, 1.0, 0.0, -0.0, 2.5, -0.5, np.nan], size=shape, p=[0.35, 0.35, 0.1, 0.05, 0.05, 0.05, 0.05]
    )


def _curve(stacked: StackedTables, column: int, p: NDArray) -> NDArray:
    """One stacked curve, point by point: clamp, find the interval, Horner."""
    grid = stacked.grid
    q = np.clip(p, grid[0], grid[-1])
    i = np.clip(np.searchsorted(grid, q, side="right") - 1, 0, len(grid) - 2)
    dx = q - grid[i]
    c0, c1, c2, c3 = (c[column, i] for c in stacked.coefficients)
    return ((c0 * dx + c1) * dx + c2) * dx + c3


def _tables(rng: np.random.Generator) -> list[Table]:
    tables = []
    for _ in range(rng.integers(1, 7)):
        m = int(rng.integers(1, 9))
        x = np.cumsum(rng.uniform(5.0, 120.0, m)) - 200.0
        minus = rng.normal(size=m) * 1e-3 if rng.random() < 0.5 else None
        tables.append(Table(x, rng.normal(size=m) * 1e-3, minus, rng.choice(["linear", "smooth"])))
    return tables


@settings(max_examples=200, deadline=None)
@given(seeds, sizes)
def test_stacked_tables_equal_each_curve_chosen_by_direction(seed, n):
    rng = np.random.default_rng(seed)
    tables = _tables(rng)
    stacked = StackedTables(tables)
    p = rng.uniform(-300.0, 900.0, n)
    on_grid = rng.random(n) < 0.2  # breakpoints: where the interval search must agree exactly
    p[on_grid] = rng.choice(stacked.grid, on_grid.sum())
    p[rng.random(n) < 0.02] = np.nan
    d = _directions(rng, (n,))
    got = stacked(p, d)
    assert len(got) == len(tables)
    for values, (plus, minus) in zip(got, stacked.columns):
        want = (
            _curve(stacked, plus, p)
            if minus is None
            else _chosen(_signs(d), _curve(stacked, plus, p), _curve(stacked, minus, p))
        )
        assert np.array_equal(values, want, equal_nan=True)


def _plain_cross(a: NDArray, b: NDArray) -> NDArray:
    a0, a1, a2 = a[:, 0], a[:, 1], a[:, 2]
    b0, b1, b2 = b[:, 0], b[:, 1], b[:, 2]
    return np.column_stack([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def _plain_rotate_minus_identity(eps: NDArray, v: NDArray) -> NDArray:
    th2 = (eps[:, 0] * eps[:, 0] + eps[:, 1] * eps[:, 1] + eps[:, 2] * eps[:, 2])[:, None]
    a = 1.0 - th2 * (1.0 / 6.0 - th2 / 120.0)
    b = 0.5 - th2 * (1.0 / 24.0 - th2 / 720.0)
    ev = _plain_cross(eps, v)
    return a * ev + b * _plain_cross(eps, ev)


def _plain_exact_deviation(chain, P, tool, references, delta, eps, squareness) -> NDArray:
    """The chain product walked from the tool end, one expression per step."""
    dir_err = direction_errors(squareness)
    nominal = np.broadcast_to(tool, P.shape).astype(float)
    w = np.zeros(P.shape)
    for axis in reversed(chain.order):
        i = AXES.index(axis)
        lever = nominal - references[axis] + w
        w = w + P[:, i : i + 1] * dir_err[axis] + delta[axis] + _plain_rotate_minus_identity(eps[axis], lever)
        nominal[:, i] += P[:, i]
    return w


@settings(max_examples=100, deadline=None)
@given(seeds, sizes, st.sampled_from(["XZFY", "XYFZ", "XFYZ", "FXYZ", "ZYXF"]))
def test_exact_deviation_equals_the_plain_product(seed, n, chain):
    rng = np.random.default_rng(seed)
    P = rng.uniform(-100.0, 900.0, (n, 3))
    tool = rng.uniform(-300.0, 300.0, (n, 3)) if rng.random() < 0.5 else rng.uniform(-300.0, 300.0, 3)
    refs = {a: rng.uniform(-500.0, 500.0, 3) for a in AXES}
    delta = {a: rng.normal(size=(n, 3)) * 1e-2 for a in AXES}
    eps = {a: rng.normal(size=(n, 3)) * 10.0 ** rng.uniform(-8, -2) for a in AXES}
    squareness = squareness_vectors(*rng.normal(size=3) * 1e-4)
    args = (Chain(chain), P, tool, refs, delta, eps, squareness)
    assert np.array_equal(exact_deviation(*args), _plain_exact_deviation(*args))


@settings(max_examples=30, deadline=None)
@given(seeds, st.integers(1, 3000))
def test_machine_deviation_equals_the_plain_evaluation(seed, n):
    """The whole path on the sample machine with direction-dependent tables."""
    rng = np.random.default_rng(seed)
    P = rng.uniform(-50.0, 850.0, (n, 3))
    d = _directions(rng, (n, 3))
    tools = rng.uniform(0.0, 150.0, (n, 3)) if rng.random() < 0.5 else None
    delta, eps = {}, {}
    for i, axis in enumerate(AXES):
        values = {
            name: c(P[:, i], None if d is None else d[:, i])
            for name, c in MACHINE.components.items()
            if name.endswith(axis)
        }
        zero = np.zeros(n)
        delta[axis] = np.column_stack([values.get(f"E{e}{axis}", zero) for e in "XYZ"])
        eps[axis] = np.column_stack([values.get(f"E{r}{axis}", zero) for r in "ABC"])
    chain, tool, refs, squareness = MACHINE._frame
    want = _plain_exact_deviation(
        chain, P, tool if tools is None else tool - tools, refs, delta, eps, squareness
    )
    assert np.allclose(MACHINE.deviation(P, d, tools), want, rtol=0, atol=1e-12)


def test_error_motions_of_an_axis_with_missing_and_polynomial_components():
    """Motions are the stacked tables' rows as they are only when all six are tables."""
    poly = Polynomial([1e-3, 2e-6])
    partial = MACHINE.with_components(EYX=None, EZY=poly)
    rng = np.random.default_rng(3)
    P, d = rng.uniform(0.0, 700.0, (500, 3)), rng.choice([-1.0, 0.0, 1.0], (500, 3))
    full_delta, full_eps = MACHINE.error_motions(P, d)
    delta, eps = partial.error_motions(P, d)
    assert np.array_equal(delta["X"][:, 1], np.zeros(500)) and np.array_equal(
        delta["X"][:, [0, 2]], full_delta["X"][:, [0, 2]]
    )
    assert np.array_equal(delta["Y"][:, 2], poly(P[:, 1])) and np.array_equal(
        delta["Y"][:, :2], full_delta["Y"][:, :2]
    )
    for axis in AXES:
        assert np.array_equal(eps[axis], full_eps[axis])
    assert np.array_equal(delta["Z"], full_delta["Z"])
