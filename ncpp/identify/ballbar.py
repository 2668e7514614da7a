"""Ball bar → error components by regularised least squares (Rahman 2004, 4.8.4.5).

Rahman 2004 (M. Rahman, *Modeling and measurement of multi-axis machine tools to improve positioning
accuracy in a software way*, University of Oulu, 2004)
finds error components from ball-bar traces by trial and error;
here they are solved for, over all given files at once (planes, radii,
heights, centres, both directions, feeds).

Unknowns
--------
* Each error component of each axis the circles move (EXX, EYX, ..., ECZ) is
  a table over the tested range of its axis, linear between `knots` values
  (default 9; an axis seen at a few positions only, e.g. Z at two heights of
  XY circles, gets those positions as knots).  Gauge: a ball bar reads
  differences, so translation tables are 0 at their first knot, and
  straightness tables (EJK, J ≠ K) also at their last: the slope of a
  straightness is the squareness (ISO 230-1's convention).
* The reversal of each positioning table, (EKK+ − EKK−) at the same knots
  (written as ± tables).
* The squarenesses C0Y, B0Z, A0Z of the planes the circles span.
* Per file, set-up nuisances fitted always and never reported as machine
  errors: ball-bar length offset and centre offset in the plane (1, cos θ,
  sin θ) — `ncpp.diagnose.observations.observe`.

Solution
--------
Linearised through the forward model: the deviation at a point depends on
the component values at that point only, so one finite difference of
`Machine.deviation` per component (at each file's functional point, along the
simulated circle with its feed-in arcs) times the knot basis gives the
Jacobian column of every knot, read as the bar does (radial, interpolated to
the file's angles — the diagnosis's `Observation.parts`).  Residuals always
come from `predict_like` (the full forward model, effects of the base
included); a few chord (Gauss–Newton with fixed Jacobian) steps remove the
small nonlinearity.  Rows are weighted by each file's noise
(`noise_level`: second differences along the trace), the nuisances are
projected out, and

    min ‖A θ − b‖² + λ ‖D θ‖² + ε ‖S⁻¹ θ‖²

is solved, D the second differences of every table's knot values (a
dimensionless curvature over the tested travel), λ chosen by generalized
cross-validation, GCV(λ) = n·RSS/(n − tr H)², on a log grid via the
generalised eigenproblem of (DᵀD, AᵀA + εS⁻²).  The tiny ridge ε picks one
solution where the data and the penalty leave a choice; S weights angles 100×
harder than translations, so a combination only the sum of which is seen
(roll of X × lever vs straightness EYX from one height) goes to the
translation, as a laser fit without angle files would do.

Uncertainty and what cannot be separated
----------------------------------------
Covariance: s²·G AᵀA G with G = (AᵀA + λDᵀD + εS⁻²)⁻¹ and s² = RSS/(n − tr H)
in noise units (the regularisation bias is not in it).  The data cannot
separate a combination v (unit norm, µm/µrad) of the parameters when
‖A v‖ < 1/`resolution`: its standard uncertainty would exceed `resolution`
(default 1 µm or µrad).  Those directions (from the eigenvectors of AᵀA) are
grouped by the components they mix, and every knot mostly inside them is
reported "not determined" instead of with a number: e.g. a common scale of
all axes (the bar's length offset), EAX with EYX from XY circles at one
height, reversal from one direction only, out-of-plane straightness.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from itertools import combinations

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import eigh

from ncpp.diagnose.observations import Observation, noise_level, observe, predicted
from ncpp.errors import Location, NcppError
from ncpp.instruments.files import Measurement
from ncpp.machine.components import AXES, COMPONENTS, SQUARENESS_AXES, Polynomial, Table
from ncpp.machine.model import Machine

ANGLE_PRIORITY = 100.0  # ridge weight of angles relative to translations (see the docstring)
RIDGE = 1e-9  # ε relative to the mean diagonal of AᵀA
STEP = {"translation": 1e-3, "rotation": 1e-6}  # finite-difference step, mm / rad
SCALE = {"um": 1e-3, "urad": 1e-6}  # model unit per parameter unit


@dataclass(frozen=True)
class Block:
    """One unknown of the fit: a table's free knot values, or a squareness."""

    name: str  # "EXX", "EXX reversal", "C0Y"
    component: str  # ISO name it changes
    kind: str  # "table" | "reversal" | "squareness"
    knots: NDArray  # positions of all knot values (mm); empty for a squareness
    free: NDArray  # which knots are parameters (the others are held at 0)

    @property
    def size(self) -> int:
        return 1 if self.kind == "squareness" else len(self.free)

    @property
    def unit(self) -> str:
        return "urad" if self.kind == "squareness" or COMPONENTS[self.component].kind == "rotation" else "um"

    @property
    def axis(self) -> str:
        return COMPONENTS[self.component].axis if self.kind != "squareness" else ""

    def basis(self, positions: NDArray, directions: NDArray) -> NDArray:
        """(n, size): the change of the component at each point per unit parameter
        (model units); a squareness is a constant."""
        if self.kind == "squareness":
            return np.full((len(positions), 1), SCALE[self.unit])
        i = AXES.index(self.axis)
        eye = np.eye(len(self.knots))[:, self.free]
        hat = np.column_stack([np.interp(positions[:, i], self.knots, e) for e in eye.T])
        if self.kind == "reversal":  # + table gets +r/2, − table −r/2, standing: the mean
            hat = hat * (directions[:, i] / 2.0)[:, None]
        return hat * SCALE[self.unit]


@dataclass(frozen=True)
class Unobservable:
    """Parameters whose combination the data cannot fix."""

    components: tuple[str, ...]
    dimensions: int
    hint: str


@dataclass(frozen=True)
class FileFit:
    source: str
    setup: str
    noise_um: float
    rms_before_um: float  # measured − base model, set-up nuisances removed
    rms_after_um: float  # measured − fitted model, set-up nuisances removed


@dataclass(frozen=True)
class BallbarFit:
    machine: Machine
    blocks: tuple[Block, ...]
    values: NDArray  # parameters, µm / µrad
    uncertainty: NDArray  # standard uncertainties; NaN where not determined
    unobservable: tuple[Unobservable, ...]
    files: tuple[FileFit, ...]
    smoothing: float  # λ
    effective_parameters: float  # tr H
    rms_um: float  # all files after the fit
    by_gcv: bool = True  # λ chosen by GCV (else given)

    def block(self, name: str) -> tuple[Block, NDArray, NDArray]:
        """A block with its values and uncertainties."""
        k = 0
        for b in self.blocks:
            if b.name == name:
                return b, self.values[k : k + b.size], self.uncertainty[k : k + b.size]
            k += b.size
        raise KeyError(name)


# ----------------------------------------------------------------- unknowns
def _knots(obs: Sequence[Observation], axis: str, count: int) -> NDArray | None:
    i = AXES.index(axis)
    values = np.unique(
        np.round(np.concatenate([p.trajectory.positions[:, i] for o in obs for p in o.parts]), 6)
    )
    if len(values) < 2:
        return None
    return values if len(values) <= count else np.linspace(values[0], values[-1], count)


def unknowns(obs: Sequence[Observation], count: int = 9, fixed: Sequence[str] = ()) -> list[Block]:
    """The blocks the ball-bar files can speak to: components of the moved axes
    (minus `fixed`), reversals of their positioning, squareness of the planes."""
    blocks: list[Block] = []
    moved = []
    for axis in AXES:
        knots = _knots(obs, axis, count)
        if knots is None:
            continue
        moved.append(axis)
        every = np.arange(len(knots))
        for name, info in COMPONENTS.items():
            if info.axis != axis or name in fixed:
                continue
            if info.kind == "rotation":
                free = every
            elif name == f"E{axis}{axis}":
                free = every[1:]
            else:
                free = every[1:-1]
            if len(free):
                blocks.append(Block(name, name, "table", knots, free))
            if name == f"E{axis}{axis}":
                blocks.append(Block(f"{name} reversal", name, "reversal", knots, every))
    for name, (axis, _) in SQUARENESS_AXES.items():
        other = "X" if name != "A0Z" else "Y"
        if axis in moved and other in moved and name not in fixed:
            blocks.append(Block(name, name, "squareness", np.zeros(0), np.zeros(0, dtype=int)))
    return blocks


def _shifted(machine: Machine, name: str, h: float) -> Machine:
    """`machine` with a constant h (model units) added to a component or squareness."""
    if name in SQUARENESS_AXES:
        return machine.with_components(**{name: machine.squareness[name] + h})
    comp = machine.component(name)
    if comp is None:
        new: Table | Polynomial = Polynomial((h,))
    elif isinstance(comp, Polynomial):
        new = Polynomial((comp.coefficients[0] + h, *comp.coefficients[1:]), comp.reference, comp.limits)
    else:
        minus = None if comp.values_minus is None else tuple(v + h for v in comp.values_minus)
        new = Table(comp.positions, tuple(v + h for v in comp.values), minus, comp.interpolation)
    return machine.with_components(**{name: new})


def jacobian(obs: Sequence[Observation], blocks: Sequence[Block]) -> NDArray:
    """Readings (µm) per unit parameter (µm, µrad), files stacked (see the docstring)."""
    n = sum(len(o) for o in obs)
    J = np.zeros((n, sum(b.size for b in blocks)))
    start = 0
    for o in obs:
        for part in o.parts:
            P, dirs = part.trajectory.positions, part.trajectory.directions()
            rows = start + np.asarray(part.rows)
            sens: dict[str, NDArray] = {}
            col = 0
            for b in blocks:
                if b.component not in sens:
                    kind = "rotation" if b.unit == "urad" else "translation"
                    h = STEP[kind]
                    up = _shifted(o.machine, b.component, h).deviation(P, dirs)
                    down = _shifted(o.machine, b.component, -h).deviation(P, dirs)
                    sens[b.component] = (up - down) / (2 * h)
                basis = b.basis(P, dirs)
                for j in range(b.size):
                    J[rows, col + j] = part.read(sens[b.component] * basis[:, j : j + 1])  # type: ignore[operator]
                col += b.size
        start += len(o)
    return J


def penalty(blocks: Sequence[Block]) -> NDArray:
    """Second differences of every table's knot values (held knots are 0)."""
    rows, col, p = [], 0, sum(b.size for b in blocks)
    for b in blocks:
        if b.kind != "squareness" and len(b.knots) >= 3:
            m = len(b.knots)
            D2 = (np.eye(m)[2:] - 2 * np.eye(m)[1:-1] + np.eye(m)[:-2])[:, b.free]
            full = np.zeros((m - 2, p))
            full[:, col : col + b.size] = D2
            rows.append(full)
        col += b.size
    return np.vstack(rows) if rows else np.zeros((0, p))


def apply(machine: Machine, blocks: Sequence[Block], theta: NDArray) -> Machine:
    """`machine` with the fitted corrections added to its components."""
    updates: dict[str, object] = {}
    tables: dict[str, tuple[NDArray, dict[str, NDArray]]] = {}  # component: knots, "table" and "reversal"
    col = 0
    for b in blocks:
        values = theta[col : col + b.size] * SCALE[b.unit]
        col += b.size
        if b.kind == "squareness":
            updates[b.name] = machine.squareness[b.name] + float(values[0])
            continue
        full = np.zeros(len(b.knots))
        full[b.free] = values
        _, corrections = tables.setdefault(b.component, (b.knots, {"table": np.zeros(len(b.knots))}))
        corrections[b.kind] = full
    for name, (knots, corrections) in tables.items():
        updates[name] = _combined(
            machine.component(name), knots, corrections["table"], corrections.get("reversal")
        )
    return machine.with_components(**updates)  # type: ignore[arg-type]


def _combined(base, knots: NDArray, values: NDArray, reversal: NDArray | None) -> Table:
    """Base component + linear correction, as one table on the union of their
    positions (linear between them: the correction is piecewise linear)."""
    grid = knots if not isinstance(base, Table) else np.union1d(knots, base.positions)
    correction = np.interp(grid, knots, values)
    half = np.zeros(len(grid)) if reversal is None else np.interp(grid, knots, reversal) / 2.0
    plus = (0.0 if base is None else base(grid, 1.0)) + correction + half
    minus = (0.0 if base is None else base(grid, -1.0)) + correction - half
    directional = reversal is not None or getattr(base, "directional", False)
    return Table(tuple(grid), tuple(plus), tuple(minus) if directional else None, "linear")


# -------------------------------------------------------------------- solve
@dataclass(frozen=True)
class _Regularised:
    W: NDArray  # generalised eigenvectors: Wᵀ B W = I, Wᵀ DᵀD W = diag(mu)
    mu: NDArray
    AW: NDArray

    def solve(self, b: NDArray, lam: float) -> tuple[NDArray, NDArray]:
        f = 1.0 / (1.0 + lam * self.mu)
        c = self.AW.T @ b
        return self.W @ (f * c), f

    def gcv(self, b: NDArray, n: int) -> float:
        """λ minimising GCV(λ) = n·RSS/(n − tr H)² on a log grid."""
        norms = np.sum(self.AW**2, axis=0)
        positive = self.mu[self.mu > 1e-12 * max(self.mu.max(), 1e-300)]
        if len(positive) == 0:
            return 0.0
        grid = np.logspace(np.log10(1 / positive.max()) - 2, np.log10(1 / positive.min()) + 2, 121)
        c = self.AW.T @ b
        best = (np.inf, 0.0)
        for lam in grid:
            f = 1.0 / (1.0 + lam * self.mu)
            rss = float(np.sum((b - self.AW @ (f * c)) ** 2))
            trace = float(f @ norms)
            score = n * rss / max(n - trace, 1.0) ** 2
            best = min(best, (score, float(lam)))
        return best[1]


def _regularised(A: NDArray, D: NDArray, blocks: Sequence[Block]) -> _Regularised:
    AtA = A.T @ A
    weight = np.concatenate(
        [
            np.full(b.size, ANGLE_PRIORITY if b.unit == "urad" and b.kind != "squareness" else 1.0)
            for b in blocks
        ]
    )
    ridge = RIDGE * max(float(np.mean(np.diag(AtA))), 1e-300)
    mu, W = eigh(D.T @ D, AtA + ridge * np.diag(weight**2))
    return _Regularised(W, np.clip(mu, 0.0, None), A @ W)


def _profiled(obs: Sequence[Observation], M: NDArray, sigma: Sequence[float]) -> NDArray:
    """Rows of M (stacked files) whitened and with each file's nuisances projected out."""
    out, start = np.empty_like(M), 0
    for o, s in zip(obs, sigma):
        rows = slice(start, start + len(o))
        Q, _ = np.linalg.qr(o.nuisance)
        block = M[rows]
        out[rows] = (block - Q @ (Q.T @ block)) / s
        start += len(o)
    return out


def _residuals(machine: Machine, obs: Sequence[Observation]) -> NDArray:
    return np.concatenate([o.y - predicted(machine, o.measurement) for o in obs])


def _rms_per_file(obs: Sequence[Observation], r: NDArray) -> list[float]:
    flat = _profiled(obs, r[:, None], [1.0] * len(obs))[:, 0]
    out, start = [], 0
    for o in obs:
        out.append(float(np.sqrt(np.mean(flat[start : start + len(o)] ** 2))))
        start += len(o)
    return out


def fit_ballbar(
    machine: Machine,
    measurements: Sequence[Measurement],
    *,
    knots: int = 9,
    fixed: Sequence[str] = (),
    smoothing: float | None = None,
    resolution: float = 1.0,
    iterations: int = 4,
) -> BallbarFit:
    """Error components of `machine` refined from ball-bar files (see the module docstring).

    knots: values per table; fixed: components not to touch (given by other
    files); smoothing: λ (None: by GCV); resolution: µm or µrad — a combination
    known no better than this is reported as not separable."""
    for m in measurements:
        if m.instrument != "ballbar":
            raise NcppError(f"fit_ballbar takes ball-bar files, not {m.instrument}", m.at())
    if knots < 2:
        raise NcppError("--knots must be at least 2", Location("ncpp fit"))
    if smoothing is not None and not 0 < smoothing < np.inf:
        raise NcppError(f"--smoothing must be a positive number, not {smoothing!r}", Location("ncpp fit"))
    obs = [observe(machine, m) for m in measurements]
    _check_knots(measurements, knots)
    blocks = unknowns(obs, knots, fixed)
    if not blocks:
        raise NcppError("the ball-bar files move no axis whose errors could be fitted", measurements[0].at())
    r0 = _residuals(machine, obs)
    before = _rms_per_file(obs, r0)
    sigma, start = [], 0
    for o in obs:
        sigma.append(max(noise_level(o, r0[start : start + len(o)]), 1e-3))
        start += len(o)
    A = _profiled(obs, jacobian(obs, blocks), sigma)
    D = penalty(blocks)
    reg = _regularised(A, D, blocks)
    n = len(A) - sum(o.nuisance.shape[1] for o in obs)
    theta = np.zeros(A.shape[1])
    current, r = machine, r0
    lam = smoothing
    for _ in range(iterations):
        rhs = _profiled(obs, r[:, None], sigma)[:, 0] + A @ theta
        if lam is None:
            lam = reg.gcv(rhs, n)
        new, f = reg.solve(rhs, lam)
        change = float(np.max(np.abs(new - theta))) if len(theta) else 0.0
        theta = new
        current = apply(machine, blocks, theta)
        r = _residuals(current, obs)
        if change < 1e-3:
            break
    assert lam is not None
    # Statistics in noise units at the solution.
    e = _profiled(obs, r[:, None], sigma)[:, 0]
    _check_converged(e, _profiled(obs, r0[:, None], sigma)[:, 0], lam, smoothing is None)
    trace = float(f @ np.sum(reg.AW**2, axis=0))
    s2 = float(e @ e) / max(n - trace, 1.0)
    G = reg.W * f  # θ = G (AW)ᵀ b
    cov = s2 * (G @ (reg.AW.T @ reg.AW) @ G.T)
    null, groups = _unobservable(A, blocks, resolution)
    u = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    u[null > 0.5] = np.nan
    after = _rms_per_file(obs, r)
    files = tuple(
        FileFit(o.name, _setup(o.measurement), s, b0, a0) for o, s, b0, a0 in zip(obs, sigma, before, after)
    )
    flat = _profiled(obs, r[:, None], [1.0] * len(obs))[:, 0]
    # A table no value of which the data fix is not written (its min-norm values are ~0 anyway).
    written, col = np.zeros(len(theta), dtype=bool), 0
    for b in blocks:
        written[col : col + b.size] = bool(np.any(null[col : col + b.size] <= 0.5))
        col += b.size
    kept = [b for b, s in zip(blocks, _slices(blocks)) if written[s].all()]
    fitted = _named(apply(machine, kept, theta[written]), blocks, null)
    return BallbarFit(
        fitted,
        tuple(blocks),
        theta,
        u,
        groups,
        files,
        float(lam),
        trace,
        float(np.sqrt(np.mean(flat**2))),
        by_gcv=smoothing is None,
    )


def _check_knots(measurements: Sequence[Measurement], knots: int) -> None:
    """A table cannot have more values than the positions its axis is read at (1 µm
    apart): the values between readings would be set by the penalty alone."""
    read: dict[str, set[float]] = {}
    for m in measurements:
        centre = m.center_mm if m.center_mm is not None else np.zeros(3)
        theta = np.radians(m["angle_deg"])
        for axis, along in zip(m.plane_axes, (np.cos(theta), np.sin(theta))):
            read.setdefault(axis, set()).update(np.round(centre[AXES.index(axis)] + m.radius_mm * along, 3))
    most = max(len(positions) for positions in read.values())
    if knots > most:
        raise NcppError(
            f"--knots {knots}: the ball-bar files read an axis at {most} positions at most; "
            f"a table cannot have more values than that", Location("ncpp fit"),
        )  # fmt: skip


def _check_converged(after: NDArray, before: NDArray, lam: float, by_gcv: bool) -> None:
    """A least-squares fit explains the files at least as well as no change (up to a
    little nonlinearity); worse, the steps diverged: λ too small to hold the tables."""
    if after @ after <= 1.01 * (before @ before):
        return
    hint = "" if by_gcv else " (leave out --smoothing to choose λ by GCV)"
    raise NcppError(
        f"the ball-bar fit diverged: its residual is {np.sqrt(np.mean(after**2)):.3g} noise units, "
        f"{np.sqrt(np.mean(before**2)):.3g} without it; smoothing λ = {lam:.3g} is too small{hint}",
        Location("ncpp fit"),
    )


def _slices(blocks: Sequence[Block]) -> list[slice]:
    out, col = [], 0
    for b in blocks:
        out.append(slice(col, col + b.size))
        col += b.size
    return out


def _named(machine: Machine, blocks: Sequence[Block], null: NDArray) -> Machine:
    meta = dict(machine.meta)
    fitted = dict(meta.get("fitted", {}))
    col = 0
    for b in blocks:
        determined = int(np.sum(null[col : col + b.size] <= 0.5))
        col += b.size
        if determined and b.kind != "reversal":
            fitted[b.component] = (
                f"ball bar, regularised least squares ({determined} of {b.size} values determined)"
            )
    meta["fitted"] = fitted
    return machine.replace(meta=meta)


def _setup(m: Measurement) -> str:
    centre = ",".join(f"{v:g}" for v in (m.center_mm if m.center_mm is not None else np.zeros(3)))
    dirs = "/".join(dict.fromkeys(m["direction"]))
    return f"{m.plane} R{m.radius_mm:g} at {centre} {dirs} F{m.feed_mm_min or 1000:g}"


# ---------------------------------------------------------- observability
def _unobservable(
    A: NDArray, blocks: Sequence[Block], resolution: float
) -> tuple[NDArray, tuple[Unobservable, ...]]:
    """Per parameter, the share of it in directions the data cannot fix (diag
    of the projector on them), and those directions explained by the smallest
    sets of blocks: single blocks first, then pairs, then triples, each set
    counted for the null directions its predecessors do not already span."""
    AtA = A.T @ A
    floor = max(1.0 / resolution**2, 1e-14 * max(float(np.max(np.diag(AtA))), 1e-300))
    evals, V = np.linalg.eigh(AtA)
    V0 = V[:, evals < floor]
    share = np.sum(V0**2, axis=1)
    slices, col = [], 0
    for b in blocks:
        slices.append(np.arange(col, col + b.size))
        col += b.size
    involved = [i for i, s in enumerate(slices) if share[s].sum() > 1e-6]
    explained = np.zeros((len(share), 0))
    groups: list[Unobservable] = []
    for size in (1, 2, 3):
        if explained.shape[1] >= V0.shape[1]:
            break
        for members in combinations(involved, size):
            cols = np.concatenate([slices[i] for i in members])
            e, U = np.linalg.eigh(AtA[np.ix_(cols, cols)])
            if not np.any(e < floor):
                continue
            null = np.zeros((len(share), int(np.sum(e < floor))))
            null[cols] = U[:, e < floor]
            if explained.shape[1]:
                null = null - explained @ (explained.T @ null)
            u, sv, _ = np.linalg.svd(null, full_matrices=False)
            new = u[:, sv > 1e-6]
            if new.shape[1] == 0:
                continue
            explained = np.column_stack([explained, new])
            chosen = [blocks[i] for i in members]
            groups.append(Unobservable(tuple(b.name for b in chosen), new.shape[1], _hint(chosen, new, cols)))
    if explained.shape[1] < V0.shape[1]:
        rest = V0 - explained @ (explained.T @ V0)
        names = tuple(blocks[i].name for i in involved if np.linalg.norm(rest[slices[i]]) > 1e-3)
        groups.append(
            Unobservable(names, V0.shape[1] - explained.shape[1], "combinations of four or more of these")
        )
    return share, tuple(groups)


def _hint(blocks: Sequence[Block], null: NDArray, cols: NDArray) -> str:
    kinds = {b.kind for b in blocks}
    if kinds == {"reversal"}:
        return "reversal needs both directions of travel (CW and CCW)"
    if len(blocks) == 1:
        b = blocks[0]
        if null.shape[1] >= b.size:
            return "does not change the bar length in any tested set-up"
        v = null[cols, 0]
        if null.shape[1] == 1 and b.unit == "urad" and np.ptp(v) < 0.05 * np.max(np.abs(v)):
            return (
                "its mean: a constant tilt turns the whole path rigidly (values are given about their mean)"
            )
        return f"{null.shape[1]} shape(s) of it do not change the bar length"
    if kinds == {"table"} and all(b.component[1] == b.axis for b in blocks):
        return (
            "a common scale of these axes is the ball bar's length offset: a laser file of one axis fixes it"
        )
    units = {b.unit for b in blocks if b.kind == "table"}
    if units == {"um", "urad"}:
        return "an angular error seen through one lever arm looks like a translation: another height or tool offset separates them (given to the translation)"
    return "only their combination changes the bar length in the tested set-ups"


# ----------------------------------------------------------------- account
def account(fit: BallbarFit) -> str:
    """The printed account: files, each parameter ± uncertainty, what cannot be separated."""
    lines = [f"ball-bar fit: {len(fit.files)} file(s), {sum(b.size for b in fit.blocks)} parameters "
             f"({fit.effective_parameters:.1f} effective), smoothing λ = {fit.smoothing:.3g} "
             f"({'GCV' if fit.by_gcv else 'given'}), "
             f"rms after {fit.rms_um:.3f} µm"]  # fmt: skip
    lines.append(
        "  file                                  set-up                               noise   rms before → after (µm)"
    )
    for f in fit.files:
        lines.append(
            f"  {f.source[-36:]:<36}  {f.setup:<36} {f.noise_um:5.2f}   {f.rms_before_um:7.3f} → {f.rms_after_um:.3f}"
        )
    lines.append("  parameters (value ± standard uncertainty; n.d. = not determined by these data;")
    lines.append("  combinations listed under 'cannot separate' are set by the minimum-norm rule):")
    for b in fit.blocks:
        _, values, u = fit.block(b.name)
        unit = "µrad" if b.unit == "urad" else "µm"
        if b.kind == "squareness":
            text = "n.d." if np.isnan(u[0]) else f"{values[0]:.2f} ± {u[0]:.2f}"
            lines.append(f"    {b.name:<13} {text} {unit} (= µm/m)")
            continue
        cells = []
        for pos, v, s in zip(b.knots[b.free], values, u):
            cells.append(f"{pos:g}: " + ("n.d." if np.isnan(s) else f"{v:.2f}±{s:.2f}"))
        lines.append(f"    {b.name:<13} {unit:<4} " + ", ".join(cells))
    if fit.unobservable:
        lines.append("  cannot separate:")
        for g in fit.unobservable:
            lines.append(f"    {' + '.join(g.components)} ({g.dimensions} combination(s)): {g.hint}")
    else:
        lines.append("  cannot separate: nothing (every parameter is determined)")
    return "\n".join(lines)
