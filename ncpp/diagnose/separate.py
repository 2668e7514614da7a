"""Which further measurement would tell apart effects the data cannot.

Two candidate effects are indistinguishable when, after the set-up offsets are
removed, the readings they add to the files are (nearly) proportional.  A test
separates them when, with its readings added, they no longer are.  The tests
tried are the given ball-bar tests varied one thing at a time: the direction
not run, another radius, another feed, another plane through the same centre,
and another height (the centre moved along the plane's normal axis); each is
simulated from the model with the file's own set-up and judged by the same
correlation the diagnosis calls ambiguous.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ncpp.diagnose.candidates import Candidate
from ncpp.diagnose.observations import Observation, observe
from ncpp.instruments.files import Measurement
from ncpp.machine.model import Machine

NORMAL_AXIS = {"XY": 2, "YZ": 0, "ZX": 1}
HEIGHT_SHIFT_MM = 100.0  # how far "another height" moves the centre along the normal axis


@dataclass(frozen=True)
class Proposal:
    """A test that is not in the data: what it varies, in words, and its simulated file."""

    label: str
    measurement: Measurement


def correlation(a: NDArray, b: NDArray) -> float:
    """Largest canonical correlation of the column spaces of `a` and `b` (1: indistinguishable)."""
    qa, qb = (np.linalg.svd(m, full_matrices=False)[0][:, : np.linalg.matrix_rank(m)] for m in (a, b))
    if qa.shape[1] == 0 or qb.shape[1] == 0:
        return 0.0
    return float(np.linalg.svd(qa.T @ qb, compute_uv=False).max())


def seen(candidate: Candidate, observations: Sequence[Observation], weights: Sequence[float]) -> NDArray:
    """The readings `candidate`'s basis adds to each file, the set-up offsets removed, each file weighted."""
    parts = []
    for o, w in zip(observations, weights, strict=True):
        columns = np.column_stack([o.contribution(e) for e in candidate.basis])
        fitted = o.nuisance @ np.linalg.lstsq(o.nuisance, columns, rcond=None)[0]
        parts.append((columns - fitted) * w)
    return np.vstack(parts)


def proposals(model: Machine, observations: Sequence[Observation]) -> Iterator[Proposal]:
    """The given ball-bar tests varied one thing at a time (duplicates left out)."""
    from ncpp.instruments.forward import predict_ballbar

    done: set[tuple] = set()
    for o in observations:
        m = o.measurement
        if m.instrument != "ballbar" or m.radius_mm is None:
            continue
        plane, radius, feed = m.plane, float(m.radius_mm), o.feed
        centre = m.center_mm if m.center_mm is not None else np.zeros(3)
        directions = tuple(dict.fromkeys(str(d) for d in o.label))
        where = f"ball bar {plane} R{radius:g} F{feed:g}"
        for label, setup in _variants(model, plane, radius, feed, centre, directions, where):
            centre_key = tuple(np.round(setup["center_mm"], 3))
            key = (setup["plane"], setup["radius_mm"], setup["feed_mm_min"], centre_key, setup["directions"])
            if key in done:
                continue
            done.add(key)
            try:
                test = predict_ballbar(model, step_deg=2.0, offset_mm=m.offset_mm, **setup)
            except ValueError:  # (outside what the forward model can run)
                continue
            yield Proposal(label, test)


def _variants(
    model: Machine,
    plane: str,
    radius: float,
    feed: float,
    centre: NDArray,
    directions: tuple[str, ...],
    where: str,
) -> Iterator[tuple[str, dict]]:
    base = {
        "plane": plane,
        "radius_mm": radius,
        "feed_mm_min": feed,
        "center_mm": centre,
        "directions": directions,
    }
    missing = tuple(d for d in ("CCW", "CW") if d not in directions)
    if missing:
        yield (
            f"the {where} run in the other direction ({', '.join(missing)}) too",
            {**base, "directions": ("CCW", "CW")},
        )
    yield f"the {where} at another radius (R{radius / 2:g})", {**base, "radius_mm": radius / 2}
    yield f"the {where} at another feed (F{2 * feed:g})", {**base, "feed_mm_min": 2 * feed}
    for other in ("XY", "YZ", "ZX"):
        if other != plane:
            yield (
                f"a ball bar in another plane ({other} R{radius:g} about the same centre)",
                {**base, "plane": other},
            )
    n = NORMAL_AXIS[plane]
    axis = "XYZ"[n]
    lo, hi = model.limits.get(axis, (-np.inf, np.inf))
    for shift in (HEIGHT_SHIFT_MM, -HEIGHT_SHIFT_MM):
        moved = np.array(centre, dtype=float)
        moved[n] += shift
        if lo <= moved[n] <= hi:
            yield f"the {where} at another height ({axis}{moved[n]:g})", {**base, "center_mm": moved}
            break


def separating(
    model: Machine,
    first: Candidate,
    second: Candidate,
    observations: Sequence[Observation],
    weights: Sequence[float],
    ambiguity: float,
) -> list[str]:
    """The proposed tests that, added to the data, tell `first` and `second` apart (their
    correlation falls to `ambiguity` or below)."""
    a, b = seen(first, observations, weights), seen(second, observations, weights)
    scale = float(np.mean(weights)) if len(weights) else 1.0
    out = []
    for p in proposals(model, observations):
        extra = [observe(model, p.measurement, p.label)]
        more_a, more_b = seen(first, extra, [scale]), seen(second, extra, [scale])
        if correlation(np.vstack([a, more_a]), np.vstack([b, more_b])) <= ambiguity:
            out.append(p.label)
    return out
