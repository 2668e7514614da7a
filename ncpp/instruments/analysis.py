"""The standard evaluation of any measurement file, as `ncpp analyze` prints it.

`analyze(m)` picks the evaluation from the instrument and quantity:

============================== ============ ==============================================
file                           standard     figures (keys of `Analysis.figures`)
============================== ============ ==============================================
laser position, comparator     ISO 230-2    A A_up A_down E E_up E_down M B B_mean R R_up
                                            R_down (µm); comparator adds the transverse
                                            straightness_um, slope_um_per_m
laser straightness_*           ISO 230-1    straightness_um (about the least-squares line),
                                            slope_um_per_m (of that line), B (µm, max
                                            reversal of the mean profiles)
laser pitch / yaw / roll       ISO 230-1    range_urad, mean_urad, slope_urad_per_m
level                          profile      range_um_per_m, mean_um_per_m,
                                            slope_um_per_m_per_m; pitch adds
                                            integrated_straightness_um
ballbar, cutting, circular     ISO 230-4    G G_cw G_ccw H F_max F_min (µm) and the
grid                                        diagnosis (see iso230_4): squareness_um_per_m,
                                            scale_mismatch_um_per_m, servo_mismatch_ms,
                                            backlash_<axis>_um, reversal_spike_<axis>_um,
                                            cyclic_<axis>_um, cyclic_<axis>_period_mm,
                                            centre_offset_<axis>_um, radius_deviation_um,
                                            residual_rms_um
grid (any path)                path         path_max_um, path_rms_um (length of the 2-D
                                            deviation vector)
============================== ============ ==============================================

A figure that a file cannot give (a missing direction, a single run) is None.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ncpp.errors import NcppError, quoted
from ncpp.instruments import iso230_2, iso230_4
from ncpp.instruments.files import ANGULAR_QUANTITIES, Measurement


@dataclass(frozen=True, eq=False)
class Profile:
    """A deviation along an axis: per-target mean and the least-squares reference line."""

    position_mm: np.ndarray
    value: np.ndarray  # mean value per position (file unit)

    @property
    def line(self) -> tuple[float, float]:
        """(slope per mm, intercept) of the least-squares line."""
        slope, intercept = np.polyfit(self.position_mm, self.value, 1)
        return float(slope), float(intercept)

    @property
    def about_line(self) -> np.ndarray:
        slope, intercept = self.line
        return self.value - (slope * self.position_mm + intercept)

    @property
    def straightness(self) -> float:
        """Max − min about the least-squares line (ISO 230-1 straightness deviation)."""
        r = self.about_line
        return float(r.max() - r.min())

    @property
    def range(self) -> float:
        return float(self.value.max() - self.value.min())


@dataclass(frozen=True, eq=False)
class Analysis:
    """What `ncpp analyze` reports for one file."""

    measurement: Measurement
    standard: str
    figures: dict[str, float | None]
    positioning: iso230_2.Iso230_2 | None = None
    circle: iso230_4.Iso230_4 | None = None
    test: iso230_4.CircularTest | None = None
    diagnosis: iso230_4.Diagnosis | None = None
    profiles: dict[str, Profile] = field(default_factory=dict)


def _clean(figures: dict[str, float | None]) -> dict[str, float | None]:
    return {k: (None if v is None or not math.isfinite(v) else float(v)) for k, v in figures.items()}


def analyze(m: Measurement, spike_width_deg: float = 3.0) -> Analysis:
    """The standard evaluation of measurement `m`."""
    if len(m) == 0:
        raise NcppError("the file holds no readings", m.at())
    if m.instrument == "comparator" or (m.instrument == "laser" and m.quantity == "position"):
        return _positioning(m)
    if m.instrument == "laser":
        return _laser_profile(m)
    if m.instrument == "level":
        return _level(m)
    if m.instrument in ("ballbar", "cutting") or (
        m.instrument == "grid" and m.radius_mm and m.center_mm is not None
    ):
        return _circular(m, spike_width_deg)
    if m.instrument == "grid":
        return Analysis(m, "path", _clean(_path_figures(m)))
    raise NcppError(f"no evaluation for instrument {quoted(m.instrument)}", m.at())


def _positioning(m: Measurement) -> Analysis:
    result = iso230_2.evaluate_measurement(m)
    figures = result.figures()
    profiles = {}
    if m.instrument == "comparator" and "transverse_um" in m.columns:
        transverse = _mean_profile(m, "transverse_um")
        profiles["transverse"] = transverse
        if len(transverse.position_mm) >= 2:  # a line needs two targets; one target: no straightness (None)
            figures |= {
                "straightness_um": transverse.straightness,
                "slope_um_per_m": transverse.line[0] * 1000.0,
            }
        else:
            figures |= {"straightness_um": None, "slope_um_per_m": None}
    return Analysis(m, "ISO 230-2", _clean(figures), positioning=result, profiles=profiles)


def _mean_profile(m: Measurement, column: str) -> Profile:
    """Bidirectional mean per target (x̄_i of ISO 230-2, which handles one-way tests too)."""
    result = iso230_2.evaluate_measurement(m, column)
    ok = ~np.isnan(result.mean)
    return Profile(result.targets[ok], result.mean[ok])


def _line_fits(m: Measurement, profile: Profile, what: str, where: str = "targets") -> Profile:
    """`profile`, to which a line is fitted: that needs two positions (NcppError if not)."""
    count = len(np.unique(profile.position_mm))
    if count < 2:
        raise NcppError(f"a {what} profile needs at least two {where}; the file has {count}", m.at())
    return profile


def _laser_profile(m: Measurement) -> Analysis:
    column = m.deviation_column
    profile = _line_fits(m, _mean_profile(m, column), m.quantity)
    result = iso230_2.evaluate_measurement(m, column)
    figures: dict[str, float | None]
    if m.quantity in ANGULAR_QUANTITIES:
        figures = {
            "range_urad": profile.range,
            "mean_urad": float(profile.value.mean()),
            "slope_urad_per_m": profile.line[0] * 1000.0,
        }
    else:
        figures = {
            "straightness_um": profile.straightness,
            "slope_um_per_m": profile.line[0] * 1000.0,
            "B": result.B,
        }
    return Analysis(m, "ISO 230-1", _clean(figures), positioning=result, profiles={m.quantity: profile})


def _level(m: Measurement) -> Analysis:
    order = np.argsort(m["position_mm"], kind="stable")
    x, incl = m["position_mm"][order], m["inclination_um_per_m"][order]
    profile = _line_fits(m, Profile(x, incl), f"level {m.quantity}", "positions")
    figures: dict[str, float | None] = {
        "range_um_per_m": profile.range,
        "mean_um_per_m": float(incl.mean()),
        "slope_um_per_m_per_m": profile.line[0] * 1000.0,
    }
    profiles = {m.quantity: profile}
    if m.quantity == "pitch" and len(x) > 2:
        # Integrating the slope (µm/m × mm = nm) gives the height profile of the travel.
        height = np.concatenate([[0.0], np.cumsum(np.diff(x) * (incl[1:] + incl[:-1]) / 2)]) / 1000.0
        profiles["height"] = Profile(x, height)
        figures["integrated_straightness_um"] = profiles["height"].straightness
    return Analysis(m, "profile", _clean(figures), profiles=profiles)


def _circular(m: Measurement, spike_width_deg: float) -> Analysis:
    test = iso230_4.circular_test(m)
    circle = iso230_4.evaluate_circular(test)
    diagnosis = iso230_4.diagnose_circular(test, spike_width_deg)
    figures = circle.figures() | diagnosis.figures
    if m.instrument == "grid":
        figures |= _path_figures(m)
    return Analysis(m, "ISO 230-4", _clean(figures), circle=circle, test=test, diagnosis=diagnosis)


def _path_figures(m: Measurement) -> dict[str, float | None]:
    p, q = (a.lower() for a in m.plane_axes)
    length = np.hypot(m[f"dev_{p}_um"], m[f"dev_{q}_um"])
    return {"path_max_um": float(length.max()), "path_rms_um": float(np.sqrt(np.mean(length**2)))}


# -- text report ------------------------------------------------------------------------

LABELS = {
    "A_up": "A↑", "A_down": "A↓", "E_up": "E↑", "E_down": "E↓", "R_up": "R↑", "R_down": "R↓", "B_mean": "B̄",
}  # fmt: skip


def describe(m: Measurement) -> str:
    """One line naming what the file measures."""
    if m.instrument in ("laser", "comparator"):
        runs = int(m["run"].max())
        dirs = "bidirectional" if {"+", "-"} <= set(m["direction"]) else "unidirectional"
        what = "position" if m.instrument == "comparator" else m.quantity
        extra = (
            f", transverse {m.text('transverse')}"
            if m.instrument == "comparator" and m.text("transverse")
            else ""
        )
        return f"{m.instrument} {m.axis or '?'} {what}{extra}: {len(np.unique(m['target_mm']))} targets, {runs} run(s), {dirs}"
    if m.instrument == "level":
        return f"level {m.axis or '?'} {m.quantity}: {len(m)} positions"
    radius = f" R{m.radius_mm:g} mm" if m.radius_mm else ""
    feed = f" F{m.feed_mm_min:g} mm/min" if m.feed_mm_min else ""
    return f"{m.instrument} {m.plane}{radius}{feed}: {len(m)} points"


def format_report(a: Analysis) -> str:
    """The readable table `ncpp analyze` prints."""
    lines = [f"{a.measurement.source}: {describe(a.measurement)} — {a.standard}"]
    lines += [f"  {LABELS.get(k, k):<28} {_fmt(v)}" for k, v in a.figures.items()]
    if a.positioning is not None and a.standard == "ISO 230-2":
        lines += ["", _target_table(a.positioning)]
    return "\n".join(lines)


def _fmt(value: float | None) -> str:
    return f"{'n/a':>10}" if value is None else f"{value:10.3f}"


def _target_table(r: iso230_2.Iso230_2) -> str:
    head = f"  {'target_mm':>10} {'x̄↑':>8} {'x̄↓':>8} {'x̄':>8} {'B_i':>8} {'s↑':>7} {'s↓':>7} {'R_i':>7}"
    rows = [head]
    for i, t in enumerate(r.targets):
        cells = (
            r.up.mean[i],
            r.down.mean[i],
            r.mean[i],
            r.reversal[i],
            r.up.s[i],
            r.down.s[i],
            r.repeatability[i],
        )
        rows.append(
            f"  {t:10.3f} " + " ".join(f"{c:8.3f}" if not math.isnan(c) else f"{'-':>8}" for c in cells)
        )
    return "\n".join(rows)
