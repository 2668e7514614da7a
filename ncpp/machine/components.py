"""The 21 geometric error components of a three-axis machine (ISO 230-1).

Naming (ISO 230-1): ``E`` + direction of the error + the axis that moves.

============  ==========================  =======================  ===========
ISO name      meaning                     Rahman 2004 (aliases)    file unit
============  ==========================  =======================  ===========
EXX EYY EZZ   positioning of X, Y, Z      xx yy zz, Xxx Yyy Zzz    µm
EYX EZX       straightness of X in Y, Z   yx zx, Xyx Xzx           µm
EXY EZY       straightness of Y in X, Z   xy zy, Yxy Yzy           µm
EXZ EYZ       straightness of Z in X, Y   xz yz, Zxz Zyz           µm
EAX EBX ECX   roll, pitch, yaw of X       ax bx cx, Xax Xbx Xcx    µrad
EAY EBY ECY   pitch, roll, yaw of Y       ay by cy, Yay Yby Ycy    µrad
EAZ EBZ ECZ   pitch, yaw, roll of Z       az bz cz, Zaz Zbz Zcz    µrad
C0Y           squareness Y to X (about Z) kxy, kyx, EC0Y           µrad (= µm/m)
B0Z           squareness Z to X (about Y) kxz, kzx, EB0Z           µrad (= µm/m)
A0Z           squareness Z to Y (about X) kyz, kzy, EA0Z           µrad (= µm/m)
============  ==========================  =======================  ===========

Rahman 2004 (M. Rahman, *Modeling and measurement of multi-axis machine tools
to improve positioning accuracy in a software way*, University of Oulu, 2004)
writes a linear error as <error direction><axis> (``yx``: Y-direction error of
the X axis), optionally prefixed by the axis
(``Xyx``), and an angular error as <rotation><axis> (``bx``: rotation about Y
of the X axis); ``kij`` is the squareness of axes i and j.  The aliases map
those spellings one to one and with the same sign; a file written by ncpp
always uses the ISO names.

Signs: actual minus nominal, of the tool relative to the workpiece (see
`ncpp.machine.chain`).  Angles are small rotations about +X (A), +Y (B),
+Z (C), right-hand rule.  Squareness is the fixed rotation of the *direction*
of an axis's motion: X is the reference, Y is turned about Z by C0Y, Z is
turned about X by A0Z and about Y by B0Z.  So C0Y > 0 opens the X–Y angle
beyond 90° and Y motion carries δx = −C0Y·y; B0Z gives δx = +B0Z·z;
A0Z gives δy = −A0Z·z.

Each component is a function of its own axis position: a `Table` (linear or
smooth, i.e. monotone cubic PCHIP, interpolation; optional separate values
for travel in the − direction, for reversal error) or a `Polynomial`.  Values
are in model units, mm and rad.  Outside the tabulated range a table holds
its end values (no extrapolation: an error map is a measurement, and
extrapolating a slope beyond it invents errors).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

AXES = "XYZ"
ROTATIONS = "ABC"
SQUARENESS = ("C0Y", "B0Z", "A0Z")
Interpolation = Literal["linear", "smooth"]  # of a `Table`: straight lines, or monotone cubic (PCHIP)


@dataclass(frozen=True)
class ComponentInfo:
    """What an ISO name means: the axis it depends on and what it moves."""

    name: str
    axis: str  # the axis whose position the error depends on
    kind: Literal["translation", "rotation"]
    index: int  # 0, 1, 2: the x/y/z direction (translation) or A/B/C axis (rotation)

    @property
    def unit(self) -> str:
        return "um" if self.kind == "translation" else "urad"


def _component_table() -> dict[str, ComponentInfo]:
    table = {}
    for axis in AXES:
        for i, d in enumerate(AXES):
            table[f"E{d}{axis}"] = ComponentInfo(f"E{d}{axis}", axis, "translation", i)
        for i, r in enumerate(ROTATIONS):
            table[f"E{r}{axis}"] = ComponentInfo(f"E{r}{axis}", axis, "rotation", i)
    return table


COMPONENTS: dict[str, ComponentInfo] = _component_table()

# Squareness: (axis whose direction is turned, rotation index A/B/C).
SQUARENESS_AXES: dict[str, tuple[str, int]] = {"C0Y": ("Y", 2), "B0Z": ("Z", 1), "A0Z": ("Z", 0)}


def _thesis_table() -> dict[str, str]:
    names = {}
    for iso, info in COMPONENTS.items():
        letter = AXES[info.index] if info.kind == "translation" else ROTATIONS[info.index]
        short = f"{letter.lower()}{info.axis.lower()}"
        names[short] = iso
        names[f"{info.axis}{short}"] = iso
    for iso, pair in (("C0Y", "xy"), ("B0Z", "xz"), ("A0Z", "yz")):
        names[f"k{pair}"] = names[f"k{pair[::-1]}"] = iso
        names[f"E{iso}"] = iso
    return names


THESIS_NAMES: dict[str, str] = _thesis_table()


def canonical_name(name: str) -> str:
    """The ISO name for an ISO or Rahman 2004 spelling; ValueError if unknown."""
    if name in COMPONENTS or name in SQUARENESS:
        return name
    if name.upper() in COMPONENTS or name.upper() in SQUARENESS:
        return name.upper()
    if name in THESIS_NAMES:
        return THESIS_NAMES[name]
    raise ValueError(
        f"unknown error component {name!r}; use an ISO 230-1 name "
        f"(EXX, EYX, ..., EAX, EBX, ECX, ..., C0Y, B0Z, A0Z) or a thesis name (xx, yx, ax, kxy, ...)"
    )


def _floats(values: ArrayLike, what: str) -> tuple[float, ...]:
    arr = np.asarray(values, dtype=float).ravel()
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must be finite numbers")
    return tuple(float(v) for v in arr)


def _select(direction: ArrayLike | None, plus: NDArray, minus: NDArray) -> NDArray:
    """Per-point choice: + table for d > 0, − table for d < 0, their mean when
    the direction is unknown (None) or the axis stands (0)."""
    return _chosen(_signs(direction), plus, minus)


def _signs(direction: ArrayLike | None) -> tuple[NDArray, NDArray] | None:
    """(d > 0, d < 0) of travel directions, read once for every table of an axis."""
    if direction is None:
        return None
    d = np.asarray(direction)
    return d > 0, d < 0


def _chosen(signs: tuple[NDArray, NDArray] | None, plus: NDArray, minus: NDArray) -> NDArray:
    mean = 0.5 * (plus + minus)
    if signs is None:
        return mean
    forward, backward = signs
    return np.where(forward, plus, np.where(backward, minus, mean))


@dataclass(frozen=True)
class Table:
    """Error values tabulated along an axis (model units: mm or rad)."""

    positions: tuple[float, ...]
    values: tuple[float, ...]
    values_minus: tuple[float, ...] | None = None  # travel in the − direction
    interpolation: Interpolation = "linear"

    def __post_init__(self) -> None:
        object.__setattr__(self, "positions", _floats(self.positions, "positions"))
        object.__setattr__(self, "values", _floats(self.values, "values"))
        if self.values_minus is not None:
            object.__setattr__(self, "values_minus", _floats(self.values_minus, "minus values"))
        pos = np.asarray(self.positions)
        if len(pos) < 1:
            raise ValueError("a table needs at least one position")
        if np.any(np.diff(pos) <= 0):
            raise ValueError("table positions must be strictly increasing")
        for vals, what in ((self.values, "values"), (self.values_minus, "minus values")):
            if vals is not None and len(vals) != len(pos):
                raise ValueError(f"{len(vals)} {what} for {len(pos)} positions")
        if self.interpolation not in ("linear", "smooth"):
            raise ValueError(f"interpolation must be 'linear' or 'smooth', not {self.interpolation!r}")

    @property
    def directional(self) -> bool:
        return self.values_minus is not None

    @cached_property
    def _curves(self) -> tuple:
        return tuple(self._curve(v) for v in (self.values, self.values_minus) if v is not None)

    def _curve(self, values: tuple[float, ...]):
        x, y = np.asarray(self.positions), np.asarray(values)
        if self.interpolation == "linear" or len(x) < 3:
            return lambda p: np.interp(p, x, y)  # np.interp holds the end values
        c = pchip_pieces(x, y)

        def spline(p: NDArray) -> NDArray:
            p = np.clip(p, x[0], x[-1])
            i = np.clip(np.searchsorted(x, p, side="right") - 1, 0, len(x) - 2)
            s = p - x[i]
            return ((c[i, 0] * s + c[i, 1]) * s + c[i, 2]) * s + c[i, 3]

        return spline

    def __call__(self, positions: ArrayLike, direction: ArrayLike | None = None) -> NDArray:
        p = np.asarray(positions, dtype=float)
        curves = self._curves
        if len(curves) == 1:
            return curves[0](p)
        return _select(direction, curves[0](p), curves[1](p))

    def scaled(self, factor: float) -> Table:
        """The same table with values multiplied (unit conversion, sign flip)."""
        values = _floats(np.multiply(self.values, factor), "values")
        minus = self.values_minus
        if minus is not None:
            minus = _floats(np.multiply(minus, factor), "minus values")
        return Table(self.positions, values, minus, self.interpolation)


@dataclass(frozen=True)
class Polynomial:
    """sum_i c_i·(pos − reference)^i; c_i in model units per mm^i.

    `limits` (lo, hi) optionally holds the value constant outside [lo, hi],
    like a table's end values."""

    coefficients: tuple[float, ...]
    reference: float = 0.0
    limits: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "coefficients", _floats(self.coefficients, "coefficients"))
        object.__setattr__(self, "reference", float(self.reference))
        if not self.coefficients:
            raise ValueError("a polynomial needs at least one coefficient")
        if self.limits is not None:
            lo, hi = _floats(self.limits, "limits")
            if not lo < hi:
                raise ValueError("polynomial limits must be [lo, hi] with lo < hi")
            object.__setattr__(self, "limits", (lo, hi))

    directional = False

    def __call__(self, positions: ArrayLike, direction: ArrayLike | None = None) -> NDArray:
        p = np.asarray(positions, dtype=float)
        if self.limits is not None:
            p = np.clip(p, *self.limits)
        # np.polyval wants the highest power first.
        return np.polyval(self.coefficients[::-1], p - self.reference)

    def scaled(self, factor: float) -> Polynomial:
        coefficients = _floats(np.multiply(self.coefficients, factor), "coefficients")
        return Polynomial(coefficients, self.reference, self.limits)


Component = Table | Polynomial


# ------------------------------------------------------------ fast evaluation
def _cubic_pieces(table: Table, values: tuple[float, ...]) -> tuple[NDArray, NDArray]:
    """Breakpoints x (m,) and per-interval cubic coefficients (m−1, 4), highest
    power first in (p − x_i): the same curve `Table.__call__` evaluates."""
    x, y = np.asarray(table.positions), np.asarray(values)
    if len(x) == 1:
        return np.array([x[0], x[0] + 1.0]), np.array([[0.0, 0.0, 0.0, y[0]]])
    if table.interpolation == "linear" or len(x) < 3:
        slope = np.diff(y) / np.diff(x)
        zeros = np.zeros_like(slope)
        return x, np.column_stack([zeros, zeros, slope, y[:-1]])
    return x, pchip_pieces(x, y)


def pchip_pieces(x: NDArray, y: NDArray) -> NDArray:
    """(m−1, 4) cubic coefficients, highest power first in (p − x_i), of the
    shape-preserving PCHIP interpolant through (x, y), m ≥ 3.

    The same curve as scipy.interpolate.PchipInterpolator (Fritsch–Carlson
    slopes, Moler's one-sided ends; a test compares them), computed here
    because importing scipy.interpolate costs every `ncpp` run ~0.6 s."""
    h = np.diff(x)
    m = np.diff(y) / h
    slopes = np.zeros_like(y)
    w1, w2 = 2 * h[1:] + h[:-1], h[1:] + 2 * h[:-1]
    flat = (np.sign(m[1:]) != np.sign(m[:-1])) | (m[1:] == 0) | (m[:-1] == 0)
    with np.errstate(divide="ignore", invalid="ignore"):
        mean = (w1 / m[:-1] + w2 / m[1:]) / (w1 + w2)  # weighted harmonic mean of the slopes
    slopes[1:-1] = np.where(flat, 0.0, 1.0 / np.where(flat, 1.0, mean))
    slopes[0] = _pchip_end(h[0], h[1], m[0], m[1])
    slopes[-1] = _pchip_end(h[-1], h[-2], m[-1], m[-2])
    t = (slopes[:-1] + slopes[1:] - 2 * m) / h
    return np.column_stack([t / h, (m - slopes[:-1]) / h - t, slopes[:-1], y[:-1]])


def _pchip_end(h0: float, h1: float, m0: float, m1: float) -> float:
    """One-sided three-point slope at an end, kept shape-preserving."""
    d = ((2 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > 3.0 * abs(m0):
        return 3.0 * m0
    return d


def _refine(x: NDArray, c: NDArray, grid: NDArray) -> NDArray:
    """Re-expand a piecewise cubic on a finer breakpoint grid (which contains x);
    outside [x0, x_end] the end values are held."""
    left = grid[:-1]
    i = np.clip(np.searchsorted(x, left, side="right") - 1, 0, len(x) - 2)
    s = (left - x[i])[:, None]
    c0, c1, c2, c3 = (c[i, k : k + 1] for k in range(4))
    out = np.hstack([c0, 3 * c0 * s + c1, (3 * c0 * s + 2 * c1) * s + c2, ((c0 * s + c1) * s + c2) * s + c3])
    first = np.polyval(c[0], 0.0)
    last = np.polyval(c[-1], x[-1] - x[-2])
    out[left >= x[-1]] = [0.0, 0.0, 0.0, last]
    out[grid[1:] <= x[0]] = [0.0, 0.0, 0.0, first]
    return out


class StackedTables:
    """All tables of one axis evaluated together: one interval search and one
    row gather per point for every curve, instead of one per table.  Curves
    are re-expanded on the union of the tables' breakpoints, so the result is
    the tables' own interpolation, not a resampling."""

    def __init__(self, tables: list[Table]):
        # Curve rows: each table's + (or only) curve in table order, then the − curves, so the
        # first rows are the tables' values once the direction has chosen (no copy).
        backward = [(t, t.values_minus) for t in tables if t.values_minus is not None]  # the directional ones
        curves = [(t, t.values) for t in tables] + backward
        pieces = [_cubic_pieces(t, v) for t, v in curves]
        grid = np.unique(np.concatenate([x for x, _ in pieces]))
        if len(grid) == 1:
            grid = np.array([grid[0], grid[0] + 1.0])
        self.grid = grid
        self.inner = grid[
            1:-1
        ].copy()  # the interval of p in [grid[0], grid[-1]] is how many of these are <= p
        # Per power, a (curves, intervals) array: one gather along the intervals fetches every
        # curve, and each curve's values come out as a contiguous row (numpy's loops then run
        # along the points, not along a handful of curves)
        stacked = np.stack([_refine(x, c, grid) for x, c in pieces], axis=0)
        self.coefficients = [np.ascontiguousarray(stacked[:, :, k]) for k in range(4)]
        minus = iter(range(len(tables), len(curves)))
        self.columns = [
            (k, next(minus) if t.directional else None) for k, t in enumerate(tables)
        ]  # (+, − column)

    def __call__(self, positions: NDArray, direction: NDArray | None = None) -> NDArray:
        """(tables, n), row k table k's values: a directional table's + or − curve, or
        their mean, as `_chosen` picks them by direction."""
        # np.minimum/np.maximum: np.clip's own overhead is most of the time on a few points
        p = np.minimum(np.maximum(positions, self.grid[0]), self.grid[-1])
        i = self.inner.searchsorted(p, side="right")  # NaN sorts last: the last interval
        dx = p - self.grid.take(i)
        c0, c1, c2, c3 = self.coefficients
        curves = c0.take(i, axis=1)  # (curves, n), Horner in place
        for c in (c1, c2, c3):
            curves *= dx
            curves += c.take(i, axis=1)
        signs = _signs(direction)
        for plus, minus in self.columns:
            if minus is not None:
                curves[plus] = _chosen(signs, curves[plus], curves[minus])
        return curves[: len(self.columns)]
