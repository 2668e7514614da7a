"""One measurement file as the diagnosis sees it: readings, the model's
prediction, set-up nuisances, and the reading a candidate effect adds.

The model's prediction comes from the instruments' forward models
(`ncpp.instruments.forward.predict_like`, the same set-up as the file).  A
candidate effect's contribution is the finite difference of `Machine.simulate`
with the effect added: simulate adds `effect.apply(trajectory)` to the actual
positions, so the difference is that deviation seen through the instrument,
linearised (ball bar: its radial component; laser, comparator: the read
component).  The trajectories mirror the forward models' set-ups (feed-in arcs,
stop-and-go positioning cycles) so the columns match the prediction.

Set-up nuisances, fitted with every model and never reported as effects:
ball bar — length offset and centre offset in the plane (1, cos θ, sin θ);
positioning along the axis — one zero (dead path) per run; straightness and
transverse readings — offset and slope (laser alignment); angles — offset.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import NcppError
from ncpp.instruments.files import PLANES, Measurement
from ncpp.instruments.forward import iso230_2_cycle
from ncpp.instruments.iso230_4 import circular_test
from ncpp.machine.components import AXES
from ncpp.machine.effects import Angular, Effect
from ncpp.machine.model import Machine
from ncpp.machine.trajectory import Trajectory

BALLBAR_STEP_DEG = 0.25  # simulation step; the file's angles are interpolated from it
FEED_IN_DEG = 45.0  # lead-in and lead-out arcs of a ball-bar run
OVERTRAVEL_MM = 5.0  # positioning cycle: beyond the last target before reversing (as forward.py's default)
ANGLES = ("pitch", "yaw", "roll")
USED = ("ballbar", "laser", "comparator")


@dataclass(frozen=True)
class Part:
    """One direction of a ball-bar run or one positioning cycle: its trajectory
    and how a deviation (n,3) mm becomes the file's readings (µm)."""

    trajectory: Trajectory
    rows: NDArray  # which observation rows this part fills
    read: object  # callable (n,3) mm deviation -> readings µm for `rows`


@dataclass(frozen=True, eq=False)
class Observation:
    measurement: Measurement
    y: NDArray  # readings, µm (µrad for angles)
    nuisance: NDArray  # (n, k) set-up columns
    parts: tuple[Part, ...]
    machine: Machine  # the model at the instrument's functional point
    groups: NDArray  # rows with the same group id are one trace (noise estimate)
    position: NDArray  # angle (deg) or target (mm) of each row, for the account
    label: NDArray  # direction of travel of each row ("CW", "+", ...)
    repeat_key: NDArray | None = None  # rows that repeat the same point (laser runs)
    angular: bool = False
    name: str = field(default="")

    def __len__(self) -> int:
        return len(self.y)

    @property
    def feed(self) -> float:
        return self.measurement.feed_mm_min or 1000.0

    def contribution(self, effect: Effect) -> NDArray:
        """Readings (µm) the effect adds to this file's readings (linearised)."""
        out = np.zeros(len(self.y))
        for part in self.parts:
            if self.angular:
                out[part.rows] = part.read(effect)  # type: ignore[operator]
            else:
                out[part.rows] = part.read(effect.apply(part.trajectory, self.machine))  # type: ignore[operator]
        return out


def predicted(machine: Machine, m: Measurement) -> NDArray:
    """The model's readings for file `m` (µm), in the observation's row order."""
    from ncpp.instruments.forward import predict_like

    p = predict_like(machine, m)
    return readings_of(p)


def readings_of(m: Measurement) -> NDArray:
    if m.instrument == "ballbar":
        return np.asarray(m["deviation_um"], dtype=float)
    if m.instrument == "laser":
        return np.asarray(m[m.deviation_column], dtype=float)
    cols = [m["linear_um"]] + ([m["transverse_um"]] if "transverse_um" in m.columns else [])
    return np.concatenate(cols).astype(float)


def observe(machine: Machine, m: Measurement, name: str = "") -> Observation:
    """The diagnosis view of one file (NcppError for files it cannot use)."""
    if m.instrument not in USED:
        raise NcppError(f"diagnose uses ballbar, laser and comparator files, not {m.instrument}", m.at())
    fp = machine.replace(tool=np.add(machine.tool, m.offset_mm))
    name = name or m.source
    if m.instrument == "ballbar":
        return _ballbar(fp, m, name)
    return _positioning(fp, m, name)


# ---------------------------------------------------------------- ball bar
def _ballbar(machine: Machine, m: Measurement, name: str) -> Observation:
    if m.radius_mm is None:
        raise NcppError("ballbar file without radius_mm", m.at())
    circular_test(m)  # refuses what analyze refuses (fewer than three points a direction)
    centre = m.center_mm if m.center_mm is not None else np.zeros(3)
    radius = m.radius_mm
    first, second = (AXES.index(a) for a in PLANES[m.plane])
    theta = np.radians(m["angle_deg"])
    directions = np.asarray(m["direction"])
    parts, groups = [], np.zeros(len(m), dtype=int)
    for g, d in enumerate(dict.fromkeys(directions)):
        rows = np.flatnonzero(directions == d)
        groups[rows] = g
        sign = 1.0 if d == "CCW" else -1.0
        n_rev = int(round(360.0 / BALLBAR_STEP_DEG))
        n_over = int(round(FEED_IN_DEG / BALLBAR_STEP_DEG))
        index = np.arange(-n_over, n_rev + n_over + 1)
        angle = sign * index * BALLBAR_STEP_DEG
        P = np.tile(centre, (len(index), 1))
        P[:, first] += radius * np.cos(np.radians(angle))
        P[:, second] += radius * np.sin(np.radians(angle))
        unit = (P - centre) / radius
        data = (index >= 0) & (index < n_rev)
        at = np.asarray(m["angle_deg"])[rows]
        ring, order = angle[data] % 360.0, None
        order = np.argsort(ring)

        def read(delta: NDArray, unit=unit, data=data, ring=ring, order=order, at=at) -> NDArray:
            radial = np.einsum("ij,ij->i", unit, delta)[data] * 1e3
            return np.interp(at, ring[order], radial[order], period=360.0)

        parts.append(Part(Trajectory(P, m.feed_mm_min or 1000.0), rows, read))
    nuisance = np.column_stack([np.ones(len(m)), np.cos(theta), np.sin(theta)])
    return Observation(
        m, readings_of(m), nuisance, tuple(parts), machine, groups,
        np.asarray(m["angle_deg"], dtype=float), directions, name=name,
    )  # fmt: skip


# ------------------------------------------------------------- positioning
def _component_index(m: Measurement) -> tuple[list[int], bool, str | None]:
    """Which deviation components the file reads, whether they are angles, and
    for angles the ISO component name."""
    axis = m.axis or "X"
    if m.instrument == "comparator":
        transverse = (m.text("transverse") or {"X": "Y", "Y": "X", "Z": "X"}[axis]).upper()
        return (
            [AXES.index(axis), AXES.index(transverse)][: 2 if "transverse_um" in m.columns else 1],
            False,
            None,
        )
    q = m.quantity
    if q == "position":
        return [AXES.index(axis)], False, None
    if q.startswith("straightness_"):
        return [AXES.index(q.removeprefix("straightness_").upper())], False, None
    from ncpp.instruments.forward import reading_component

    name = (m.text("component") or reading_component(axis, q)).upper()
    return ["ABC".index(name[1])], True, name


def _positioning(machine: Machine, m: Measurement, name: str) -> Observation:
    axis = m.axis or "X"
    components, angular, component = _component_index(m)
    targets = np.unique(np.asarray(m["target_mm"], dtype=float))
    runs = int(np.max(m["run"]))
    both = set(m["direction"]) == {"+", "-"}
    traj, at, labels = iso230_2_cycle(
        axis, targets, runs, both, m.fixed, m.feed_mm_min or 1000.0, OVERTRAVEL_MM
    )
    key = {
        (round(float(t), 6), int(r), d): i for i, (t, r, d) in enumerate(labels)
    }  # float(t): numpy's round may differ
    sample = np.array([
        at[key[(round(float(t), 6), int(r), str(d))]] for t, r, d in zip(m["target_mm"], m["run"], m["direction"])
    ])  # fmt: skip
    n = len(m)
    rows_all = np.arange(n * len(components))
    k = AXES.index(axis)

    read: Callable[[Effect], NDArray] | Callable[[NDArray], NDArray]
    if angular:
        assert component is not None  # angles come with their ISO component name

        def read_angle(effect: Effect) -> NDArray:
            if not isinstance(effect, Angular) or effect.component[1] != component[1]:
                return np.zeros(n)
            i = AXES.index(effect.component[2])
            return effect.urad_per_m * 1e-3 * (traj.positions[sample, i] - effect.ref_mm)

        read = read_angle
    else:

        def read_deviation(delta: NDArray) -> NDArray:
            return np.concatenate([delta[sample, c] * 1e3 for c in components])

        read = read_deviation

    run = np.asarray(m["run"], dtype=int)
    target = np.asarray(m["target_mm"], dtype=float)
    blocks = []
    for c in components:
        if c == k and not angular:  # along the axis: one zero per run
            cols = np.column_stack([(run == r).astype(float) for r in np.unique(run)])
        elif angular:
            cols = np.ones((n, 1))
        else:  # across: offset and slope of the alignment
            span = max(np.ptp(target), 1.0)
            cols = np.column_stack([np.ones(n), (target - target.mean()) / span])
        blocks.append(cols)
    nuisance = np.zeros((n * len(components), sum(b.shape[1] for b in blocks)))
    col = 0
    for j, b in enumerate(blocks):
        nuisance[j * n : (j + 1) * n, col : col + b.shape[1]] = b
        col += b.shape[1]
    direction = np.asarray(m["direction"])
    groups = np.concatenate([j * 100000 + run * 10 + (direction == "+") for j in range(len(components))])
    repeat = np.concatenate([
        np.array([f"{j}|{t:g}|{d}" for t, d in zip(target, direction)]) for j in range(len(components))
    ])  # fmt: skip
    return Observation(
        m, readings_of(m), nuisance, (Part(traj, rows_all, read),), machine, groups,
        np.tile(target, len(components)), np.tile(direction, len(components)), repeat, angular, name,
    )  # fmt: skip


# ------------------------------------------------------------------- noise
def noise_level(obs: Observation, residual: NDArray) -> float:
    """Robust noise estimate (same unit as the readings) from the residual:
    scatter between repeated runs when there are any, else the second
    differences along each trace (MAD; a smooth misfit or a few steps barely
    move it)."""
    if obs.repeat_key is not None:
        keys, inverse, counts = np.unique(obs.repeat_key, return_inverse=True, return_counts=True)
        if np.any(counts > 1):
            means = np.bincount(inverse, residual) / counts
            dev = residual - means[inverse]
            dof = int(np.sum(counts - 1))
            return float(np.sqrt(np.sum(dev**2) / dof))
    d2 = []
    for g in np.unique(obs.groups):
        rows = np.flatnonzero(obs.groups == g)
        rows = rows[np.argsort(obs.position[rows], kind="stable")]
        if len(rows) >= 3:
            d2.append(np.diff(residual[rows], 2))
    if not d2:
        return float(np.std(residual)) or 1.0
    return float(1.4826 * np.median(np.abs(np.concatenate(d2))) / np.sqrt(6.0))
