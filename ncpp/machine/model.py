"""`Machine`: chain, offsets, limits, error components and effects as one value.

A Machine is immutable; `with_components` and `replace` return new ones.
Conventions (frames, signs, the chain product) are in `ncpp.machine.chain`;
component names in `ncpp.machine.components`.  Rahman 2004: M. Rahman, *Modeling and
measurement of multi-axis machine tools to improve positioning accuracy in a software
way*, University of Oulu, 2004.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property, partial
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ncpp.machine.chain import (
    Chain,
    abbe_offset,
    direction_errors,
    exact_deviation,
    linear_deviation,
    squareness_vectors,
)
from ncpp.machine.components import (
    AXES,
    COMPONENTS,
    SQUARENESS,
    Component,
    StackedTables,
    Table,
    canonical_name,
)

if TYPE_CHECKING:
    from ncpp.machine.curvature import BowBound
    from ncpp.machine.effects import Effect
    from ncpp.machine.trajectory import Trajectory

Vec3 = tuple[float, float, float]
# points per block: the kernels' dozens of (n,3) temporaries stay in a core's second-level cache,
# which a larger block overflows (more time a point, not less)
CHUNK = 2048


def _vec3(value: ArrayLike, what: str) -> Vec3:
    arr = np.asarray(value, dtype=float).ravel()
    if arr.shape != (3,) or not np.all(np.isfinite(arr)):
        raise ValueError(f"{what} must be three finite numbers [x, y, z]")
    return (float(arr[0]), float(arr[1]), float(arr[2]))


def as_points(P: ArrayLike) -> NDArray:
    """(n,3) float array of axis positions; a single (3,) point becomes (1,3)."""
    arr = np.asarray(P, dtype=float)
    if arr.ndim == 1:
        arr = arr[None, :]
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise ValueError(f"positions must have shape (n, 3), got {np.shape(P)}")
    return arr


def _motion_row(name: str) -> int:
    """The row of a component in `Machine.error_motions`' (6, n) motions: δx δy δz εx εy εz."""
    info = COMPONENTS[name]
    return info.index + (0 if info.kind == "translation" else 3)


MOTION_ROWS = list(range(6))  # the rows of an axis whose six components are all tables


def _per_point(values: ArrayLike, shape: tuple[int, ...]) -> NDArray:
    """Values as a float array of `shape`, broadcast (not copied) if they are not that
    shape already: np.broadcast_to's own overhead shows on calls of a few points."""
    arr = np.asarray(values, dtype=float)
    return arr if arr.shape == shape else np.broadcast_to(arr, shape)


def _shaped_like(result: NDArray, P: ArrayLike) -> NDArray:
    return result[0] if np.ndim(P) == 1 else result


@dataclass(frozen=True)
class Machine:
    """A three-axis machine's geometric error model.

    Fields are in model units (mm, rad).  `components` maps ISO names
    (EXX, ..., ECZ) to a `Table` or `Polynomial`; absent components are zero.
    `squareness` maps C0Y, B0Z, A0Z to angles in rad."""

    name: str
    chain: str
    tool: Vec3 = (0.0, 0.0, 0.0)  # the tool point with no tool length offset in effect (G49): the gauge point
    work: Vec3 = (0.0, 0.0, 0.0)
    references: Mapping[str, Vec3] = field(default_factory=dict)
    limits: Mapping[str, tuple[float, float]] = field(default_factory=dict)
    components: Mapping[str, Component] = field(default_factory=dict)
    squareness: Mapping[str, float] = field(default_factory=dict)
    effects: tuple[Effect, ...] = ()
    max_correction_mm: float = 0.5
    meta: Mapping[str, Any] = field(default_factory=dict)
    # The programmed X Y Z are the linear axes' positions also while a rotary axis turns (no
    # tool-centre-point kinematics): moves that turn A, B or C may be compensated
    rotary_xyz_are_axis_positions: bool = False
    kinematics_m_codes: tuple[int, ...] = ()  # M codes that switch the control's kinematics (refused)

    def __post_init__(self) -> None:
        setter = lambda name, value: object.__setattr__(self, name, value)  # noqa: E731
        setter("chain", Chain(self.chain).text)
        setter("tool", _vec3(self.tool, "tool offset"))
        setter("work", _vec3(self.work, "work offset"))
        refs = {}
        for axis, r in self.references.items():
            if axis not in AXES:
                raise ValueError(f"reference point for unknown axis {axis!r}")
            refs[axis] = _vec3(r, f"reference point of {axis}")
        setter("references", {a: refs.get(a, (0.0, 0.0, 0.0)) for a in AXES})
        limits = {}
        for axis, lim in self.limits.items():
            if axis not in AXES:
                raise ValueError(f"limits for unknown axis {axis!r}")
            lo, hi = (float(v) for v in lim)
            if not lo < hi:
                raise ValueError(f"limits of {axis} must be [lo, hi] with lo < hi")
            limits[axis] = (lo, hi)
        setter("limits", {a: limits.get(a, (-math.inf, math.inf)) for a in AXES})
        comps = {}
        for name, comp in self.components.items():
            iso = canonical_name(name)
            if iso not in COMPONENTS:
                raise ValueError(f"{name} is a squareness; give it in `squareness`")
            if comp is not None:
                comps[iso] = comp
        order = list(COMPONENTS)  # axis by axis: EXX EYX EZX EAX EBX ECX EXY ...
        setter("components", dict(sorted(comps.items(), key=lambda item: order.index(item[0]))))
        sq = {}
        for name, value in self.squareness.items():
            iso = canonical_name(name)
            if iso not in SQUARENESS:
                raise ValueError(f"{name} is not a squareness (C0Y, B0Z, A0Z)")
            sq[iso] = float(value)
        setter("squareness", {k: sq.get(k, 0.0) for k in SQUARENESS})
        setter("effects", tuple(self.effects))
        setter("max_correction_mm", float(self.max_correction_mm))
        if not self.max_correction_mm > 0:
            raise ValueError("max_correction_mm must be positive")

    # ----------------------------------------------------------------- shape
    @property
    def axes(self) -> tuple[str, ...]:
        """Axes in chain order, workpiece to tool."""
        return Chain(self.chain).order

    def component(self, name: str) -> Component | None:
        return self.components.get(canonical_name(name))

    def within_limits(self, P: ArrayLike) -> NDArray:
        """Boolean per point: every axis inside its travel."""
        pts = as_points(P)
        ok = np.ones(len(pts), dtype=bool)
        for i, axis in enumerate(AXES):
            lo, hi = self.limits[axis]
            ok &= (pts[:, i] >= lo) & (pts[:, i] <= hi)
        return _shaped_like(ok, P)

    # ------------------------------------------------------------ evaluation
    @cached_property
    def _evaluators(self) -> dict[str, tuple[StackedTables | None, list[int], list[tuple[int, Component]]]]:
        """Per axis: its tables stacked for one-pass evaluation with the row of each
        in `error_motions`' (6, n) motions, and the other components with theirs."""
        out: dict[str, tuple[StackedTables | None, list[int], list[tuple[int, Component]]]] = {}
        for axis in AXES:
            mine = [(_motion_row(n), c) for n, c in self.components.items() if COMPONENTS[n].axis == axis]
            tables = [(row, c) for row, c in mine if isinstance(c, Table)]
            stacked = StackedTables([c for _, c in tables]) if tables else None
            out[axis] = (
                stacked,
                [row for row, _ in tables],
                [(row, c) for row, c in mine if not isinstance(c, Table)],
            )
        return out

    @cached_property
    def bow_bound(self) -> BowBound | None:
        """Bounds of the second derivative of `static_deviation` along segments
        (`curvature.BowBound`), or None where the errors may not be smooth."""
        from ncpp.machine.curvature import BowBound

        return BowBound.of(self)

    @cached_property
    def ripple(self) -> NDArray:
        """(3,) per axis X Y Z, a bound of the second derivative (1/mm) of the static errors that
        repeat along the axis faster than a line's samples see (`curvature.ripple`)."""
        from ncpp.machine.curvature import ripple

        return ripple(self)

    def error_motions(
        self, P: ArrayLike, direction: ArrayLike | None = None
    ) -> tuple[dict[str, NDArray], dict[str, NDArray]]:
        """Per axis, the translation δ_K (n,3) mm and rotation ε_K (n,3) rad at P."""
        pts = as_points(P)
        dirs = None if direction is None else _per_point(direction, pts.shape)
        delta, eps = {}, {}
        for i, axis in enumerate(AXES):
            stacked, rows, others = self._evaluators[axis]
            p, d = pts[:, i], None if dirs is None else dirs[:, i]
            values = None if stacked is None else stacked(p, d)
            if values is not None and rows == MOTION_ROWS:
                motions = values  # all six are tables: their values are the motions, as they are
            else:
                motions = np.zeros(
                    (6, len(pts))
                )  # δx δy δz εx εy εz, each row contiguous (see chain.columns)
                if values is not None:
                    motions[rows] = values
                for row, component in others:
                    motions[row] = component(p, d)
            delta[axis], eps[axis] = motions[:3].T, motions[3:].T
        return delta, eps

    def _kinematics(self, pts: NDArray, dirs: NDArray | None, tool_offset: NDArray | None = None):
        delta, eps = self.error_motions(pts, dirs)
        chain, tool, refs, sq = self._frame
        # the control's tool length offset: the axes are that much further, the tip that much nearer
        return chain, pts, tool if tool_offset is None else tool - tool_offset, refs, delta, eps, sq

    @cached_property
    def _frame(self) -> tuple:
        """The parts of the kinematics that do not depend on the position."""
        refs = {a: np.asarray(r) for a, r in self.references.items()}
        sq = squareness_vectors(self.squareness["C0Y"], self.squareness["B0Z"], self.squareness["A0Z"])
        return Chain(self.chain), np.asarray(self.tool), refs, sq

    @cached_property
    def _directions(self) -> dict[str, NDArray]:
        """The axes' direction errors from squareness (chain.direction_errors), once."""
        return direction_errors(self._frame[3])

    def _blockwise(
        self, kernel, P: ArrayLike, direction: ArrayLike | None, tool_offset: ArrayLike | None = None
    ) -> NDArray:
        pts = np.ascontiguousarray(as_points(P).T).T  # columns contiguous, like the algebra
        dirs = None if direction is None else _per_point(direction, pts.shape)
        tools = None if tool_offset is None else _per_point(tool_offset, pts.shape)
        out = np.empty(pts.shape)
        for start in range(0, len(pts), CHUNK):
            block = slice(start, start + CHUNK)
            out[block] = kernel(
                *self._kinematics(
                    pts[block], None if dirs is None else dirs[block], None if tools is None else tools[block]
                )
            )
        return _shaped_like(out, P)

    def deviation(
        self, P: ArrayLike, direction: ArrayLike | None = None, tool_offset: ArrayLike | None = None
    ) -> NDArray:
        """Actual minus nominal tool point relative to the workpiece, mm.

        P: (n,3) axis positions X, Y, Z in mm (or one (3,) point).
        direction: optional (n,3) travel signs +1/−1/0 for direction-dependent
        tables (None or 0: the mean of the + and − tables).
        tool_offset: optional (n,3) tool length offsets in effect (the control's
        G43), mm: the tool point is `tool` minus it, a longer Abbe arm for a longer tool."""
        return self._blockwise(
            partial(exact_deviation, directions=self._directions), P, direction, tool_offset
        )

    def static_deviation(
        self, P: ArrayLike, direction: ArrayLike | None = None, tool_offset: ArrayLike | None = None
    ) -> NDArray:
        """Geometric deviation plus the effects that depend on position alone
        (scale, squareness, straightness, cyclic, angular), mm: what
        compensation can cancel.  A straightness bow without `range_mm` spans
        the axis travel."""
        from ncpp.machine.effects import Straightness
        from ncpp.machine.trajectory import Trajectory

        pts = as_points(P)
        total = self.deviation(pts, direction, tool_offset)
        static = [e for e in self.effects if e.static]
        if static and len(pts):
            padded = pts if len(pts) >= 2 else np.vstack([pts, pts])
            tools = None if tool_offset is None else _per_point(tool_offset, padded.shape)
            trajectory = Trajectory(padded, 1000.0)
            for effect in static:
                if isinstance(effect, Straightness) and effect.range_mm is None:
                    lo, hi = self.limits.get(effect.axis, (-math.inf, math.inf))
                    if math.isfinite(lo) and math.isfinite(hi):
                        effect = dataclasses.replace(effect, range_mm=(lo, hi))
                total = total + effect.apply(trajectory, self, tools)[: len(pts)]
        return _shaped_like(total, P)

    def deviation_linear(self, P: ArrayLike, direction: ArrayLike | None = None) -> NDArray:
        """First-order deviation (Rahman 2004, eqs. 28–30), mm."""
        return self._blockwise(linear_deviation, P, direction)

    def abbe_offset(self, axis: str, P: ArrayLike, tool_offset: ArrayLike | None = None) -> NDArray:
        """Lever arm L_K (mm) through which axis K's rotation moves the tool point; `tool_offset`:
        (n,3) tool length offsets in effect, as in `deviation` (the tip that much nearer)."""
        pts = as_points(P)
        tool = np.asarray(self.tool)
        tool = tool if tool_offset is None else tool - _per_point(tool_offset, pts.shape)
        return _shaped_like(
            abbe_offset(Chain(self.chain), axis, pts, tool, np.asarray(self.references[axis])), P
        )

    def rotation(self, P: ArrayLike, direction: ArrayLike | None = None) -> NDArray:
        """Rotation vector (rad) of the tool relative to the workpiece, (n,3).

        What a laser's angular optics read as pitch/yaw between the two
        members: the composition of every axis's ε in chain order."""
        return _shaped_like(self._compose(P, direction, self.axes, sign=1.0), P)

    def member_rotation(self, member: str, P: ArrayLike, direction: ArrayLike | None = None) -> NDArray:
        """Rotation (rad) of a member relative to the frame, as a level on it reads.

        member: 'work' (the workpiece/table), 'tool', or an axis letter (that
        carriage).  A workpiece-side carriage turns by −ε (the error motions are
        of the tool relative to the workpiece)."""
        chain = Chain(self.chain)
        if member == "work":
            member = chain.work_side[0] if chain.work_side else "F"
        elif member == "tool":
            member = chain.tool_side[-1] if chain.tool_side else "F"
        if member == "F":
            return _shaped_like(np.zeros(as_points(P).shape), P)
        if member not in AXES:
            raise ValueError(f"member must be 'work', 'tool' or an axis letter, not {member!r}")
        if chain.side(member) == "tool":
            path = chain.tool_side[: chain.tool_side.index(member) + 1]
            return _shaped_like(self._compose(P, direction, path, sign=1.0), P)
        # Frame to carriage on the workpiece side: B_1 ... B_K with R(ε)^-1 each.
        path = chain.work_side[chain.work_side.index(member) :][::-1]
        return _shaped_like(self._compose(P, direction, path, sign=-1.0), P)

    def _compose(self, P, direction, axes, sign: float) -> NDArray:
        from scipy.spatial.transform import Rotation

        _, eps = self.error_motions(P, direction)
        total = Rotation.identity(len(as_points(P)))
        for axis in axes:
            total = total * Rotation.from_rotvec(sign * eps[axis])
        return total.as_rotvec()

    def simulate(self, trajectory: Trajectory, tool_offset: ArrayLike | None = None) -> NDArray:
        """Actual tool positions (n,3) mm along a sampled trajectory: command +
        geometric deviation (direction of travel from the trajectory; `tool_offset`
        (n,3): the tool length offsets in effect, as in `deviation`) + effects."""
        pts = trajectory.positions
        actual = pts + self.deviation(pts, trajectory.directions(), tool_offset)
        tools = None if tool_offset is None else _per_point(tool_offset, pts.shape)
        for effect in self.effects:
            actual = actual + effect.apply(trajectory, self, tools)
        return actual

    # ---------------------------------------------------------------- values
    def with_components(self, **updates: Component | float | None) -> Machine:
        """New machine with components (ISO or Rahman 2004 names) replaced; None removes.
        Squareness names take an angle in rad."""
        comps = dict(self.components)
        sq = dict(self.squareness)
        for name, value in updates.items():
            iso = canonical_name(name)
            if iso in SQUARENESS:
                sq[iso] = 0.0 if value is None else float(value)  # type: ignore[arg-type]
            elif value is None:
                comps.pop(iso, None)
            else:
                comps[iso] = value  # type: ignore[assignment]
        return dataclasses.replace(self, components=comps, squareness=sq)

    def replace(self, **changes: Any) -> Machine:
        """New machine with fields replaced (dataclasses.replace, validated)."""
        return dataclasses.replace(self, **changes)

    def without_errors(self) -> Machine:
        """The same structure with no errors and no effects (the ideal machine)."""
        return dataclasses.replace(self, components={}, squareness={}, effects=())
