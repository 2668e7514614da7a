"""Forward models: what each instrument reads on a given machine (Rahman 2004, 4.5–4.8, ch. 5).

Rahman 2004: M. Rahman, *Modeling and measurement of multi-axis machine tools to improve positioning
accuracy in a software way*, University of Oulu, 2004.

Every `predict_<instrument>(machine, setup...)` returns a `Measurement` in the
contract's file form (shared/spec/measurement-files.md), so that a prediction
can be written with `write_measurement`, evaluated with `ncpp analyze` and set
beside a real file.  `predict_like(machine, m)` predicts the reading of the same
set-up as an existing file (the fit and the diagnosis compare the two).

The functional point
--------------------
An instrument reads at its functional point (laser optic, VM182 scanning head,
moving ball, grid-encoder head, cutter), `offset_mm` from the tool point in the
tool carriage.  Its deviation is `Machine.deviation` with the tool vector
replaced by tool + offset: the angular errors then act through the Abbe offset
of that point (eqs. 31–34), e.g. laser position on X with the optic 120 mm
below the tool reference reads EXX + 120·EBX.

What each instrument sees
-------------------------
* laser / comparator: an ISO 230-2 cycle (targets, runs, both directions,
  overtravel before each reversal) simulated as a stop-and-go `Trajectory`
  through `Machine.simulate`, so backlash, lateral play, scale, cyclic errors
  show as they would; readings are taken at standstill (no servo lag).  The
  reading is relative, zeroed at the first approach of the first target
  (`zero=True`), as an interferometer or an incremental comparator is.
  Straightness is seen from a laser aligned with the machine's reference axes
  (so it carries squareness and the fixed angles of inboard axes; real files
  are often slope-removed).  Angles: the rotation of the tool relative to the
  workpiece (`Machine.rotation`), pitch/yaw/roll named per axis as in
  `ANGLE_COMPONENTS`.
* level: the absolute rotation of a member against the frame (gravity),
  `Machine.member_rotation`, in µm/m (= µrad); by default the member is the
  moving carriage of the axis.
* ball bar: the exact bar length |ball − fixed ball| − R (eq. 50) along a
  simulated circle (feed, direction, overshoot arcs), non-geometric effects
  included; the fixed ball is set where the machine puts the moving ball when
  commanded to the centre.
* grid encoder: the 2-D deviation of the head in the plane along a free path
  (circle or square), relative to the deviation at the centre where the plate
  was set.
* cutting test: the actual tool path of a circle cut, as a CMM sees the part:
  radius about the centre as a function of the actual polar angle, sampled at
  the probing angles.

Units follow the files: µm, µrad, µm/m; inside, mm and rad.  `noise_um` adds
normal noise in the file's deviation unit (µm, µrad or µm/m) with `seed`.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ncpp.instruments.files import PLANES, Measurement, make_measurement
from ncpp.machine.components import AXES
from ncpp.machine.effects import LARGEST_LENGTH_MM, Angular
from ncpp.machine.model import Machine
from ncpp.machine.trajectory import Trajectory

# Pitch, yaw and roll per axis as ISO 230-1 components (ncpp.machine.components).
ANGLE_COMPONENTS: dict[tuple[str, str], str] = {
    ("X", "roll"): "EAX", ("X", "pitch"): "EBX", ("X", "yaw"): "ECX",
    ("Y", "pitch"): "EAY", ("Y", "roll"): "EBY", ("Y", "yaw"): "ECY",
    ("Z", "pitch"): "EAZ", ("Z", "yaw"): "EBZ", ("Z", "roll"): "ECZ",
}  # fmt: skip
INSTRUMENTS = ("laser", "comparator", "level", "ballbar", "grid", "cutting")
DWELL_S = 0.5  # standstill per stop of a positioning cycle (the reading is taken there)
# Readings (path points) of one prediction: a million take seconds and half a GB; no real test has as many.
MAX_READINGS = 1_000_000
MAX_CIRCLE_STEP_DEG = 120.0  # a circular test needs three points a revolution (iso230_4.circular_test)


# --------------------------------------------------------------------------- helpers
def reading_component(axis: str, quantity: str) -> str:
    """ISO name of the error a laser/level `quantity` along `axis` reads directly:
    position → EKK, straightness_y on X → EYX, pitch of X → EBX, ..."""
    axis = _axis_name(axis)
    if quantity == "position":
        return f"E{axis}{axis}"
    if quantity.startswith("straightness_"):
        direction = quantity.removeprefix("straightness_").upper()
        if direction not in AXES or direction == axis:
            raise ValueError(
                f"straightness of {axis} must be across it (straightness_x|_y|_z), not {quantity!r}"
            )
        return f"E{direction}{axis}"
    try:
        return ANGLE_COMPONENTS[(axis, quantity)]
    except KeyError:
        raise ValueError(f"unknown quantity {quantity!r}") from None


def _axis_name(axis: str) -> str:
    axis = axis.upper()
    if axis not in AXES:
        raise ValueError(f"axis must be X, Y or Z, not {axis!r}")
    return axis


def parse_fixed(fixed: Mapping[str, float] | str | None) -> dict[str, float]:
    """`"Y=-250 Z=300"` or a mapping → {'Y': -250.0, 'Z': 300.0}."""
    if fixed is None:
        return {}
    if isinstance(fixed, str):
        out = {}
        for word in fixed.replace(",", " ").split():
            name, sep, value = word.partition("=")
            if not sep:
                raise ValueError(f"fixed: expected AXIS=value words, got {word!r}")
            out[_axis_name(name)] = float(value)
    else:
        out = {_axis_name(k): float(v) for k, v in fixed.items()}
    check_extent(list(out.values()), "fixed positions")
    return out


def check_extent(values: Sequence[float], what: str) -> None:
    """Refuse positions or lengths (mm) that are not finite or beyond LARGEST_LENGTH_MM."""
    if not np.all(np.abs(np.asarray(values, dtype=float)) <= LARGEST_LENGTH_MM):
        raise ValueError(f"{what} must be finite numbers within ±{LARGEST_LENGTH_MM:g} mm, got {values}")


def _fixed_text(fixed: Mapping[str, float]) -> str:
    return " ".join(f"{a}={_num(v)}" for a, v in sorted(fixed.items()))


def _num(value: float) -> str:
    return repr(float(value)).removesuffix(".0")


def functional_point(machine: Machine, offset_mm: ArrayLike = (0.0, 0.0, 0.0)) -> Machine:
    """The machine as seen at a point `offset_mm` from the tool point (tool vector moved)."""
    return machine.replace(tool=np.add(machine.tool, np.asarray(offset_mm, dtype=float)))


def _points(fixed: Mapping[str, float], axis: str, values: ArrayLike) -> NDArray:
    values = np.asarray(values, dtype=float)
    P = np.tile([fixed.get(a, 0.0) for a in AXES], (len(values), 1))
    P[:, AXES.index(axis)] = values
    return P


def _check_count(count: int, what: str) -> None:
    """Refuse a prediction of more than MAX_READINGS readings before it is built."""
    if count > MAX_READINGS:
        raise ValueError(f"{what}: {count:,} readings; at most {MAX_READINGS:,}")


def _noise(values: NDArray, noise: float, rng: np.random.Generator) -> NDArray:
    return values + rng.normal(0.0, noise, values.shape) if noise > 0 else values


def _base_meta(machine: Machine, instrument: str) -> dict[str, object]:
    return {"machine": machine.name, "source": f"ncpp predict {instrument} (simulated)"}


def _vector_text(v: ArrayLike) -> str:
    return ",".join(_num(x) for x in np.asarray(v, dtype=float))


def _rounded(values: NDArray, digits: int = 4) -> NDArray:
    return np.round(values, digits) + 0.0  # + 0.0: no "-0" in files


# ------------------------------------------------------------- positioning cycles
def iso230_2_cycle(
    axis: str,
    targets: NDArray,
    runs: int,
    bidirectional: bool,
    fixed: Mapping[str, float],
    feed_mm_min: float,
    overtravel_mm: float,
) -> tuple[Trajectory, NDArray, list[tuple[float, int, str]]]:
    """The ISO 230-2 stop-and-go cycle: + pass up the targets, overtravel, − pass
    down.  Returns the trajectory, the indices of the reading samples (standstill)
    and the (target, run, direction) of each reading."""
    lo, hi = targets[0] - overtravel_mm, targets[-1] + overtravel_mm
    stops: list[float] = [lo]
    labels: list[tuple[float, int, str] | None] = [None]
    for run in range(1, runs + 1):
        stops += list(targets)
        labels += [(t, run, "+") for t in targets]
        if bidirectional:
            stops.append(hi)
            labels.append(None)
            stops += list(targets[::-1])
            labels += [(t, run, "-") for t in targets[::-1]]
        stops.append(lo)
        labels.append(None)
    # Three samples per stop: the middle one has zero velocity on both sides.
    values = np.repeat(np.asarray(stops), 3)
    travel = np.abs(np.diff(values))
    dt = np.where(travel > 0, travel / (feed_mm_min / 60.0), DWELL_S)
    t = np.concatenate([[0.0], np.cumsum(dt)])
    trajectory = Trajectory(_points(fixed, axis, values), feed_mm_min, t)
    readings = np.array([3 * k + 1 for k, lab in enumerate(labels) if lab is not None])
    return trajectory, readings, [lab for lab in labels if lab is not None]


def _positioning_readings(
    machine: Machine,
    axis: str,
    targets: ArrayLike,
    runs: int,
    bidirectional: bool,
    fixed: Mapping[str, float],
    offset_mm: ArrayLike,
    feed_mm_min: float,
    overtravel_mm: float,
    effects: bool,
    angular: bool,
) -> tuple[NDArray, list[tuple[float, int, str]]]:
    """(n,3) deviation in mm (or rotation in rad when `angular`) at each reading."""
    targets = np.unique(np.asarray(targets, dtype=float))
    if targets.size < 1:
        raise ValueError("no targets")
    if runs < 1:
        raise ValueError("runs must be at least 1")
    directions = 2 if bidirectional else 1
    _check_count(
        targets.size * runs * directions, f"{targets.size} targets × {runs} runs × {directions} direction(s)"
    )
    m = functional_point(machine, offset_mm)
    if not effects:
        m = m.replace(effects=())
    trajectory, at, labels = iso230_2_cycle(
        axis, targets, runs, bidirectional, fixed, feed_mm_min, overtravel_mm
    )
    P = trajectory.positions[at]
    if angular:
        values = m.rotation(P, trajectory.directions()[at])
        values = values + _angular_effects(m, P)
    else:
        values = (m.simulate(trajectory) - trajectory.positions)[at]
    return values, labels


def _angular_effects(machine: Machine, P: NDArray) -> NDArray:
    """Rotation (rad) the `angular` effects add (the others are pure translations)."""
    out = np.zeros(P.shape)
    for effect in machine.effects:
        if isinstance(effect, Angular):
            info = effect.component  # e.g. ECZ
            i = AXES.index(info[2])
            out[:, "ABC".index(info[1])] += effect.urad_per_m * 1e-9 * (P[:, i] - effect.ref_mm)
    return out


def _laser_component(axis: str, quantity: str, component: str | None) -> str:
    """The ISO component a laser reads: `component` may name another angle of the axis."""
    name = reading_component(axis, quantity)
    if component is None or component.upper() == name:
        return name
    angles = [f"E{r}{axis}" for r in "ABC"]
    if quantity not in ("pitch", "yaw", "roll") or component.upper() not in angles:
        allowed = f"one of {', '.join(angles)}" if quantity in ("pitch", "yaw", "roll") else name
        raise ValueError(
            f"component {component!r} is not what a laser reads for {quantity} of {axis}: use {allowed}"
        )
    return component.upper()


def _layout_columns(labels: list[tuple[float, int, str]]) -> dict[str, object]:
    return {
        "target_mm": [t for t, _, _ in labels],
        "run": [r for _, r, _ in labels],
        "direction": [d for _, _, d in labels],
    }


def predict_laser(
    machine: Machine,
    axis: str,
    quantity: str = "position",
    targets: ArrayLike = (0.0,),
    *,
    fixed: Mapping[str, float] | str | None = None,
    offset_mm: ArrayLike = (0.0, 0.0, 0.0),
    runs: int = 1,
    bidirectional: bool = True,
    feed_mm_min: float = 1000.0,
    overtravel_mm: float = 5.0,
    component: str | None = None,
    zero: bool = True,
    effects: bool = True,
    noise_um: float = 0.0,
    seed: int | None = None,
) -> Measurement:
    """Laser interferometer reading along `axis` (eqs. 31–34).

    quantity: position | straightness_x|_y|_z | pitch | yaw | roll; `component`
    (ISO name, angles only) overrides which rotation the angular optics read.
    Readings are µm (µrad for angles), zeroed at the first reading when `zero`."""
    axis = _axis_name(axis)
    fixed = parse_fixed(fixed)
    angular = quantity in ("pitch", "yaw", "roll")
    name = _laser_component(axis, quantity, component)
    values, labels = _positioning_readings(
        machine,
        axis,
        targets,
        runs,
        bidirectional,
        fixed,
        offset_mm,
        feed_mm_min,
        overtravel_mm,
        effects,
        angular,
    )
    index = "ABC".index(name[1]) if angular else AXES.index(name[1])
    reading = values[:, index] * (1e6 if angular else 1e3)
    if zero:
        reading = reading - reading[0]
    reading = _noise(reading, noise_um, np.random.default_rng(seed))
    meta = {
        **_base_meta(machine, "laser"), "axis": axis, "quantity": quantity, "component": name,
        "fixed": _fixed_text(fixed), "offset_mm": _vector_text(offset_mm), "feed_mm_min": feed_mm_min,
    }  # fmt: skip
    column = "deviation_urad" if angular else "deviation_um"
    return make_measurement("laser", meta, {**_layout_columns(labels), column: _rounded(reading)})


def predict_comparator(
    machine: Machine,
    axis: str,
    transverse: str | None = None,
    targets: ArrayLike = (0.0,),
    *,
    fixed: Mapping[str, float] | str | None = None,
    offset_mm: ArrayLike = (0.0, 0.0, 0.0),
    runs: int = 1,
    bidirectional: bool = True,
    feed_mm_min: float = 1000.0,
    overtravel_mm: float = 5.0,
    zero: bool = True,
    effects: bool = True,
    noise_um: float = 0.0,
    seed: int | None = None,
) -> Measurement:
    """VM182-type comparator along `axis`: linear deviation and the transverse one
    in direction `transverse` (default: the next axis, X→Y, Y→X, Z→X), both at the
    scanning head (eqs. 35–47).  µm, zeroed at the first reading when `zero`."""
    axis = _axis_name(axis)
    transverse = _axis_name(transverse or {"X": "Y", "Y": "X", "Z": "X"}[axis])
    if transverse == axis:
        raise ValueError("the transverse direction must differ from the axis")
    fixed = parse_fixed(fixed)
    values, labels = _positioning_readings(
        machine,
        axis,
        targets,
        runs,
        bidirectional,
        fixed,
        offset_mm,
        feed_mm_min,
        overtravel_mm,
        effects,
        False,
    )
    readings = values[:, [AXES.index(axis), AXES.index(transverse)]] * 1e3
    if zero:
        readings = readings - readings[0]
    readings = _noise(readings, noise_um, np.random.default_rng(seed))
    meta = {
        **_base_meta(machine, "comparator"), "axis": axis, "transverse": transverse,
        "fixed": _fixed_text(fixed), "offset_mm": _vector_text(offset_mm), "feed_mm_min": feed_mm_min,
    }  # fmt: skip
    columns = {
        **_layout_columns(labels),
        "linear_um": _rounded(readings[:, 0]),
        "transverse_um": _rounded(readings[:, 1]),
    }
    return make_measurement("comparator", meta, columns)


def level_member(axis: str) -> str:
    """Where a level for `axis` sits by default: on that axis's carriage."""
    return _axis_name(axis)


def predict_level(
    machine: Machine,
    axis: str,
    positions: ArrayLike,
    *,
    quantity: str = "roll",
    member: str | None = None,
    fixed: Mapping[str, float] | str | None = None,
    noise_um: float = 0.0,
    seed: int | None = None,
) -> Measurement:
    """Electronic level on `member` (default: the carriage of `axis`) read at
    `positions` of the axis: the member's rotation against the frame about the
    roll/pitch direction of `axis`, in µm/m (= µrad).  Not zeroed: a level reads
    against gravity."""
    axis = _axis_name(axis)
    if quantity not in ("roll", "pitch"):
        raise ValueError("a level reads roll or pitch")
    fixed = parse_fixed(fixed)
    member = member or level_member(axis)
    P = _points(fixed, axis, np.asarray(positions, dtype=float))
    name = ANGLE_COMPONENTS[(axis, quantity)]
    reading = machine.member_rotation(member, P)[:, "ABC".index(name[1])] * 1e6
    reading = _noise(reading, noise_um, np.random.default_rng(seed))
    meta = {
        **_base_meta(machine, "level"), "axis": axis, "quantity": quantity, "component": name,
        "member": member, "fixed": _fixed_text(fixed),
    }  # fmt: skip
    return make_measurement(
        "level", meta, {"position_mm": P[:, AXES.index(axis)], "inclination_um_per_m": _rounded(reading)}
    )


# ------------------------------------------------------------------- circular paths
def _circle_commands(
    plane: str,
    centre: NDArray,
    radius: float,
    direction: str,
    start_deg: float,
    overshoot_deg: float,
    step_deg: float,
) -> tuple[NDArray, NDArray, NDArray]:
    """Command points of one direction of a circular test with lead-in and
    lead-out arcs: (positions (n,3), angle of each point in deg, mask of the data arc)."""
    sign = {"CCW": 1.0, "CW": -1.0}[direction]
    if not radius > 0:
        raise ValueError(f"radius must be positive, not {radius:g}")
    if not (np.all(np.isfinite(centre)) and np.isfinite(start_deg)):
        raise ValueError("the centre and the start angle must be finite numbers")
    _check_step(step_deg)
    if not 0.0 <= overshoot_deg <= 360.0:
        raise ValueError(
            f"overshoot must be 0 to 360 deg (a feed-in arc of up to a turn), not {overshoot_deg:g}"
        )
    n_rev = int(round(360.0 / step_deg))
    n_over = int(round(overshoot_deg / step_deg))
    _check_count(n_rev + 2 * n_over + 1, f"a step of {step_deg:g} deg and {overshoot_deg:g} deg of overshoot")
    index = np.arange(-n_over, n_rev + n_over + 1)
    angle = start_deg + sign * index * (360.0 / n_rev)
    first, second = (AXES.index(a) for a in PLANES[plane])
    P = np.tile(centre, (len(index), 1))
    P[:, first] += radius * np.cos(np.radians(angle))
    P[:, second] += radius * np.sin(np.radians(angle))
    return P, angle, (index >= 0) & (index < n_rev)


def _check_step(step_deg: float) -> None:
    if not 0.0 < step_deg <= MAX_CIRCLE_STEP_DEG:
        raise ValueError(
            f"step {step_deg:g} deg: a circular test needs three points a revolution (0 < step <= {MAX_CIRCLE_STEP_DEG:g} deg)"
        )


def _simulated_deviation(machine: Machine, P: NDArray, feed_mm_min: float, effects: bool) -> NDArray:
    """Actual minus command (mm) along a path of command points, effects included."""
    m = machine if effects else machine.replace(effects=())
    trajectory = Trajectory(P, feed_mm_min)
    return m.simulate(trajectory) - trajectory.positions


def _check_plane(plane: str) -> str:
    plane = plane.upper()
    if plane not in PLANES:
        raise ValueError(f"plane must be XY, YZ or ZX, not {plane!r}")
    return plane


def _directions(directions: str | Iterable[str]) -> tuple[str, ...]:
    names = (directions,) if isinstance(directions, str) else tuple(directions)
    names = tuple(d.upper() for d in names)
    if not names or any(d not in ("CW", "CCW") for d in names):
        raise ValueError(f"directions must be CW and/or CCW, not {directions!r}")
    return names


def predict_ballbar(
    machine: Machine,
    plane: str = "XY",
    radius_mm: float = 150.0,
    center_mm: ArrayLike = (0.0, 0.0, 0.0),
    *,
    feed_mm_min: float = 1000.0,
    directions: str | Sequence[str] = ("CCW", "CW"),
    offset_mm: ArrayLike = (0.0, 0.0, 0.0),
    start_deg: float = 0.0,
    overshoot_deg: float = 45.0,
    step_deg: float = 1.0,
    effects: bool = True,
    noise_um: float = 0.0,
    seed: int | None = None,
) -> Measurement:
    """Double ball bar: ΔR = |moving ball − fixed ball| − R (eq. 50), µm, per direction.

    The moving ball sits `offset_mm` from the tool point; `center_mm` is the
    command position of the fixed ball.  Each direction is one data revolution
    from `start_deg` with `overshoot_deg` of feed-in and feed-out arc."""
    plane = _check_plane(plane)
    if not radius_mm > 0 or not step_deg > 0:
        raise ValueError("radius and step must be positive")
    centre = np.asarray(center_mm, dtype=float)
    m = functional_point(machine, offset_mm)
    fixed_ball = m.deviation(centre)  # the fixed ball is set where the machine puts the moving ball
    rng = np.random.default_rng(seed)
    dirs, angles, values = [], [], []
    for direction in _directions(directions):
        P, angle, data = _circle_commands(
            plane, centre, radius_mm, direction, start_deg, overshoot_deg, step_deg
        )
        d = _simulated_deviation(m, P, feed_mm_min, effects)
        bar = (P - centre) + (
            d - fixed_ball
        )  # (P − C) is exact; microns are added, not subtracted from metres
        dev = (np.linalg.norm(bar, axis=1) - radius_mm) * 1e3
        dirs += [direction] * int(data.sum())
        angles.append(np.round(angle[data] % 360.0, 9) % 360.0)
        values.append(_noise(dev[data], noise_um, rng))
    meta = {
        **_base_meta(machine, "ballbar"), "plane": plane, "radius_mm": float(radius_mm),
        "center_mm": _vector_text(centre), "feed_mm_min": float(feed_mm_min), "offset_mm": _vector_text(offset_mm),
    }  # fmt: skip
    columns = {
        "direction": dirs,
        "angle_deg": np.concatenate(angles),
        "deviation_um": _rounded(np.concatenate(values)),
    }
    return make_measurement("ballbar", meta, columns)


def _square_commands(plane: str, centre: NDArray, half: float, direction: str, step_mm: float) -> NDArray:
    """Square of side 2·half about the centre from the corner (−half, −half),
    CCW: +p, +q, −p, −q (CW the reverse), every step_mm."""
    corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]], dtype=float) * half
    if direction == "CW":
        corners = corners[::-1]
    if not (half > 0 and step_mm > 0):
        raise ValueError("the square's size and step must be positive")
    n = max(1, int(round(2 * half / step_mm)))
    _check_count(4 * n + 1, f"a step of {step_mm:g} mm along a side of {2 * half:g} mm")
    s = np.arange(n) / n
    pq = np.vstack([a + s[:, None] * (b - a) for a, b in zip(corners[:-1], corners[1:])] + [corners[-1:]])
    first, second = (AXES.index(a) for a in PLANES[plane])
    P = np.tile(centre, (len(pq), 1))
    P[:, first] += pq[:, 0]
    P[:, second] += pq[:, 1]
    return P


def predict_grid(
    machine: Machine,
    plane: str = "XY",
    path: str = "circle",
    center_mm: ArrayLike = (0.0, 0.0, 0.0),
    radius_mm: float = 100.0,
    *,
    feed_mm_min: float = 1000.0,
    directions: str | Sequence[str] = ("CCW",),
    offset_mm: ArrayLike = (0.0, 0.0, 0.0),
    start_deg: float = 0.0,
    overshoot_deg: float = 45.0,
    step_deg: float = 2.0,
    step_mm: float = 5.0,
    effects: bool = True,
    noise_um: float = 0.0,
    seed: int | None = None,
) -> Measurement:
    """Grid encoder (KGM type): 2-D deviation of the head in `plane` along a free
    path, µm, relative to the deviation at the centre (where the plate was set).

    path: "circle" (radius `radius_mm`, evaluated to ISO 230-4 too) or "square"
    (side 2·radius_mm about the centre, sampled every step_mm)."""
    plane = _check_plane(plane)
    centre = np.asarray(center_mm, dtype=float)
    m = functional_point(machine, offset_mm)
    datum = m.deviation(centre)
    rng = np.random.default_rng(seed)
    first, second = (AXES.index(a) for a in PLANES[plane])
    p, q = (a.lower() for a in PLANES[plane])
    parts: list[dict[str, object]] = []
    for direction in _directions(directions):
        if path == "circle":
            P, _, data = _circle_commands(
                plane, centre, radius_mm, direction, start_deg, overshoot_deg, step_deg
            )
        elif path == "square":
            P = _square_commands(plane, centre, radius_mm, direction, step_mm)
            data = np.ones(len(P), dtype=bool)
        else:
            raise ValueError(f"path must be circle or square, not {path!r}")
        d = (_simulated_deviation(m, P, feed_mm_min, effects) - datum)[data] * 1e3
        Pd = P[data]
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(Pd, axis=0), axis=1))])
        parts.append({
            "direction": [direction] * len(Pd), "s_mm": np.round(s, 6),
            f"{p}_mm": np.round(Pd[:, first], 6), f"{q}_mm": np.round(Pd[:, second], 6),
            f"dev_{p}_um": _rounded(_noise(d[:, first], noise_um, rng)),
            f"dev_{q}_um": _rounded(_noise(d[:, second], noise_um, rng)),
        })  # fmt: skip
    columns = {k: np.concatenate([np.asarray(part[k]) for part in parts]) for k in parts[0]}
    if path != "circle":
        del columns["direction"]
    meta = {**_base_meta(machine, "grid"), "plane": plane, "path": path, "center_mm": _vector_text(centre)}
    if path == "circle":
        meta["radius_mm"] = float(radius_mm)
    else:
        meta["side_mm"] = 2.0 * float(radius_mm)
    meta |= {"feed_mm_min": float(feed_mm_min), "offset_mm": _vector_text(offset_mm)}
    return make_measurement("grid", meta, columns)


def predict_cutting(
    machine: Machine,
    plane: str = "XY",
    radius_mm: float = 50.0,
    center_mm: ArrayLike = (0.0, 0.0, 0.0),
    *,
    feed_mm_min: float = 500.0,
    direction: str = "CCW",
    offset_mm: ArrayLike = (0.0, 0.0, 0.0),
    probe_step_deg: float = 2.0,
    overshoot_deg: float = 20.0,
    tool_diameter_mm: float | None = None,
    effects: bool = True,
    noise_um: float = 0.0,
    seed: int | None = None,
) -> Measurement:
    """Circle cut and measured on a CMM: radius of the cut surface about the
    centre minus R (µm) at probing angles.  The surface is the actual tool path
    (the cutter radius is compensated by the control and cancels), read at the
    actual polar angle of each path point, so tangential errors (lag) shift
    features instead of changing the radius."""
    plane = _check_plane(plane)
    direction = _directions(direction)[0]
    centre = np.asarray(center_mm, dtype=float)
    _check_step(probe_step_deg)
    _check_count(int(360.0 / probe_step_deg) + 1, f"a probe step of {probe_step_deg:g} deg")
    m = functional_point(machine, offset_mm)
    P, _, data = _circle_commands(plane, centre, radius_mm, direction, 0.0, overshoot_deg, 0.25)
    d = _simulated_deviation(m, P, feed_mm_min, effects) - m.deviation(centre)
    first, second = (AXES.index(a) for a in PLANES[plane])
    actual = (P - centre + d)[data][:, [first, second]]
    phi = np.degrees(np.arctan2(actual[:, 1], actual[:, 0])) % 360.0
    radius = (np.hypot(actual[:, 0], actual[:, 1]) - radius_mm) * 1e3
    order = np.argsort(phi)
    probes = np.arange(0.0, 360.0, probe_step_deg)
    measured = np.interp(probes, phi[order], radius[order], period=360.0)
    measured = _noise(measured, noise_um, np.random.default_rng(seed))
    meta = {
        **_base_meta(machine, "cutting"), "plane": plane, "radius_mm": float(radius_mm),
        "center_mm": _vector_text(centre), "feed_mm_min": float(feed_mm_min), "direction": direction,
        "offset_mm": _vector_text(offset_mm),
    }  # fmt: skip
    if tool_diameter_mm is not None:
        meta["tool_diameter_mm"] = float(tool_diameter_mm)
    return make_measurement("cutting", meta, {"angle_deg": probes, "radius_dev_um": _rounded(measured)})


# ------------------------------------------------------------------------ dispatch
PREDICTORS = {
    "laser": predict_laser,
    "comparator": predict_comparator,
    "level": predict_level,
    "ballbar": predict_ballbar,
    "grid": predict_grid,
    "cutting": predict_cutting,
}


def predict(machine: Machine, instrument: str, **setup: object) -> Measurement:
    """`predict_<instrument>(machine, **setup)`."""
    try:
        return PREDICTORS[instrument](machine, **setup)  # type: ignore[operator]
    except KeyError:
        raise ValueError(f"unknown instrument {instrument!r}; known: {', '.join(PREDICTORS)}") from None


def setup_of(m: Measurement) -> dict[str, object]:
    """The set-up of a measurement file as keyword arguments of its predict_ function
    (noise-free; the positioning layout is the file's targets, runs and directions)."""
    inst = m.instrument
    offset = m.offset_mm
    if inst in ("laser", "comparator"):
        setup: dict[str, object] = {
            "axis": m.axis or "X", "targets": np.unique(m["target_mm"]), "fixed": m.fixed, "offset_mm": offset,
            "runs": int(m["run"].max()), "bidirectional": set(m["direction"]) == {"+", "-"},
            "feed_mm_min": m.feed_mm_min or 1000.0,
        }  # fmt: skip
        if inst == "laser":
            setup["quantity"] = m.quantity
            if m.quantity in ("pitch", "yaw", "roll") and m.text("component"):
                setup["component"] = m.text("component")
        else:
            setup["transverse"] = m.text("transverse")
        return setup
    if inst == "level":
        return {"axis": m.axis or "X", "positions": m["position_mm"], "quantity": m.quantity,
                "member": m.text("member"), "fixed": m.fixed}  # fmt: skip
    centre = m.center_mm if m.center_mm is not None else np.zeros(3)
    common = {
        "plane": m.plane,
        "center_mm": centre,
        "offset_mm": offset,
        "feed_mm_min": m.feed_mm_min or 1000.0,
    }
    if inst == "ballbar":
        return {
            **common,
            "radius_mm": m.radius_mm,
            "directions": tuple(dict.fromkeys(m["direction"])),
            "step_deg": 0.25,
        }
    if inst == "cutting":
        return {
            **common,
            "radius_mm": m.radius_mm,
            "direction": m.text("direction") or "CCW",
            "probe_step_deg": 0.25,
        }
    raise ValueError(f"no forward model for {inst} files of this kind")


def predict_like(machine: Machine, m: Measurement, *, effects: bool = True, zero: bool = True) -> Measurement:
    """The noise-free reading `machine` gives in the set-up of file `m`, row for row
    (same targets/runs/directions, same angles or positions), with m's metadata.
    zero=False: laser/comparator readings absolute instead of zeroed at the first."""
    inst = m.instrument
    if inst == "grid":
        return _grid_like(machine, m, effects)
    setup = setup_of(m)
    if inst != "level":
        setup["effects"] = effects
    if inst in ("laser", "comparator"):
        setup["zero"] = zero
    pred = predict(machine, inst, **setup)
    columns = dict(m.columns)
    if inst in ("laser", "comparator"):
        key = {(round(float(t), 6), int(r), str(d)): i
               for i, (t, r, d) in enumerate(zip(pred["target_mm"], pred["run"], pred["direction"]))}  # fmt: skip
        rows = np.array([key[(round(float(t), 6), int(r), str(d))]
                         for t, r, d in zip(m["target_mm"], m["run"], m["direction"])])  # fmt: skip
        for name in ("deviation_um", "deviation_urad", "linear_um", "transverse_um"):
            if name in columns:
                columns[name] = pred[name][rows]
    elif inst == "level":
        columns["inclination_um_per_m"] = pred["inclination_um_per_m"]
    elif inst == "ballbar":
        out = np.empty(len(m))
        for d in set(m["direction"]):
            mine, theirs = pred["direction"] == d, m["direction"] == d
            out[theirs] = _periodic_interp(
                m["angle_deg"][theirs], pred["angle_deg"][mine], pred["deviation_um"][mine]
            )
        columns["deviation_um"] = out
    elif inst == "cutting":
        columns["radius_dev_um"] = _periodic_interp(m["angle_deg"], pred["angle_deg"], pred["radius_dev_um"])
    return Measurement(inst, dict(m.meta), columns, source=f"{m.source} (predicted)")


def _periodic_interp(at: NDArray, angle: NDArray, value: NDArray) -> NDArray:
    order = np.argsort(angle)
    return np.interp(at, angle[order], value[order], period=360.0)


def _grid_line(m: Measurement) -> NDArray:
    """Command points (n,3) of a grid file's rows (axes off the plane at the centre)."""
    centre = m.center_mm if m.center_mm is not None else np.zeros(3)
    P = np.tile(centre, (len(m), 1))
    for a in m.plane_axes:
        P[:, AXES.index(a)] = m[f"{a.lower()}_mm"]
    return P


def _grid_like(machine: Machine, m: Measurement, effects: bool) -> Measurement:
    """Grid rows are a path: simulate the file's own path point by point, per direction."""
    mm = functional_point(machine, m.offset_mm)
    centre = m.center_mm if m.center_mm is not None else np.zeros(3)
    P = _grid_line(m)
    groups = (
        [m["direction"] == d for d in dict.fromkeys(m["direction"])]
        if "direction" in m.columns
        else [np.ones(len(m), bool)]
    )
    d = np.empty(P.shape)
    for rows in groups:
        index = np.flatnonzero(rows)[np.argsort(m["s_mm"][rows], kind="stable")]
        d[index] = _simulated_deviation(mm, P[index], m.feed_mm_min or 1000.0, effects)
    d = (d - mm.deviation(centre)) * 1e3
    columns = dict(m.columns)
    for a in m.plane_axes:
        columns[f"dev_{a.lower()}_um"] = d[:, AXES.index(a)]
    return Measurement("grid", dict(m.meta), columns, source=f"{m.source} (predicted)")
