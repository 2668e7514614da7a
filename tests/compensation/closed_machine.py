"""A machine file read the way docs/machine-file.md says, without ncpp: where the machine puts the
tool tip for axis positions, as 4x4 homogeneous transforms written out here (the judge of the
held-out machine tests, `test_machine_files.py`).

The documented convention (docs/machine-file.md, ncpp/machine/chain.py's docstring, Rahman 2004
eqs. 6-30): the chain string lists the axes from the workpiece to the tool; the tool tip in the
workpiece is the product, workpiece first, of T(k·e'_K)·T(r_K)·T(δ_K)·R(ε_K)·T(−r_K) over the axes
applied to the tool point t − L·ẑ (L: the tool length offset G43 applies); δ_K = (EXK, EYK, EZK)
and ε_K = (EAK, EBK, ECK) of the axis position k, r_K its reference point, e'_K its direction
turned by the squareness (Y about Z by C0Y, Z about X by A0Z then about Y by B0Z).  The static
effects add as the table of [[effects]] defines them."""

from __future__ import annotations

import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray
from scipy.interpolate import PchipInterpolator

AXES = "XYZ"
# ISO name -> (axis, row: 0-2 translation x y z, 3-5 rotation a b c); the thesis's spellings
ISO = {f"E{d}{a}": (a, "XYZABC".index(d)) for a in AXES for d in "XYZABC"}
ALIASES = {
    **{f"{d.lower()}{a.lower()}": f"E{d}{a}" for a in AXES for d in "XYZABC"},
    **{f"{a}{d.lower()}{a.lower()}": f"E{d}{a}" for a in AXES for d in "XYZABC"},
}
SQUARENESS_ALIASES = {"kxy": "C0Y", "kyx": "C0Y", "kxz": "B0Z", "kzx": "B0Z", "kyz": "A0Z", "kzy": "A0Z"}


def rotation(v: NDArray) -> NDArray:
    """(n,3,3) exact rotation matrices of rotation vectors (n,3) (Rodrigues with cos and sin)."""
    theta = np.linalg.norm(v, axis=1)
    safe = np.where(theta > 0, theta, 1.0)
    k = v / safe[:, None]
    K = np.zeros((len(v), 3, 3))
    K[:, 0, 1], K[:, 0, 2], K[:, 1, 2] = -k[:, 2], k[:, 1], -k[:, 0]
    K[:, 1, 0], K[:, 2, 0], K[:, 2, 1] = k[:, 2], -k[:, 1], k[:, 0]
    s, c = np.sin(theta)[:, None, None], (1 - np.cos(theta))[:, None, None]
    return np.eye(3) + s * K + c * (K @ K)


def translation(v: NDArray) -> NDArray:
    """(n,4,4) translations by (n,3)."""
    T = np.tile(np.eye(4), (len(v), 1, 1))
    T[:, :3, 3] = v
    return T


def turning(R: NDArray) -> NDArray:
    T = np.tile(np.eye(4), (len(R), 1, 1))
    T[:, :3, :3] = R
    return T


def _offset(tool_offset: NDArray | float) -> NDArray:
    """A tool length offset as a vector (a number is along Z)."""
    if np.ndim(tool_offset) == 0:
        return np.array([0.0, 0.0, float(tool_offset)])
    return np.asarray(tool_offset, float)


@dataclass
class Curve:
    """One error component: a function of its axis position, in mm or rad, per direction."""

    plus: object  # callable (n,) -> (n,)
    minus: object | None = None

    def __call__(self, k: NDArray, direction: NDArray | None) -> NDArray:
        up = self.plus(k)
        if self.minus is None:
            return up
        down = self.minus(k)
        if direction is None:
            return (up + down) / 2
        return np.where(direction > 0, up, np.where(direction < 0, down, (up + down) / 2))


def _table(positions: list[float], values: list[float], smooth: bool, scale: float):
    x, y = np.array(positions, float), np.array(values, float) * scale
    if smooth and len(x) >= 3:
        pchip = PchipInterpolator(x, y)
        return lambda k: pchip(np.clip(k, x[0], x[-1]))
    return lambda k: np.interp(k, x, y)


def _polynomial(coefficients: list[float], reference: float, span: list[float] | None, scale: float):
    c = np.array(coefficients, float) * scale

    def value(k: NDArray) -> NDArray:
        u = np.asarray(k, float) if span is None else np.clip(k, span[0], span[1])
        return sum(ci * (u - reference) ** i for i, ci in enumerate(c))

    return value


def _curve(spec: dict) -> Curve:
    """A component's table or polynomial, as the documentation's keys say (the unit in their names)."""
    unit = "um" if any(key.endswith("_um") for key in spec) else "urad"
    scale = 1e-3 if unit == "um" else 1e-6  # to mm, to rad
    if "coefficients_" + unit in spec:
        return Curve(_polynomial(spec["coefficients_" + unit], spec.get("reference_mm", 0.0),
                                 spec.get("range_mm"), scale))  # fmt: skip
    smooth = spec.get("interpolation", "linear") == "smooth"
    plus = _table(spec["positions"], spec["values_" + unit], smooth, scale)
    minus = spec.get(f"values_{unit}_minus")
    return Curve(plus, None if minus is None else _table(spec["positions"], minus, smooth, scale))


@dataclass
class ClosedMachine:
    chain: str
    tool: NDArray
    references: dict[str, NDArray]
    curves: dict[str, Curve]  # ISO name -> curve
    squareness: dict[str, float]  # C0Y, B0Z, A0Z in rad
    effects: list[dict] = field(default_factory=list)

    @classmethod
    def read(cls, path: Path) -> ClosedMachine:
        data = tomllib.loads(path.read_text())
        offsets = data.get("offsets", {})
        refs = {a: np.array(offsets.get("reference", {}).get(a, [0.0, 0.0, 0.0]), float) for a in AXES}
        curves = {}
        for name, spec in data.get("errors", {}).items():
            iso = ALIASES.get(name, ALIASES.get(name.lower(), name.upper()))
            curves[iso] = _curve(spec)
        square = {"C0Y": 0.0, "B0Z": 0.0, "A0Z": 0.0}
        for key, value in data.get("squareness", {}).items():  # `_urad` and `_um_per_m` say the same number
            name = re.sub(r"_(urad|um_per_m)$", "", key)
            square[SQUARENESS_ALIASES.get(name.lower(), name.upper())] = value * 1e-6
        return cls(data["machine"]["chain"].upper(), np.array(offsets.get("tool", [0.0, 0.0, 0.0]), float),
                   refs, curves, square, list(data.get("effects", [])))  # fmt: skip

    def motions(self, axis: str, k: NDArray, direction: NDArray | None) -> tuple[NDArray, NDArray]:
        """(n,3) translation δ in mm and (n,3) rotation ε in rad of one axis at positions k."""
        out = np.zeros((len(k), 6))
        for iso, curve in self.curves.items():
            if ISO[iso][0] == axis:
                out[:, ISO[iso][1]] += curve(k, direction)
        for effect in self.effects:  # the static effects the model treats as error motions
            if effect["kind"] == "angular" and ISO[effect["component"]][0] == axis:
                out[:, ISO[effect["component"]][1]] += (
                    effect["urad_per_m"] * 1e-9 * (k - effect.get("ref_mm", 0.0))
                )
        return out[:, :3], out[:, 3:]

    def direction(self, axis: str) -> NDArray:
        """e'_K: the axis's unit direction turned by the squareness."""
        e = np.eye(3)[AXES.index(axis)]
        if axis == "Y":
            return rotation(np.array([[0.0, 0.0, self.squareness["C0Y"]]]))[0] @ e
        if axis == "Z":
            return rotation(np.array([[self.squareness["A0Z"], self.squareness["B0Z"], 0.0]]))[0] @ e
        return e

    def tip(
        self, P: NDArray, tool_offset: NDArray | float = 0.0, direction: NDArray | None = None
    ) -> NDArray:
        """(n,3) the actual tool tip in the workpiece, for axis positions P (n,3) with the tool length
        offset (a number: along Z; or (3,) or (n,3)) in effect; `direction` (n,3) each axis's travel
        sign or None."""
        n = len(P)
        product = np.tile(np.eye(4), (n, 1, 1))
        for axis in self.chain.replace("F", ""):
            i = AXES.index(axis)
            k = P[:, i]
            delta, eps = self.motions(axis, k, None if direction is None else direction[:, i])
            r = np.tile(self.references[axis], (n, 1))
            step = translation(k[:, None] * self.direction(axis)) @ translation(r) @ translation(delta)
            product = product @ step @ turning(rotation(eps)) @ translation(-r)
        point = np.ones((n, 4))
        point[:, :3] = self.tool - _offset(tool_offset)
        tip = np.einsum("nij,nj->ni", product, point)[:, :3]
        return tip + self.static_effects(P)

    def reached(
        self, P: NDArray, tool_offset: NDArray | float = 0.0, direction: NDArray | None = None
    ) -> NDArray:
        """Where the tool tip goes, as the axis positions that would put an ideal machine's tip there."""
        return self.tip(P, tool_offset, direction) - self.tool + _offset(tool_offset)

    def static_effects(self, P: NDArray) -> NDArray:
        """(n,3) mm the position-only [[effects]] add, as docs/machine-file.md defines each."""
        out = np.zeros(P.shape)
        for e in self.effects:
            kind = e["kind"]
            if kind == "scale":
                i = AXES.index(e["axis"])
                out[:, i] += e["um_per_m"] * 1e-6 * (P[:, i] - e.get("ref_mm", 0.0))
            elif kind == "cyclic":
                i = AXES.index(e["axis"])
                angle = 2 * np.pi * P[:, i] / e["period_mm"] + np.radians(e.get("phase_deg", 0.0))
                out[:, i] += e["um"] * 1e-3 * np.sin(angle)
            elif kind == "squareness":
                deviating, driving = {"XY": (0, 1), "YZ": (1, 2), "ZX": (2, 0)}[e["plane"]]
                out[:, deviating] += e["um_per_m"] * 1e-6 * P[:, driving]
            elif kind == "straightness":
                lo, hi = e["range_mm"]
                u = (P[:, AXES.index(e["axis"])] - lo) / (hi - lo)
                out[:, AXES.index(e["direction"])] += e["um"] * 1e-3 * 4 * u * (1 - u)
        return out
