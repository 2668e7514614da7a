"""Non-geometric effects: what a measurement shows and the static map lacks.

Each effect is a small frozen dataclass with a `kind` (the name used in the
diagnosis report and in a machine file's ``[[effects]]`` list), parameters
whose names carry their units, and ``apply(trajectory) -> (n,3)`` deviation
in mm (actual minus command) along a time-ordered `Trajectory`.

====================  =========================================================
kind                  definition (k: position of `axis`, d: its travel sign)
====================  =========================================================
scale                 δk = um_per_m·(k − ref_mm)
backlash              play operator of width `um`: the axis lags ±um/2 behind
                      the command; a reversal costs `um` of lost motion (um < 0:
                      it runs |um|/2 ahead and jumps |um| ahead on reversal, a
                      backlash compensation set larger than the play)
lateral_play          δ(direction) = ±um/2 with the travel sign of `axis`
                      (direction defaults: X→Y, Y→X, Z→X)
reversal_spike        after each reversal of `axis`: δk = −d·um·exp(−s/decay),
                      s = path length (decay_mm) or time (decay_ms) since it;
                      um > 0 = the axis sticks at the turning point (outward)
servo_mismatch        position-loop lag v·τ per axis; first axis of `axes` lags
                      by ms/2 more, the second by ms/2 less than the mean
squareness            XY: δx = s·y, YZ: δy = s·z, ZX: δz = s·x (s = um_per_m)
straightness          bow δ(direction) = um·4u(1−u), u = (k − lo)/(hi − lo)
                      over range_mm, default the trajectory's extent along axis
cyclic                δk = um·sin(2π·k/period_mm + phase_deg)
angular               rotation ε(k) = urad_per_m·(k − ref_mm) about the
                      component's axis, moving the tool through the machine's
                      Abbe offset at the tool length offset in effect (or
                      through P itself when no machine is given)
====================  =========================================================
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import typing
from collections.abc import Mapping
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np
from numpy.typing import NDArray

from ncpp.machine.components import AXES, COMPONENTS
from ncpp.machine.trajectory import Trajectory

if TYPE_CHECKING:
    from ncpp.machine.model import Machine

# The largest error a machine file may give, in its µm (a metre), µm/m or µrad/m
LARGEST_ERROR = 1e6
# mm: positions, offsets and travel past a kilometre are typing errors, no machine's (a reference
# point of 1e308 mm would simulate a contour error of 'inf µm'; a set-up there, inf readings)
LARGEST_LENGTH_MM = 1e6
PLANE_TERMS = {"XY": (0, 1), "YZ": (1, 2), "ZX": (2, 0)}  # (deviating axis, driving axis)
LATERAL_DEFAULT = {"X": "Y", "Y": "X", "Z": "X"}


def _axis(name: str, what: str = "axis") -> int:
    if name not in tuple(AXES):  # a tuple: "XY" and "" are substrings of "XYZ", a list is not hashable
        raise ValueError(f"{what} must be X, Y or Z, not {name!r}")
    return AXES.index(name)


@dataclass(frozen=True)
class Effect:
    """Base: dict round trip and the shared `apply` signature.  A dataclass without
    fields, so that every effect is one to `dataclasses` (and to the type checker)."""

    kind: ClassVar[str]
    # True when the effect depends on position alone (not on time, feed or the
    # direction of travel): compensation can cancel it like a geometric error.
    static: ClassVar[bool] = False

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        raise NotImplementedError

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"kind": self.kind}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is not None:
                out[f.name] = list(value) if isinstance(value, tuple) else value
        return out


def effect_from_dict(data: Mapping[str, Any]) -> Effect:
    """Build an effect from its dict (``kind`` plus parameters); ValueError if bad."""
    if not isinstance(data, Mapping):
        raise ValueError(
            f'must be a table such as {{ kind = "backlash", axis = "X", um = 3.0 }}, not {data!r}'
        )
    kind = data.get("kind")
    cls = EFFECTS.get(kind) if isinstance(kind, str) else None
    if cls is None:
        raise ValueError(f"unknown effect kind {kind!r}; known: {', '.join(EFFECTS)}")
    fields = {f.name: f for f in dataclasses.fields(cls)}
    params = {k: v for k, v in data.items() if k != "kind"}
    unknown = sorted(set(params) - set(fields))
    if unknown:
        raise ValueError(
            f"effect {kind}: unknown key(s) {', '.join(unknown)}; expected {', '.join(sorted(fields))}"
        )
    missing = sorted(n for n, f in fields.items() if n not in params and f.default is dataclasses.MISSING)
    if missing:
        raise ValueError(f"effect {kind}: missing key(s) {', '.join(missing)}")
    hints = typing.get_type_hints(cls)
    return cls(
        **{
            k: _size(f"effect {kind}: {k}", k, _param(f"effect {kind}: {k}", hints[k], v))
            for k, v in params.items()
        }
    )


def is_finite_number(value: Any) -> bool:
    """A real number a float holds: not a bool, nan, inf, nor an integer of 400 digits (TOML has those)."""
    if not isinstance(value, numbers.Real) or isinstance(value, (bool, np.bool_)):
        return False
    try:
        return math.isfinite(value)
    except OverflowError:
        return False


def _size(what: str, key: str, value: Any) -> Any:
    """An error's size (µm, µm/m, µrad/m) past LARGEST_ERROR is a typing error, not a machine's:
    1e300 µm of backlash would make simulations report 'inf µm'."""
    if key.split("_")[0] in ("um", "urad") and isinstance(value, float) and not abs(value) <= LARGEST_ERROR:
        raise ValueError(
            f"{what} must be within ±{LARGEST_ERROR:g} (an error of a metre is no machine's), not {value:g}"
        )
    return value


def _param(what: str, hint: Any, value: Any) -> Any:
    """A number or [lo, hi] parameter checked against its field's type: a string "3"
    would pass here and fail only when the effect is applied.  Text parameters are
    left to the effect's own check, which names the values it takes."""
    want = next(a for a in typing.get_args(hint) or (hint,) if a is not type(None))
    if want is float:
        if not is_finite_number(value):
            raise ValueError(f"{what} must be a finite number, not {value!r}")
        return float(value)
    if typing.get_origin(want) is tuple:  # tuple[float, float]: a range
        if not (isinstance(value, (list, tuple)) and len(value) == 2 and all(map(is_finite_number, value))):
            raise ValueError(f"{what} must be [lo, hi], two finite numbers, not {value!r}")
        return tuple(float(v) for v in value)
    return value


def _zeros(trajectory: Trajectory) -> NDArray:
    return np.zeros(trajectory.positions.shape)


@dataclass(frozen=True)
class Scale(Effect):
    kind: ClassVar[str] = "scale"
    static: ClassVar[bool] = True
    axis: str
    um_per_m: float
    ref_mm: float = 0.0

    def __post_init__(self) -> None:
        _axis(self.axis)

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        i = _axis(self.axis)
        out = _zeros(trajectory)
        out[:, i] = self.um_per_m * 1e-6 * (trajectory.positions[:, i] - self.ref_mm)
        return out


def play_operator(command: NDArray, direction: NDArray, width: float) -> NDArray:
    """Output of a play (backlash) operator of total width `width`.

    The output follows the command at a distance width/2 behind it; after a
    reversal it stands still until the command has crossed the play.  Each
    monotone run is a running max/min, so the loop is over runs, not samples."""
    h = 0.5 * width
    out = command.copy()
    moving = np.flatnonzero(direction)
    if len(moving) == 0:
        return out
    y = command[0] - direction[0] * h
    bounds = np.flatnonzero(np.diff(direction)) + 1
    for run in np.split(np.arange(len(command)), bounds):
        s = direction[run[0]]
        if s > 0:
            seg = np.maximum.accumulate(np.maximum(command[run] - h, y))
        elif s < 0:
            seg = np.minimum.accumulate(np.minimum(command[run] + h, y))
        else:
            seg = np.full(len(run), y)
        out[run] = seg
        y = seg[-1]
    return out


@dataclass(frozen=True)
class Backlash(Effect):
    kind: ClassVar[str] = "backlash"
    axis: str
    um: float

    def __post_init__(self) -> None:
        _axis(self.axis)

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        i = _axis(self.axis)
        c = trajectory.positions[:, i]
        out = _zeros(trajectory)
        out[:, i] = play_operator(c, trajectory.directions()[:, i], self.um * 1e-3) - c
        return out


@dataclass(frozen=True)
class LateralPlay(Effect):
    kind: ClassVar[str] = "lateral_play"
    axis: str
    um: float
    direction: str | None = None  # the sideways axis; default LATERAL_DEFAULT[axis]

    def __post_init__(self) -> None:
        _axis(self.axis)
        if self.direction is not None and _axis(self.direction, "direction") == _axis(self.axis):
            raise ValueError("lateral_play: direction must differ from axis")

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        i = _axis(self.axis)
        j = _axis(self.direction or LATERAL_DEFAULT[self.axis])
        out = _zeros(trajectory)
        out[:, j] = 0.5e-3 * self.um * trajectory.directions()[:, i]
        return out


@dataclass(frozen=True)
class ReversalSpike(Effect):
    kind: ClassVar[str] = "reversal_spike"
    axis: str
    um: float
    decay_mm: float | None = None  # path length; default 2 mm when neither is given
    decay_ms: float | None = None  # time

    def __post_init__(self) -> None:
        _axis(self.axis)
        if self.decay_mm is not None and self.decay_ms is not None:
            raise ValueError("reversal_spike: give decay_mm or decay_ms, not both")
        for v in (self.decay_mm, self.decay_ms):
            if v is not None and not v > 0:
                raise ValueError("reversal_spike: decay must be positive")

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        i = _axis(self.axis)
        out = _zeros(trajectory)
        turns = trajectory.reversals(i)
        if len(turns) == 0:
            return out
        if self.decay_ms is not None:
            clock, decay = trajectory.time * 1e3, self.decay_ms
        else:
            clock, decay = trajectory.arc_length, self.decay_mm or 2.0
        marker = np.full(len(trajectory), -1)
        marker[turns] = turns
        last = np.maximum.accumulate(marker)  # latest turning point at or before each sample
        after = last >= 0
        since = clock - clock[np.maximum(last, 0)]
        d = trajectory.directions()[:, i]
        # The turning point itself is still approached in the old direction: use −d there.
        sign = np.where(np.arange(len(trajectory)) == last, d, -d)
        out[:, i] = np.where(after, sign * self.um * 1e-3 * np.exp(-since / decay), 0.0)
        return out


@dataclass(frozen=True)
class ServoMismatch(Effect):
    kind: ClassVar[str] = "servo_mismatch"
    axes: str
    ms: float

    def __post_init__(self) -> None:
        if not isinstance(self.axes, str) or len(self.axes) != 2 or self.axes[0] == self.axes[1]:
            raise ValueError(f"servo_mismatch: axes must name two different axes, e.g. XY, not {self.axes!r}")
        _axis(self.axes[0], "axes"), _axis(self.axes[1], "axes")

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        first, second = _axis(self.axes[0]), _axis(self.axes[1])
        half_tau = 0.5e-3 * self.ms  # s
        v = trajectory.velocity
        out = _zeros(trajectory)
        out[:, first] = -v[:, first] * half_tau  # lagging: behind the command
        out[:, second] = v[:, second] * half_tau
        return out


@dataclass(frozen=True)
class Squareness(Effect):
    kind: ClassVar[str] = "squareness"
    static: ClassVar[bool] = True
    plane: str
    um_per_m: float

    def __post_init__(self) -> None:
        if self.plane not in tuple(PLANE_TERMS):
            raise ValueError(f"squareness: plane must be XY, YZ or ZX, not {self.plane!r}")

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        dev, drive = PLANE_TERMS[self.plane]
        out = _zeros(trajectory)
        out[:, dev] = self.um_per_m * 1e-6 * trajectory.positions[:, drive]
        return out


@dataclass(frozen=True)
class Straightness(Effect):
    kind: ClassVar[str] = "straightness"
    static: ClassVar[bool] = True
    axis: str
    direction: str
    um: float
    range_mm: tuple[float, float] | None = None

    def __post_init__(self) -> None:
        if _axis(self.axis) == _axis(self.direction, "direction"):
            raise ValueError("straightness: direction must differ from axis")
        if self.range_mm is not None:
            lo, hi = (float(v) for v in self.range_mm)
            if not lo < hi:
                raise ValueError("straightness: range_mm must be [lo, hi] with lo < hi")

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        i, j = _axis(self.axis), _axis(self.direction)
        k = trajectory.positions[:, i]
        lo, hi = self.range_mm if self.range_mm is not None else (k.min(), k.max())
        out = _zeros(trajectory)
        if hi > lo:
            u = np.clip((k - lo) / (hi - lo), 0.0, 1.0)
            out[:, j] = self.um * 1e-3 * 4.0 * u * (1.0 - u)
        return out


@dataclass(frozen=True)
class Cyclic(Effect):
    kind: ClassVar[str] = "cyclic"
    static: ClassVar[bool] = True
    axis: str
    um: float
    period_mm: float
    phase_deg: float = 0.0

    def __post_init__(self) -> None:
        _axis(self.axis)
        if not self.period_mm > 0:
            raise ValueError("cyclic: period_mm must be positive")

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        i = _axis(self.axis)
        out = _zeros(trajectory)
        phase = 2 * np.pi * trajectory.positions[:, i] / self.period_mm + np.deg2rad(self.phase_deg)
        out[:, i] = self.um * 1e-3 * np.sin(phase)
        return out


@dataclass(frozen=True)
class Angular(Effect):
    kind: ClassVar[str] = "angular"
    static: ClassVar[bool] = True
    component: str
    urad_per_m: float
    ref_mm: float = 0.0

    def __post_init__(self) -> None:
        info = COMPONENTS.get(self.component) if isinstance(self.component, str) else None
        if info is None or info.kind != "rotation":
            raise ValueError(
                f"angular: component must be an angular error such as ECZ, not {self.component!r}"
            )

    def apply(
        self, trajectory: Trajectory, machine: Machine | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        info = COMPONENTS[self.component]
        P = trajectory.positions
        i = AXES.index(info.axis)
        eps = np.zeros(P.shape)
        eps[:, info.index] = self.urad_per_m * 1e-9 * (P[:, i] - self.ref_mm)  # µrad/m · mm
        lever = P if machine is None else machine.abbe_offset(info.axis, P, tool_offset)
        return np.cross(eps, lever)


EFFECTS: dict[str, type[Effect]] = {
    cls.kind: cls
    for cls in (
        Scale,
        Backlash,
        LateralPlay,
        ReversalSpike,
        ServoMismatch,
        Squareness,
        Straightness,
        Cyclic,
        Angular,
    )
}
