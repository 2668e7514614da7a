"""The kinematic chain and the volumetric error (Rahman 2004, eqs. 6–30).

Rahman 2004: M. Rahman, *Modeling and measurement of multi-axis machine tools to improve positioning
accuracy in a software way*, University of Oulu, 2004.

Chain string
------------
The axes from the workpiece to the tool through the frame ``F``:
``XZFY`` (Mitsui Seiki HR5B) = workpiece on X, X on Z, Z on the frame; Y on
the frame, tool on Y.  ``XYFZ`` (TL-Tuotanto), ``XFYZ`` (Valmet) likewise.

Coordinates
-----------
Machine coordinates are the frame's axes with every carriage at axis
position 0; every carriage frame coincides with them there.  A command
``P = (x, y, z)`` is the axis positions.  Nominally the tool point sits at
``P + t`` relative to the workpiece, ``t`` being the tool point in the tool
carriage (tool length vector, e.g. ``(0, 0, -200)`` for a 200 mm tool
pointing down).  The axes are the tool's motion relative to the workpiece,
as the programmer sees them: a table axis physically moves the table by
``−x``.

Error motions
-------------
Each axis K contributes a rigid-body error motion of the tool relative to
the workpiece: a translation δ_K = (EXK, EYK, EZK) and a small rotation
ε_K = (EAK, EBK, ECK), both functions of the axis position k.  The
translation is the one seen at the axis reference point r_K, a point fixed
to the tool-side member of the axis's joint (the carriage itself for an axis
on the tool side of F; the carriage it rides on, or the frame, for an axis
on the workpiece side).  That is where a laser or straightedge reading taken
at the tool sees it, so measured tables go in as they are; put r_K where
the axis was measured (Fig. 6's axis reference points).  As a transform:

    E_K = T(r_K) · T(δ_K) · R(ε_K) · T(−r_K)

Squareness turns the direction of an axis's motion: e'_K = R(S_K)·e_K with
S_X = 0, S_Y = (0, 0, C0Y), S_Z = (A0Z, B0Z, 0).

Composition
-----------
For a tool-side axis the carriage pose in its parent is T(k·e'_K)·E_K; for a
workpiece-side axis the tool, seen from the carriage, is T(k·e'_K)·E_K
applied to where it sits in the parent (the inverse of the carriage pose).
Both reduce to one product in chain-string order, workpiece first:

    tool point in the workpiece = Π_{K in chain order} [T(k·e'_K)·E_K] · t

The deviation E(P) is that minus ``P + t``, in workpiece coordinates (the
work point only moves the origin, so it does not enter).  Rotations are the
exact rotation for the rotation vector ε (Rodrigues, series form: the
errors are micro-radians); Rahman 2004's I + [ε]× differs by terms of order
ε², far below a micron.  Keeping only first-order terms gives eqs. 28–30:

    E_lin(P) = Σ_K  δ_K + ε_K × L_K + k·(S_K × e_K),
    L_K = t + Σ_{J right of K in the chain} j·e_J − r_K   (the Abbe offset)

Where F sits
------------
With error motions measured at the tool-side member of each joint, the
relative motion of tool and workpiece depends only on the order of the axes,
not on which member is bolted to the floor (rigid bodies do not care).  F
still matters for what an instrument fixed to one member reads against
gravity (a level): `member_rotation` gives the rotation of the workpiece or
a tool-side carriage relative to the frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ncpp.machine.components import AXES

UNIT = np.eye(3)
SMALL_ANGLE = 0.01  # rad: the rotation series (`rodrigues`) are exact in double precision below it


@dataclass(frozen=True)
class Chain:
    """A validated chain string such as ``XZFY``."""

    text: str

    def __post_init__(self) -> None:
        text = self.text.strip().upper()
        if sorted(text) != sorted("XYZF"):
            raise ValueError(
                f"chain {self.text!r} must hold X, Y, Z and the frame F once each, "
                "from workpiece to tool (e.g. XZFY, XYFZ, XFYZ)"
            )
        object.__setattr__(self, "text", text)

    def __str__(self) -> str:
        return self.text

    @property
    def order(self) -> tuple[str, ...]:
        """Axes from the workpiece to the tool (the product order)."""
        return tuple(c for c in self.text if c != "F")

    @property
    def work_side(self) -> tuple[str, ...]:
        """Axes carrying the workpiece, from the workpiece to the frame."""
        return tuple(self.text[: self.text.index("F")])

    @property
    def tool_side(self) -> tuple[str, ...]:
        """Axes carrying the tool, from the frame to the tool."""
        return tuple(self.text[self.text.index("F") + 1 :])

    def side(self, axis: str) -> str:
        return "work" if axis in self.work_side else "tool"

    def outboard(self, axis: str) -> tuple[str, ...]:
        """Axes between this axis's joint and the tool: they set its Abbe offset."""
        order = self.order
        return order[order.index(axis) + 1 :]


def columns(n: int) -> NDArray:
    """An (n,3) array stored column by column: each coordinate contiguous,
    which is what the column-wise vector algebra here reads and writes."""
    return np.empty((3, n)).T


def cyclic(n: int) -> NDArray:
    """An empty (n,5) array for x y z x y, stored column by column: once `wrap`ped,
    [:, 1:4] and [:, 2:5] are the components turned by one and by two places, as views."""
    return np.empty((5, n)).T


def wrap(v: NDArray) -> NDArray:
    """Copy the x, y of a `cyclic` array after its z; return it."""
    v[:, 3:] = v[:, :2]
    return v


def as_cyclic(v: NDArray) -> NDArray:
    """An (n,3) array copied into a `wrap`ped `cyclic` one."""
    out = cyclic(len(v))
    out[:, :3] = v
    return wrap(out)


def cyclic_cross(a: NDArray, b: NDArray, out: NDArray) -> NDArray:
    """a × b of `cyclic` a and b into (n,3) out: each component a_j·b_k − a_k·b_j,
    the three at once (numpy's call overhead, not the arithmetic, is most of the time)."""
    np.multiply(a[:, 1:4], b[:, 2:5], out=out)
    out -= a[:, 2:5] * b[:, 1:4]
    return out


def norm3(vectors: NDArray) -> NDArray:
    """Lengths of (..., 3) vectors: `np.linalg.norm(vectors, axis=-1)` (bit for bit: the same
    sum in the same order), without its reduction over a short last axis (several times slower)."""
    squares = vectors * vectors
    return np.sqrt((squares[..., 0] + squares[..., 1]) + squares[..., 2])


def cross(a: NDArray, b: NDArray) -> NDArray:
    """Row-wise a × b for (n,3) arrays (np.cross is several times slower)."""
    return cyclic_cross(as_cyclic(a), as_cyclic(b), columns(len(a)))


def rotate_minus_identity(eps: NDArray, v: NDArray) -> NDArray:
    """(R(ε) − I)·v for rotation vectors ε, row-wise, without cancellation."""
    a, b = rodrigues(eps.T)
    return rotate_cyclic(as_cyclic(eps), as_cyclic(v), a[:, None], b[:, None])


def rodrigues(eps: NDArray) -> tuple[NDArray, NDArray]:
    """The factors a = sinθ/θ and b = (1−cosθ)/θ² of rotation vectors ε (…, 3, n), (…, n).

    Rodrigues: R v = v + a ε×v + b ε×(ε×v); the series below are exact in
    double precision for θ < SMALL_ANGLE (0.01 rad)."""
    squares = eps * eps
    th2 = squares[..., 0, :] + squares[..., 1, :] + squares[..., 2, :]
    return 1.0 - th2 * (1.0 / 6.0 - th2 / 120.0), 0.5 - th2 * (1.0 / 24.0 - th2 / 720.0)


def rotate_cyclic(eps: NDArray, v: NDArray, a: NDArray, b: NDArray) -> NDArray:
    """(R(ε) − I)·v = a ε×v + b ε×(ε×v) of `cyclic` ε and v, with ε's `rodrigues`
    factors as (n,1); (n,3)."""
    ev = cyclic(len(v))
    cyclic_cross(eps, v, ev[:, :3])
    wrap(ev)
    out = cyclic_cross(eps, ev, columns(len(v)))
    out *= b
    ev = ev[:, :3]
    ev *= a
    out += ev
    return out


def squareness_vectors(c0y: float, b0z: float, a0z: float) -> dict[str, NDArray]:
    """Rotation vector S_K turning each axis's direction."""
    return {"X": np.zeros(3), "Y": np.array([0.0, 0.0, c0y]), "Z": np.array([a0z, b0z, 0.0])}


def direction_errors(squareness: dict[str, NDArray]) -> dict[str, NDArray]:
    """e'_K − e_K, the exact change of each axis's unit direction."""
    out = {}
    for i, axis in enumerate(AXES):
        e = UNIT[i][None, :]
        out[axis] = rotate_minus_identity(squareness[axis][None, :], e)[0]
    return out


def abbe_offset(chain: Chain, axis: str, P: NDArray, tool: NDArray, reference: NDArray) -> NDArray:
    """L_K: nominal tool point in the axis's tool-side member minus r_K, (n,3)."""
    lever = np.broadcast_to(tool - reference, P.shape).copy()
    for j in chain.outboard(axis):
        lever[:, AXES.index(j)] += P[:, AXES.index(j)]
    return lever


def exact_deviation(
    chain: Chain,
    P: NDArray,
    tool: NDArray,
    references: dict[str, NDArray],
    delta: dict[str, NDArray],
    eps: dict[str, NDArray],
    squareness: dict[str, NDArray],
    directions: dict[str, NDArray] | None = None,
) -> NDArray:
    """Full homogeneous-transform chain: actual minus nominal tool point, (n,3) mm.

    Walks the product from the tool end, carrying w = actual − nominal of the
    partial product so that microns are never the difference of metres.
    `directions`: `direction_errors(squareness)`, when the caller keeps them."""
    dir_err = direction_errors(squareness) if directions is None else directions
    n = len(P)
    # What does not depend on the walk, for the three axes at once (numpy's per-call overhead
    # is much of the time on a few thousand points): each axis's ε made `cyclic`, its Rodrigues
    # factors, and k·(e'_K − e_K), each axis's (3, n) block seen as (n,3) by `.T`.
    e = np.empty((3, 5, n))
    for k, axis in enumerate(AXES):
        e[k, :3] = eps[axis].T
    e[:, 3:] = e[:, :2]
    a, b = rodrigues(e[:, :3])
    moved = P.T[:, None, :] * np.array([dir_err[axis] for axis in AXES])[:, :, None]
    nominal = columns(n)
    nominal[:] = tool
    w = columns(n)
    w[:] = 0.0
    lever = cyclic(n)
    arm = lever[:, :3]
    for axis in reversed(chain.order):
        k = AXES.index(axis)
        np.subtract(nominal, references[axis], out=arm)
        arm += w
        # w + k·e' + δ + (R(ε) − I)·lever, summed in that order
        step = moved[k].T
        step += w
        step += delta[axis]
        step += rotate_cyclic(e[k].T, wrap(lever), a[k, :, None], b[k, :, None])
        w = step
        nominal[:, k] += P[:, k]
    return w


def linear_deviation(
    chain: Chain,
    P: NDArray,
    tool: NDArray,
    references: dict[str, NDArray],
    delta: dict[str, NDArray],
    eps: dict[str, NDArray],
    squareness: dict[str, NDArray],
) -> NDArray:
    """First-order (eqs. 28–30): Σ δ_K + ε_K × L_K + k·(S_K × e_K)."""
    out = np.zeros(P.shape)
    for axis in chain.order:
        i = AXES.index(axis)
        out += delta[axis] + cross(eps[axis], abbe_offset(chain, axis, P, tool, references[axis]))
        out += P[:, i : i + 1] * np.cross(squareness[axis], UNIT[i])
    return out
