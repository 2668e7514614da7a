"""The candidate effects of the diagnosis report's effect table.

A `Candidate` is one effect kind with its axis/plane/component fixed and its
shape parameters (cyclic period, spike decay, straightness range) fixed per
variant.  Its free parameters enter (nearly) linearly: the columns of the
least-squares problem are the readings its `basis` effects add; coefficients
`c` on the basis give the effect `build(c)`.  Backlash is the only one that is
not exactly linear in its size (the play operator's take-up arc is as long as
the play), so its basis is re-evaluated at the current estimate (`relinearise`).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import partial
from typing import Any

import numpy as np
from numpy.typing import NDArray

from ncpp.machine.components import COMPONENTS
from ncpp.machine.effects import (
    Angular,
    Backlash,
    Cyclic,
    Effect,
    LateralPlay,
    ReversalSpike,
    Scale,
    ServoMismatch,
    Squareness,
    Straightness,
)

SCREW_LEADS_MM = (4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 16.0, 20.0, 25.0, 32.0, 40.0)
SPIKE_DECAYS_MM = (0.5, 1.0, 2.0, 4.0, 8.0)
AXES = ("X", "Y", "Z")
PLANES = ("XY", "YZ", "ZX")
ANGULAR = tuple(n for n, c in COMPONENTS.items() if c.kind == "rotation")


@dataclass(frozen=True)
class Candidate:
    kind: str
    keys: dict[str, str]  # the report's keys: axis | axes | plane | axis+direction | component
    unit: str  # the report's parameter key of the size
    basis: tuple[Effect, ...]
    build: Callable[[NDArray], Effect]
    variant: str = ""  # shape parameters of this variant, for the account
    nonlinear: bool = False

    @property
    def name(self) -> str:
        return f"{self.kind} {' '.join(self.keys.values())}"

    def parameters(self, coef: NDArray, cov: NDArray) -> tuple[dict[str, float], dict[str, float]]:
        """The report's parameters and their standard uncertainties from the
        basis coefficients and their covariance."""
        effect = self.build(coef)
        if isinstance(effect, Cyclic):  # the cyclic candidates build one
            amp = float(np.hypot(*coef))
            g = coef / amp if amp > 0 else np.array([1.0, 0.0])
            return (
                {"um": amp, "period_mm": effect.period_mm},
                {"um": float(np.sqrt(max(g @ cov @ g, 0.0)))},
            )
        size = float(getattr(effect, self.unit))
        scale = size / coef[0] if coef[0] != 0 else 1.0
        return {self.unit: size}, {self.unit: float(abs(scale) * np.sqrt(max(cov[0, 0], 0.0)))}

    def relinearise(self, coef: NDArray) -> Candidate:
        """The same candidate with its basis at the current estimate (backlash)."""
        if not self.nonlinear:
            return self
        size = float(getattr(self.build(coef), self.unit))
        if abs(size) < 0.05:
            return self
        assert isinstance(self.basis[0], Backlash), "backlash is the only nonlinear candidate"
        axis = self.keys["axis"]
        return Candidate(self.kind, self.keys, self.unit, (Backlash(axis, size),),
                         lambda c: Backlash(axis, c[0] * size), self.variant, True)  # fmt: skip


def _one(kind: str, keys: dict[str, str], unit: str, make: Callable[[float], Effect], size: float,
         variant: str = "", nonlinear: bool = False) -> Candidate:  # fmt: skip
    return Candidate(kind, keys, unit, (make(size),), lambda c: make(float(c[0]) * size), variant, nonlinear)


def _cyclic(axis: str, period: float) -> Candidate:
    basis = (Cyclic(axis, 1.0, period, 0.0), Cyclic(axis, 1.0, period, 90.0))

    def build(c: NDArray) -> Cyclic:
        # a·sin(φ) + b·cos(φ) = √(a²+b²)·sin(φ + atan2(b, a))
        return Cyclic(axis, float(np.hypot(c[0], c[1])), period, float(np.degrees(np.arctan2(c[1], c[0]))))

    return Candidate("cyclic", {"axis": axis}, "um", basis, build, f"period {period:g} mm")


def cyclic_variant(axis: str, period: float) -> Candidate:
    return _cyclic(axis, period)


def candidates(extent: dict[str, tuple[float, float]]) -> list[list[Candidate]]:
    """All candidates, grouped: each inner list holds the variants of one
    (kind, keys).  `extent` is the tested range per axis (straightness over it)."""
    out: list[list[Candidate]] = []
    for a in AXES:
        out.append([_one("scale", {"axis": a}, "um_per_m", partial(Scale, a), 10.0)])
    for a in AXES:
        out.append([_one("backlash", {"axis": a}, "um", partial(Backlash, a), 5.0, nonlinear=True)])
    for a in AXES:
        for d in AXES:
            if d != a:
                out.append([_one("lateral_play", {"axis": a}, "um", partial(LateralPlay, a, direction=d), 5.0,
                                 f"sideways along {d}")])  # fmt: skip
    for a in AXES:
        out.append([
            _one("reversal_spike", {"axis": a}, "um", partial(ReversalSpike, a, decay_mm=k), 5.0,
                 f"decay {k:g} mm")
            for k in SPIKE_DECAYS_MM
        ])  # fmt: skip
    for axes in PLANES:
        out.append([_one("servo_mismatch", {"axes": axes}, "ms", partial(ServoMismatch, axes), 1.0)])
    for p in PLANES:
        out.append([_one("squareness", {"plane": p}, "um_per_m", partial(Squareness, p), 10.0)])
    for a in AXES:
        for d in AXES:
            if d == a:
                continue
            variants = [_one("straightness", {"axis": a, "direction": d}, "um",
                             partial(Straightness, a, d), 5.0, "over each test's own extent")]  # fmt: skip
            if a in extent:
                r = extent[a]
                variants.append(_one("straightness", {"axis": a, "direction": d}, "um",
                                     partial(Straightness, a, d, range_mm=r), 5.0,
                                     f"over {r[0]:g}..{r[1]:g} mm"))  # fmt: skip
            out.append(variants)
    for a in AXES:
        out.append([_cyclic(a, p) for p in SCREW_LEADS_MM])
    for c in ANGULAR:
        out.append([_one("angular", {"component": c}, "urad_per_m", partial(Angular, c), 20.0)])
    return out


def effect_record(effect: Effect) -> dict[str, Any]:
    return effect.to_dict()


def flatten(groups: Sequence[Sequence[Candidate]]) -> list[Candidate]:
    return [c for g in groups for c in g]
