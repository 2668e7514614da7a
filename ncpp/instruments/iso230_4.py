"""ISO 230-4 evaluation of circular tests and the ball-bar diagnosis.

A circular test is one or two `Trace`s: the radial deviation ΔR(θ) (µm,
actual minus nominal radius) at angles θ of the moving point about the centre,
measured from the plane's first axis towards its second, in one direction of
travel (CCW: θ increasing; CW: θ decreasing).

ISO 230-4 figures (µm), all after least-squares-circle (LSC) centring, which
removes the set-up offset of the centre:

* ``G_ccw``, ``G_cw``   circular deviation: max − min radial deviation of one
                        path about its own LSC centre
* ``G``                 bidirectional circular deviation: envelope of both
                        paths about their common LSC centre
* ``H``                 circular hysteresis: max |ΔR_ccw − ΔR_cw| at common
                        angles (both paths about the common centre,
                        interpolated linearly onto the union of their angles)
* ``F_max``, ``F_min``  radial deviation: max and min of (LSC-centred radius −
                        nominal radius) over the paths, each about its own centre

The diagnosis fits one explicit linear model to all traces of a test (σ = +1
CCW, −1 CW; R nominal radius, mm; ΔR in µm; p, q the plane's first and second
axes, e.g. X, Y)::

    ΔR(θ, σ) = a_σ + cx_σ cosθ + cy_σ sinθ              set-up centre and radius, per direction
             + c2 cos2θ                                 scale mismatch k_p − k_q = 2 c2 / R
             + s2 sin2θ                                 squareness s (δp = s·q) = 2 s2 / R
             + σ m sin2θ                                servo mismatch τ_p − τ_q = 2 m / v
             + b_p · σ sign(sinθ) cosθ / 2              backlash of p (play width b_p)
             − b_q · σ sign(cosθ) sinθ / 2              backlash of q
             + h_p · Σ_r exp(−φ_r/φ0)                   reversal spike of p (θ_r = 0°, 180°)
             + h_q · Σ_r exp(−φ_r/φ0)                   reversal spike of q (θ_r = 90°, 270°)
             [+ cosθ·(α sin + β cos)(2π R cosθ / P_p)]  cyclic error of p, lead P_p, if found
             [+ sinθ·(α sin + β cos)(2π R sinθ / P_q)]  cyclic error of q

Derivations (u = (cosθ, sinθ), ΔR ≈ u·δ for a small error δ of the moving point):

* Scale: δp = k_p·p, δq = k_q·q gives R(k_p cos²θ + k_q sin²θ) =
  R(k_p+k_q)/2 + R(k_p−k_q)/2·cos2θ (the mean part is the radius term a).
* Squareness δp = s·q: ΔR = cosθ·s·R sinθ = (sR/2)·sin2θ.
* Servo lag τ per axis at path speed v = R|ω|: the axis is where its command
  was τ earlier, δp = −τ_p·dp/dt = τ_p σ v sinθ, δq = −τ_q σ v cosθ, so
  ΔR = σ v (τ_p − τ_q)/2 · sin2θ: same shape as squareness, sign flips with
  direction, which is how the two are told apart (one direction alone cannot).
* Backlash as a play of width b: the axis lags its command by b/2 against the
  direction it moves, δp = −sign(dp/dt)·b/2 = σ sign(sinθ) b/2.  Positive b
  (lost motion) steps the trace outward just after each reversal of the axis.
* Reversal spike: a transient outward bump just after the axis reverses
  (θ_r), decaying over φ0 (`spike_width_deg`) of travel, φ_r = σ(θ − θ_r) mod
  360 the travel since the reversal; h is its peak (µm).

Units of the reported figures: µm/m for squareness and scale, ms for servo
mismatch, µm for backlash, spikes, centre offsets and radius deviation.
`centre_offset_<axis>_um` is the centre of the path minus the fixed ball
(the set-up error the LSC centring removes), mean of the directions;
`radius_deviation_um` is the mean radius minus nominal (bar calibration and
mean scale); `residual_rms_um` what the model leaves unexplained.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ncpp.errors import NcppError
from ncpp.instruments.files import PLANES, Measurement

SYMBOLS = ("G", "G_cw", "G_ccw", "H", "F_max", "F_min")
SIGN = {"CCW": 1.0, "CW": -1.0}
SPIKE_SPAN = 8  # a spike is cut off after 8 widths of travel (_spike)
# The widest spike that dies out before the same axis reverses again, 180° later: wider, the
# spikes of the two reversals overlap and a very wide one is the constant the set-up takes.
MAX_SPIKE_WIDTH_DEG = 180.0 / SPIKE_SPAN


@dataclass(frozen=True, eq=False)
class Trace:
    """One direction of a circular test: ΔR (µm) at angles (deg, [0, 360))."""

    direction: str  # "CW" | "CCW"
    angle_deg: np.ndarray
    deviation_um: np.ndarray

    @property
    def sigma(self) -> float:
        return SIGN[self.direction]

    @property
    def theta(self) -> np.ndarray:
        return np.radians(self.angle_deg)


@dataclass(frozen=True, eq=False)
class CircularTest:
    """The traces of one circular test and its set-up."""

    traces: tuple[Trace, ...]
    radius_mm: float
    plane: str = "XY"
    feed_mm_min: float | None = None
    source: str = "<memory>"

    @property
    def axes(self) -> tuple[str, str]:
        return PLANES[self.plane]

    def trace(self, direction: str) -> Trace | None:
        return next((t for t in self.traces if t.direction == direction), None)


# -- reading circular tests out of measurement files -------------------------------


def circular_test(m: Measurement) -> CircularTest:
    """The circular test in a ballbar, cutting or (circular) grid file."""
    if m.instrument == "ballbar":
        traces = tuple(
            Trace(d, m["angle_deg"][m["direction"] == d], m["deviation_um"][m["direction"] == d])
            for d in ("CCW", "CW")
            if np.any(m["direction"] == d)
        )
    elif m.instrument == "cutting":
        direction = (m.text("direction") or "CCW").upper()
        traces = (Trace(direction if direction in SIGN else "CCW", m["angle_deg"], m["radius_dev_um"]),)
    elif m.instrument == "grid":
        traces = _grid_traces(m)
    else:
        raise NcppError(f"{m.instrument} files hold no circular test", m.at())
    if not traces or not all(len(t.angle_deg) >= 3 for t in traces):
        raise NcppError("a circular test needs at least three points per direction", m.at())
    radius = m.radius_mm
    if radius is None:  # a file without it is refused on loading (ballbar, cutting) or above (grid)
        raise NcppError(f"a {m.instrument} file needs '# radius_mm: R' (R > 0)", m.at())
    return CircularTest(traces, float(radius), m.plane, m.feed_mm_min, m.source)


def _grid_traces(m: Measurement) -> tuple[Trace, ...]:
    """Radial deviation of a circular grid-encoder path (needs radius_mm and center_mm)."""
    if m.radius_mm is None or m.center_mm is None:
        raise NcppError("a grid file is a circular test only with radius_mm and center_mm", m.at())
    p, q = m.plane_axes
    index = {"X": 0, "Y": 1, "Z": 2}
    centre = m.center_mm[[index[p], index[q]]]
    nominal = np.column_stack([m[f"{p.lower()}_mm"], m[f"{q.lower()}_mm"]]) - centre
    actual = nominal + np.column_stack([m[f"dev_{p.lower()}_um"], m[f"dev_{q.lower()}_um"]]) / 1000.0
    radial = (np.hypot(actual[:, 0], actual[:, 1]) - m.radius_mm) * 1000.0
    angle = np.degrees(np.arctan2(nominal[:, 1], nominal[:, 0])) % 360.0
    if "direction" in m.columns:
        groups = [(d, m["direction"] == d) for d in ("CCW", "CW") if np.any(m["direction"] == d)]
    else:  # the direction of travel follows from the order of the path
        order = np.argsort(m["s_mm"], kind="stable")
        turn = np.sum(np.angle(np.exp(1j * np.diff(np.radians(angle[order])))))
        groups = [("CCW" if turn >= 0 else "CW", np.ones(len(angle), bool))]
    return tuple(Trace(d, angle[sel], radial[sel]) for d, sel in groups)


# -- least-squares circle -------------------------------------------------------------


def lsc_centre(traces: tuple[Trace, ...] | list[Trace], radius_mm: float) -> np.ndarray:
    """Least-squares circle centre (µm, in the plane) of the traces' points about the set-up centre.

    The limaçon fit ΔR ≈ a + cx cosθ + cy sinθ is the linearised LSC; two
    Gauss-Newton steps with the exact radial distances make it exact for
    any offset that is small against the radius."""
    centre = np.zeros(2)
    for _ in range(3):
        theta = np.concatenate([_angles_about(t, centre, radius_mm) for t in traces])
        d = np.concatenate([centred(t, centre, radius_mm) for t in traces])
        design = np.column_stack([np.ones_like(theta), np.cos(theta), np.sin(theta)])
        coef = np.linalg.lstsq(design, d, rcond=None)[0]
        centre = centre + coef[1:]
    return centre


def _points_mm(t: Trace, radius_mm: float) -> np.ndarray:
    r = radius_mm + t.deviation_um / 1000.0
    return np.column_stack([r * np.cos(t.theta), r * np.sin(t.theta)])


def _angles_about(t: Trace, centre_um: np.ndarray, radius_mm: float) -> np.ndarray:
    v = _points_mm(t, radius_mm) - centre_um / 1000.0
    return np.arctan2(v[:, 1], v[:, 0])


def centred(t: Trace, centre_um: np.ndarray, radius_mm: float) -> np.ndarray:
    """ΔR (µm) of the trace's points about `centre_um` instead of the set-up centre."""
    v = _points_mm(t, radius_mm) - centre_um / 1000.0
    return (np.hypot(v[:, 0], v[:, 1]) - radius_mm) * 1000.0


# -- ISO 230-4 --------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Iso230_4:
    """ISO 230-4 figures (µm) of a circular test; None where a direction is missing."""

    G: float
    G_cw: float | None
    G_ccw: float | None
    H: float | None
    F_max: float
    F_min: float
    centres_um: dict[str, np.ndarray] = field(default_factory=dict)  # own LSC centre per direction
    common_centre_um: np.ndarray = field(default_factory=lambda: np.zeros(2))

    def figures(self) -> dict[str, float | None]:
        return {k: getattr(self, k) for k in SYMBOLS}


def evaluate_circular(test: CircularTest) -> Iso230_4:
    """ISO 230-4 circular deviation, hysteresis and radial deviation of `test`."""
    R = test.radius_mm
    own = {t.direction: lsc_centre([t], R) for t in test.traces}
    dev = {t.direction: centred(t, own[t.direction], R) for t in test.traces}
    common = lsc_centre(test.traces, R)
    every = np.concatenate([centred(t, common, R) for t in test.traces])
    G_dir = {d: float(v.max() - v.min()) for d, v in dev.items()}
    return Iso230_4(
        G=float(every.max() - every.min()),
        G_cw=G_dir.get("CW"),
        G_ccw=G_dir.get("CCW"),
        H=_hysteresis(test, common),
        F_max=float(max(v.max() for v in dev.values())),
        F_min=float(min(v.min() for v in dev.values())),
        centres_um=own,
        common_centre_um=common,
    )


def _hysteresis(test: CircularTest, centre_um: np.ndarray) -> float | None:
    ccw, cw = test.trace("CCW"), test.trace("CW")
    if ccw is None or cw is None:
        return None
    grid = np.union1d(ccw.angle_deg, cw.angle_deg)
    grid = grid[_covered(ccw.angle_deg, grid) & _covered(cw.angle_deg, grid)]
    if grid.size == 0:
        return None
    a = np.interp(grid, ccw.angle_deg, centred(ccw, centre_um, test.radius_mm), period=360.0)
    b = np.interp(grid, cw.angle_deg, centred(cw, centre_um, test.radius_mm), period=360.0)
    return float(np.max(np.abs(a - b)))


def _covered(angles: np.ndarray, at: np.ndarray) -> np.ndarray:
    """Which angles `at` lie inside the arc a trace covers (no interpolation across a gap,
    e.g. the open part of a partial-arc test in a vertical plane)."""
    ordered = np.unique(angles)
    gaps = np.diff(np.append(ordered, ordered[0] + 360.0))
    limit = 3.0 * np.median(gaps)
    slot = np.searchsorted(ordered, at, side="right") - 1  # gap that starts at ordered[slot]
    on_point = np.isin(at, ordered)
    return on_point | (gaps[slot % len(ordered)] <= limit)


def evaluate_measurement(m: Measurement) -> Iso230_4:
    return evaluate_circular(circular_test(m))


# -- diagnosis ----------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Diagnosis:
    """Ball-bar diagnosis: figures by name with their standard uncertainties and the fit."""

    figures: dict[str, float | None]
    uncertainty: dict[str, float | None]
    residual_rms_um: float
    model_um: tuple[np.ndarray, ...]  # fitted ΔR per trace (same order as the test's traces)


def _spike(theta: np.ndarray, sigma: float, reversal_deg: float, width_deg: float) -> np.ndarray:
    travel = (sigma * (np.degrees(theta) - reversal_deg)) % 360.0
    return np.where(travel < SPIKE_SPAN * width_deg, np.exp(-travel / width_deg), 0.0)


def _features(t: Trace, width_deg: float) -> dict[str, np.ndarray]:
    """Direction-independent and direction-signed shapes of the model (µm per unit parameter)."""
    th, s = t.theta, t.sigma
    # The direction an axis moves in is taken just before θ: at the very point
    # of a reversal the play has not been taken up yet.
    before = th - s * 1e-7
    return {
        "cos2": np.cos(2 * th),
        "sin2": np.sin(2 * th),
        "servo": s * np.sin(2 * th),
        "backlash_p": s * np.sign(np.sin(before)) * np.cos(th) / 2,
        "backlash_q": -s * np.sign(np.cos(before)) * np.sin(th) / 2,
        "spike_p": _spike(th, s, 0.0, width_deg) + _spike(th, s, 180.0, width_deg),
        "spike_q": _spike(th, s, 90.0, width_deg) + _spike(th, s, 270.0, width_deg),
    }


SCREW_LEADS_MM = (4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0, 32.0, 40.0)


def _fit(design: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least squares: coefficients, their standard uncertainties, residual.
    Columns that are zero everywhere (e.g. no point near a reversal) stay 0 with NaN uncertainty."""
    usable = np.any(design != 0, axis=0)
    coef = np.zeros(design.shape[1])
    coef[usable], *_ = np.linalg.lstsq(design[:, usable], y, rcond=None)
    residual = y - design @ coef
    sigma2 = float(residual @ residual) / max(len(y) - int(usable.sum()), 1)
    std = np.full(design.shape[1], np.nan)
    std[usable] = np.sqrt(np.diag(sigma2 * np.linalg.pinv(design[:, usable].T @ design[:, usable])))
    return coef, std, residual


def _cyclic_columns(test: CircularTest, axis: int, period_mm: float) -> np.ndarray:
    """Radial shape of a periodic positioning error of one axis: u·(sin, cos)(2π·pos/period)."""
    cols = []
    for t in test.traces:
        u = np.cos(t.theta) if axis == 0 else np.sin(t.theta)
        phase = 2 * np.pi * test.radius_mm * u / period_mm
        cols.append(np.column_stack([u * np.sin(phase), u * np.cos(phase)]))
    return np.vstack(cols)


def _cyclic_search(
    test: CircularTest, design: np.ndarray, y: np.ndarray, significance: float = 6.0
) -> dict[int, float]:
    """Greedy forward selection of periodic axis errors: each round adds the
    (axis, screw lead) that explains most of the residual, if its amplitude
    exceeds `significance` standard uncertainties.  Returns {axis index: period mm}."""
    found: dict[int, float] = {}
    periods = [P for P in SCREW_LEADS_MM if P <= test.radius_mm / 2]
    while len(found) < 2:
        current = np.column_stack([design, *(_cyclic_columns(test, a, P) for a, P in sorted(found.items()))])
        base = _fit(current, y)[2]
        best = None
        for axis in {0, 1} - set(found):
            for period in periods:
                coef, std, residual = _fit(np.column_stack([current, _cyclic_columns(test, axis, period)]), y)
                gain = float(base @ base - residual @ residual)
                if best is None or gain > best[0]:
                    best = (gain, axis, period, float(np.hypot(coef[-2], coef[-1])), float(np.mean(std[-2:])))
        if best is None or not best[3] > significance * best[4]:
            break
        found[best[1]] = best[2]
    return found


def diagnose_circular(test: CircularTest, spike_width_deg: float = 3.0) -> Diagnosis:
    """Fit the diagnosis model (module docstring) to all traces of `test` by least squares.

    A cyclic (ball-screw lead) error per axis is added to the model when one of
    the usual leads (`SCREW_LEADS_MM`, up to R/2) shows clearly: δp = c·sin(2π p/P + φ),
    reported as `cyclic_<axis>_um` (amplitude c) and `cyclic_<axis>_period_mm`."""
    if not 0 < spike_width_deg <= MAX_SPIKE_WIDTH_DEG:
        raise ValueError(f"spike width must be in (0, {MAX_SPIKE_WIDTH_DEG:g}] deg, not {spike_width_deg!r}")
    R = test.radius_mm
    bidirectional = len({t.direction for t in test.traces}) == 2
    shared = ["cos2", "sin2", "backlash_p", "backlash_q", "spike_p", "spike_q"] + (
        ["servo"] if bidirectional else []
    )
    blocks, ys = [], []
    n_dir = len(test.traces)
    for k, t in enumerate(test.traces):
        nuisance = np.zeros((len(t.theta), 3 * n_dir))
        nuisance[:, 3 * k : 3 * k + 3] = np.column_stack(
            [np.ones_like(t.theta), np.cos(t.theta), np.sin(t.theta)]
        )
        feats = _features(t, spike_width_deg)
        blocks.append(np.column_stack([nuisance] + [feats[name] for name in shared]))
        ys.append(t.deviation_um)
    design, y = np.vstack(blocks), np.concatenate(ys)
    cyclic = _cyclic_search(test, design, y)
    extra = [_cyclic_columns(test, axis, period) for axis, period in sorted(cyclic.items())]
    full = np.column_stack([design, *extra])
    coef, std, residual = _fit(full, y)
    fitted = y - residual
    named = dict(zip(shared, range(3 * n_dir, 3 * n_dir + len(shared))))
    p, q = test.axes
    v = test.feed_mm_min / 60.0 if test.feed_mm_min else None
    scale = {  # figure name -> (model term, factor from coefficient to figure)
        "squareness_um_per_m": ("sin2", 2000.0 / R),
        "scale_mismatch_um_per_m": ("cos2", 2000.0 / R),
        "servo_mismatch_ms": ("servo", 2.0 / v if v else None),
        f"backlash_{p}_um": ("backlash_p", 1.0),
        f"backlash_{q}_um": ("backlash_q", 1.0),
        f"reversal_spike_{p}_um": ("spike_p", 1.0),
        f"reversal_spike_{q}_um": ("spike_q", 1.0),
    }
    figures: dict[str, float | None] = {}
    uncertainty: dict[str, float | None] = {}
    for name, (term, factor) in scale.items():
        i = named.get(term)
        if i is None or factor is None or not np.isfinite(std[i]):
            figures[name] = uncertainty[name] = None
            continue
        figures[name] = float(coef[i] * factor)
        uncertainty[name] = float(std[i] * factor)
    column = design.shape[1]
    for axis, letter in enumerate((p, q)):
        if axis in cyclic:
            amplitude = float(np.hypot(coef[column], coef[column + 1]))
            figures[f"cyclic_{letter}_um"], uncertainty[f"cyclic_{letter}_um"] = (
                amplitude,
                float(np.mean(std[column : column + 2])),
            )
            figures[f"cyclic_{letter}_period_mm"] = cyclic[axis]
            column += 2
        else:
            figures[f"cyclic_{letter}_um"] = figures[f"cyclic_{letter}_period_mm"] = uncertainty[
                f"cyclic_{letter}_um"
            ] = None
    figures[f"centre_offset_{p}_um"] = float(np.mean(coef[1 : 3 * n_dir : 3]))
    figures[f"centre_offset_{q}_um"] = float(np.mean(coef[2 : 3 * n_dir : 3]))
    figures["radius_deviation_um"] = float(np.mean(coef[0 : 3 * n_dir : 3]))
    figures["residual_rms_um"] = rms = float(math.sqrt(float(residual @ residual) / len(y)))
    splits = np.cumsum([len(t.theta) for t in test.traces])[:-1]
    return Diagnosis(figures, uncertainty, rms, tuple(np.split(fitted, splits)))


def diagnose_measurement(m: Measurement, spike_width_deg: float = 3.0) -> Diagnosis:
    return diagnose_circular(circular_test(m), spike_width_deg)
