"""Build a machine's error tables from laser, comparator, level and ball-bar files.

Ball-bar files are fitted after the others, by regularised least squares
over all of them (`ncpp.identify.ballbar`); the components the other files
give are held.  The rest of this docstring is about the other files.

Each file gives one component (a comparator two) as a table over its axis:

=====================================  ==========================================
file                                   component
=====================================  ==========================================
laser position on K                    EKK
laser straightness_j on K              EJK (straightness_y on X → EYX)
laser pitch / yaw / roll on K          `ANGLE_COMPONENTS` (X: roll EAX, pitch EBX,
                                       yaw ECX; Y: pitch EAY, roll EBY, yaw ECY;
                                       Z: pitch EAZ, yaw EBZ, roll ECZ), or the
                                       file's `component:` key
comparator on K, transverse J          EKK (linear) and EJK (transverse)
level roll / pitch on K                as the laser angles, sign from the side of
                                       the chain the levelled member is on
=====================================  ==========================================

How a table is found
--------------------
A reading is not the component alone: the optic sits at an Abbe offset, so
the axis's angular errors enter (eqs. 31–34); straightness carries squareness
and the fixed angles of inboard axes; effects of the base machine (backlash,
scale) are in the reading too.  Rather than undo each term by hand, the fit
uses the forward model itself (`ncpp.instruments.forward.predict_like`): with
the current machine it predicts each file noise-free, and sets the component
to its current value plus (measured − predicted), target by target and per
direction of approach.  Laser and comparator readings are relative (zeroed at
a datum), so their gap is taken relative to the first target: the
component keeps its value there (0 for a new table, as measured tables
start); a level reads against gravity, so its level is kept.  Angular files go first (their readings depend on
angles only), so that the Abbe terms are known when the translations are
fitted; sweeps repeat until nothing changes (Gauss–Seidel; the reading is
linear in its component with unit sensitivity, so one or two sweeps do).

Measured values are ISO 230-2 means per target (x̄↑, x̄↓; x̄ bidirectional).
A translation gets separate + and − tables when its reversal, beyond what
the base machine already explains, exceeds `reversal_threshold` (µm) and three
standard uncertainties; otherwise it gets the bidirectional mean.

The chain, offsets, references, limits, squareness and effects come from
`base`; without one, the chain from `chain` (default ``XYFZ``: a plain
vertical machine, work on X on Y, tool on Z) with zero offsets.  Components no
file gives keep the base's value.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import Location, NcppError
from ncpp.identify.ballbar import BallbarFit, fit_ballbar
from ncpp.instruments import iso230_2
from ncpp.instruments.files import ANGULAR_QUANTITIES, Measurement
from ncpp.instruments.forward import ANGLE_COMPONENTS, level_member, predict_like, reading_component
from ncpp.machine.chain import Chain
from ncpp.machine.components import COMPONENTS, Interpolation, Table
from ncpp.machine.model import Machine

DEFAULT_CHAIN = "XYFZ"


@dataclass(frozen=True)
class Source:
    """One component read from one column of one file."""

    measurement: Measurement
    component: str  # ISO name
    column: str
    sensitivity: float  # d(reading)/d(component): +1, or −1 for a level on a workpiece-side carriage

    @property
    def angular(self) -> bool:
        return COMPONENTS[self.component].kind == "rotation"

    @property
    def relative(self) -> bool:
        """Laser and comparator readings are zeroed at a datum: their level is not observed."""
        return self.measurement.instrument in ("laser", "comparator")

    @property
    def scale(self) -> float:
        """File unit per model unit."""
        return 1e6 if self.angular else 1e3


def sources_of(m: Measurement, chain: str) -> list[Source]:
    """The components file `m` gives (NcppError for files the fit cannot use)."""
    where = m.at()
    axis = m.axis
    if axis is None:
        raise NcppError(f"a {m.instrument} file needs '# axis: X|Y|Z' to be fitted", where)
    try:
        if m.instrument == "laser":
            name = reading_component(axis, m.quantity)
            component = m.text("component")
            if m.quantity in ANGULAR_QUANTITIES and component:
                name = component.upper()
            found = [Source(m, name, m.deviation_column, 1.0)]
        elif m.instrument == "comparator":
            found = [Source(m, f"E{axis}{axis}", "linear_um", 1.0)]
            transverse = (m.text("transverse") or "").upper()
            if "transverse_um" in m.columns and transverse:
                found.append(
                    Source(
                        m, reading_component(axis, f"straightness_{transverse.lower()}"), "transverse_um", 1.0
                    )
                )
        elif m.instrument == "level":
            name = ANGLE_COMPONENTS[(axis, m.quantity)]
            member = m.text("member") or level_member(axis)
            found = [Source(m, name, "inclination_um_per_m", _level_sign(chain, member, axis))]
        else:
            raise NcppError(
                f"fit uses laser, comparator, level and ball-bar files; {m.instrument} files are "
                "explained by the model (ncpp predict / diagnose), not fitted here",
                where,
            )
    except (KeyError, ValueError) as err:
        raise NcppError(str(err), where) from None
    _check_targets(m)
    for s in found:
        info = COMPONENTS.get(s.component)
        if info is None or info.axis != axis:
            raise NcppError(f"component {s.component} is not an error of the measured axis {axis}", where)
    return found


def _check_targets(m: Measurement) -> None:
    """A table is a curve along its axis: one target (to 1 µm) would set the whole axis."""
    column, what = ("position_mm", "positions") if m.instrument == "level" else ("target_mm", "targets")
    count = len(np.unique(np.round(m[column] * 1e3)))
    if count < 2:
        raise NcppError(f"a table needs readings at two or more {what}; the file has {count}", m.at())


def _level_sign(chain: str, member: str, axis: str) -> float:
    """A level on the carriage of `axis` (or a member outboard of it) turns with +ε on
    the tool side, −ε on the workpiece side (ε is of the tool relative to the work)."""
    c = Chain(chain)
    if member in ("work", "tool"):
        member = (
            c.work_side[0] if member == "work" and c.work_side else c.tool_side[-1] if c.tool_side else "F"
        )
    if member == "F" or c.side(member) != c.side(axis):
        raise ValueError(f"a level on {member} does not see the rotation of {axis} (chain {c.text})")
    side = c.work_side if c.side(axis) == "work" else c.tool_side
    # the member must ride on the axis: outboard of it, away from the frame
    outboard = (
        side.index(member) <= side.index(axis)
        if c.side(axis) == "work"
        else side.index(member) >= side.index(axis)
    )
    if not outboard:
        raise ValueError(f"a level on {member} does not ride on axis {axis} (chain {c.text})")
    return -1.0 if c.side(axis) == "work" else 1.0


def _per_target(s: Source, m: Measurement) -> iso230_2.Iso230_2:
    if m.instrument == "level":
        x = m["position_mm"]
        return iso230_2.evaluate_positioning(x, np.full(len(x), "+"), m[s.column])
    return iso230_2.evaluate_positioning(m["target_mm"], m["direction"], m[s.column])


@dataclass(frozen=True)
class Update:
    table: Table
    change: float  # largest change of the component at the targets, file unit


def _update(machine: Machine, s: Source, interpolation: Interpolation, reversal_threshold: float) -> Update:
    measured = _per_target(s, s.measurement)
    predicted = _per_target(s, predict_like(machine, s.measurement))
    t = measured.targets
    current = machine.component(s.component)
    now = {d: (np.zeros(len(t)) if current is None else current(t, d) * s.scale) for d in (1.0, -1.0, None)}
    gap_up = (measured.up.mean - predicted.up.mean) / s.sensitivity
    gap_down = (measured.down.mean - predicted.down.mean) / s.sensitivity
    if s.relative:  # keep the component's value at the datum (first target) where it is
        datum = gap_up[0] if np.isfinite(gap_up[0]) else gap_down[0]
        gap_up, gap_down = gap_up - datum, gap_down - datum
    gap_mean = np.where(
        np.isnan(gap_up), gap_down, np.where(np.isnan(gap_down), gap_up, (gap_up + gap_down) / 2)
    )
    # The reversal this component must carry: what is unexplained plus what it carries now.
    if _directional(s, measured, gap_up - gap_down + now[1.0] - now[-1.0], reversal_threshold):
        plus = now[1.0] + np.where(np.isnan(gap_up), gap_mean, gap_up)
        minus = now[-1.0] + np.where(np.isnan(gap_down), gap_mean, gap_down)
        table = Table(tuple(t), tuple(plus / s.scale), tuple(minus / s.scale), interpolation)
        change = float(np.max(np.abs(np.concatenate([plus - now[1.0], minus - now[-1.0]]))))
    else:
        values = now[None] + gap_mean
        table = Table(tuple(t), tuple(values / s.scale), None, interpolation)
        change = float(np.max(np.abs(gap_mean)))
    return Update(table, change)


def _directional(s: Source, measured: iso230_2.Iso230_2, reversal: NDArray, threshold: float) -> bool:
    """Separate ± tables when the unexplained reversal is real: above the threshold
    and three standard uncertainties of a reversal value."""
    if s.angular or not measured.bidirectional:
        return False
    both = measured.both & ~np.isnan(reversal)
    if not both.any():
        return False
    biggest = float(np.max(np.abs(reversal[both])))
    with np.errstate(invalid="ignore"):
        u = np.sqrt(measured.up.s**2 / measured.up.runs + measured.down.s**2 / measured.down.runs)
    u_max = float(np.nanmax(u[both])) if np.any(np.isfinite(u[both])) else 0.0
    return biggest > max(threshold, 3.0 * u_max)


def fit_machine(
    measurements: Sequence[Measurement],
    base: Machine | None = None,
    chain: str | None = None,
    *,
    name: str | None = None,
    interpolation: Interpolation = "smooth",
    reversal_threshold: float = 0.5,
    sweeps: int = 6,
    tolerance: float = 1e-4,
    knots: int = 9,
    smoothing: float | None = None,
    names: Mapping[str, str] | None = None,
) -> Machine:
    """A machine whose forward predictions reproduce the files (see the module docstring
    and `identify`)."""
    return identify(
        measurements, base, chain, name=name, interpolation=interpolation, reversal_threshold=reversal_threshold,
        sweeps=sweeps, tolerance=tolerance, knots=knots, smoothing=smoothing, names=names,
    )[0]  # fmt: skip


def identify(
    measurements: Sequence[Measurement],
    base: Machine | None = None,
    chain: str | None = None,
    *,
    name: str | None = None,
    interpolation: Interpolation = "smooth",
    reversal_threshold: float = 0.5,
    sweeps: int = 6,
    tolerance: float = 1e-4,
    knots: int = 9,
    smoothing: float | None = None,
    names: Mapping[str, str] | None = None,
) -> tuple[Machine, BallbarFit | None]:
    """The fitted machine and, when ball-bar files were given, the ball-bar fit's account.

    measurements: laser, comparator and level files (tables, as the module
    docstring says) and ball-bar files (`ncpp.identify.ballbar`: the remaining
    components and the squareness by regularised least squares, with the
    tables of the other files held); base: the machine whose structure,
    squareness, effects and other components are kept; chain: overrides the
    base's chain (default ``XYFZ`` without a base).  `tolerance` (µm, µrad)
    ends the sweeps; `knots`, `smoothing`: the ball-bar tables (λ None: GCV).
    `names`: how [meta.fitted] names each file (by its source; default the source
    itself), e.g. relative to the machine file written (`fileio.portable_name`)."""
    if not measurements:
        raise NcppError("no measurement files to fit", Location("ncpp fit"))
    if base is None:
        machine = Machine(name=name or "fitted", chain=chain or DEFAULT_CHAIN)
    else:
        machine = base.replace(chain=chain) if chain else base
        if name:
            machine = machine.replace(name=name)
    ballbars = [m for m in measurements if m.instrument == "ballbar"]
    direct = [m for m in measurements if m.instrument != "ballbar"]
    sources = [s for m in direct for s in sources_of(m, machine.chain)]
    if direct:
        machine = _fit_tables(
            machine, sources, interpolation, reversal_threshold, sweeps, tolerance, names or {}
        )
    if not ballbars:
        return machine, None
    fit = fit_ballbar(
        machine, ballbars, knots=knots, fixed=[s.component for s in sources], smoothing=smoothing
    )
    return fit.machine, fit


def _fit_tables(
    machine: Machine, sources: Sequence[Source], interpolation: Interpolation, reversal_threshold: float,
    sweeps: int, tolerance: float, names: Mapping[str, str],
) -> Machine:  # fmt: skip
    taken: dict[str, Source] = {}
    for s in sources:
        if s.component in taken:
            raise NcppError(
                f"{s.component} is given by both {taken[s.component].measurement.source} and "
                f"{s.measurement.source}; give one file per component",
                s.measurement.at(),
            )
        taken[s.component] = s
    order = sorted(sources, key=lambda s: not s.angular)  # angles first: they set the Abbe terms
    for _ in range(sweeps):
        largest = 0.0
        for s in order:
            update = _update(machine, s, interpolation, reversal_threshold)
            machine = machine.with_components(**{s.component: update.table})
            largest = max(largest, update.change)
        if largest < tolerance:
            break
    meta = dict(machine.meta)
    named = {s.component: names.get(s.measurement.source, s.measurement.source) for s in order}
    meta["fitted"] = {s.component: f"{named[s.component]} [{s.column}]" for s in order}
    return machine.replace(meta=meta)


def fit_residuals(machine: Machine, measurements: Sequence[Measurement]) -> dict[str, float]:
    """Largest |measured − predicted| per-target mean per fitted component (file unit):
    how well the machine reproduces the files (0 up to noise and interpolation)."""
    out = {}
    for m in measurements:
        if m.instrument == "ballbar":
            continue  # explained by the ball-bar fit's account
        for s in sources_of(m, machine.chain):
            measured, predicted = _per_target(s, m), _per_target(s, predict_like(machine, m))
            gaps = np.concatenate(
                [measured.up.mean - predicted.up.mean, measured.down.mean - predicted.down.mean]
            )
            if s.relative:  # a zeroed reading says nothing about its level
                gaps = gaps - np.nanmean(gaps)
            out[s.component] = float(np.nanmax(np.abs(gaps)))
    return out
