"""Forward selection of the missing effects (the diagnosis workflow).

1. Simulate every file from the model (`predict_like`) and take the residual
   r = measured − simulated.
2. Set-up nuisances (ball-bar centre and length offset, laser zero per run,
   alignment of straightness readings) are fitted with every model and never
   reported.  Each file is weighted by 1/σ² with σ its noise estimated from
   the current residual (repeat runs or second differences: the
   high-frequency part, which a smooth model misfit barely moves).
3. Every candidate of the effect table is tried on top of what is already
   chosen: the gain ΔRSS of adding its columns (weighted).  It is significant
   when ΔRSS / s² exceeds the χ²(p) quantile at α / (number of candidates
   tried) (Bonferroni), with s² = max(1, RSS_after/dof): against the noise
   level when the rest is noise, an F-test when a misfit remains.
4. The most significant candidate is added, all chosen ones are refitted
   jointly, and the loop repeats until nothing significant is left.
5. Two candidates whose columns (after removing nuisances and the chosen
   effects) have a canonical correlation above `ambiguity` cannot be told
   apart by the data.  The step then keeps the one listed first in the effect
   table as the representative (a prior for the simpler, more common effect,
   not the noise, decides), so that the model still reproduces the data, and
   its evidence says "ambiguous" and names the others: a test that separates
   them (the other direction, a second feed, another plane or height) should decide.
6. After each step the updated model is re-simulated through the forward
   models and the gap (nuisances removed) is recorded.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray
from scipy.special import chdtri  # χ² upper quantile; scipy.stats costs seconds to import

from ncpp.diagnose.candidates import Candidate, candidates, cyclic_variant
from ncpp.diagnose.observations import Observation, noise_level, observe, predicted
from ncpp.diagnose.separate import separating
from ncpp.instruments.files import Measurement
from ncpp.machine.components import AXES
from ncpp.machine.effects import Cyclic, Effect
from ncpp.machine.model import Machine


@dataclass(frozen=True)
class Gap:
    rms_um: float
    max_um: float
    residuals: tuple[NDArray, ...] = field(repr=False, default=())  # per file, nuisances removed

    def to_dict(self) -> dict[str, float]:
        return {"rms_um": round(self.rms_um, 4), "max_um": round(self.max_um, 4)}


@dataclass
class Alternative:
    """An effect the data cannot tell apart from a step's, fitted in its place, and the
    tests (in words) that would tell them apart (`separate.py`)."""

    candidate: Candidate
    parameters: dict[str, float]
    uncertainty: dict[str, float]
    separated_by: list[str]

    def to_dict(self) -> dict:
        return {"effect": self.candidate.kind, **self.candidate.keys,
                "parameters": {k: _round(v) for k, v in self.parameters.items()},
                "uncertainty": {k: _round(v) for k, v in self.uncertainty.items()},
                "separated_by": list(self.separated_by)}  # fmt: skip


@dataclass
class Step:
    candidate: Candidate
    effect: Effect
    parameters: dict[str, float]
    uncertainty: dict[str, float]
    gap_after: Gap
    evidence: str
    statistic: float
    threshold: float
    ambiguous_with: tuple[str, ...] = ()
    alternatives: tuple[Alternative, ...] = ()  # the effects `ambiguous_with` names, fitted instead

    def to_dict(self) -> dict:
        out: dict = {"effect": self.candidate.kind, **self.candidate.keys}
        out["parameters"] = {k: _round(v) for k, v in self.parameters.items()}
        out["uncertainty"] = {k: _round(v) for k, v in self.uncertainty.items()}
        out["gap_after"] = self.gap_after.to_dict()
        out["evidence"] = self.evidence
        out["alternatives"] = [a.to_dict() for a in self.alternatives]
        return out


def _round(v: float) -> float:
    return float(f"{v:.4g}")


@dataclass
class Diagnosis:
    base: Machine
    updated: Machine
    observations: list[Observation]
    noise: list[float]  # per file, final estimate
    gap_before: Gap
    steps: list[Step]
    gap_after: Gap
    where: list[str]  # where the initial gap sits, one line per file
    not_observable: list[str]

    def report(self, model: str) -> dict:
        """The contract's JSON report."""
        return {
            "gap_before": self.gap_before.to_dict(),
            "steps": [s.to_dict() for s in self.steps],
            "gap_after": self.gap_after.to_dict(),
            "model": model,
        }


# ------------------------------------------------------------------ algebra
def _orth(A: NDArray, rtol: float = 1e-9) -> NDArray:
    """Orthonormal basis of the column space of A (rank-revealing SVD)."""
    if A.shape[1] == 0:
        return np.zeros((A.shape[0], 0))
    u, s, _ = np.linalg.svd(A, full_matrices=False)
    return u[:, s > rtol * max(s[0], 1e-300)]


def _block_diag(blocks: Sequence[NDArray]) -> NDArray:
    out = np.zeros((sum(b.shape[0] for b in blocks), sum(b.shape[1] for b in blocks)))
    r = c = 0
    for b in blocks:
        out[r : r + b.shape[0], c : c + b.shape[1]] = b
        r, c = r + b.shape[0], c + b.shape[1]
    return out


@dataclass
class _Problem:
    """The stacked least-squares problem over all files."""

    obs: list[Observation]
    r: NDArray  # measured − base model, all files
    nuisance: NDArray
    slices: list[slice]

    def columns(self, cand: Candidate) -> NDArray:
        return np.column_stack([np.concatenate([o.contribution(e) for o in self.obs]) for e in cand.basis])

    def weights(self, residual: NDArray) -> tuple[NDArray, list[float]]:
        sig = [max(noise_level(o, residual[s]), 1e-3) for o, s in zip(self.obs, self.slices)]
        w = np.concatenate([np.full(s.stop - s.start, 1.0 / v) for v, s in zip(sig, self.slices)])
        return w, sig

    def fit(self, X: NDArray, sw: NDArray) -> tuple[NDArray, NDArray, NDArray]:
        """Weighted LS of r on [nuisance, X]: (coef of X, their covariance in
        whitened units ×1, unweighted residual)."""
        A = np.column_stack([self.nuisance, X]) * sw[:, None]
        coef, *_ = np.linalg.lstsq(A, self.r * sw, rcond=None)
        residual = self.r - np.column_stack([self.nuisance, X]) @ coef
        cov = np.linalg.pinv(A.T @ A)
        k = self.nuisance.shape[1]
        return coef[k:], cov[k:, k:], residual


def _gap(machine: Machine, obs: list[Observation]) -> Gap:
    """Re-simulate every file with `machine` and remove the set-up nuisances."""
    residuals = []
    for o in obs:
        res = o.y - predicted(o.machine.replace(effects=machine.effects), o.measurement)
        coef, *_ = np.linalg.lstsq(o.nuisance, res, rcond=None)
        residuals.append(res - o.nuisance @ coef)
    allr = np.concatenate(residuals)
    return Gap(float(np.sqrt(np.mean(allr**2))), float(np.max(np.abs(allr))), tuple(residuals))


def _extent(obs: list[Observation]) -> dict[str, tuple[float, float]]:
    out: dict[str, tuple[float, float]] = {}
    for i, a in enumerate(AXES):
        vals = [
            p.trajectory.positions[:, i]
            for o in obs
            for p in o.parts
            if np.ptp(p.trajectory.positions[:, i]) > 0
        ]
        if vals:
            v = np.concatenate(vals)
            lo, hi = round(float(v.min()), 3), round(float(v.max()), 3)
            if lo < hi:  # (a test moving the axis less than 1 µm has no extent to bow over)
                out[a] = (lo, hi)
    return out


# ----------------------------------------------------------------- workflow
def diagnose(
    machine: Machine,
    measurements: Sequence[Measurement],
    *,
    alpha: float = 1e-3,
    ambiguity: float = 0.98,
    max_steps: int = 8,
) -> Diagnosis:
    """Find, fit and add the effects `machine` lacks to explain `measurements`."""
    obs = [observe(machine, m) for m in measurements]
    base = np.concatenate([predicted(o.machine, o.measurement) for o in obs])
    sizes = np.cumsum([0] + [len(o) for o in obs])
    slices = [slice(a, b) for a, b in zip(sizes[:-1], sizes[1:])]
    prob = _Problem(
        obs, np.concatenate([o.y for o in obs]) - base, _block_diag([o.nuisance for o in obs]), slices
    )
    groups = candidates(_extent(obs))
    cols = {id(c): prob.columns(c) for g in groups for c in g}
    n_tests = sum(len(g) for g in groups)
    gap_before = _gap(machine, obs)
    chosen: list[Candidate] = []
    coef = np.zeros(0)
    steps: list[Step] = []
    not_observable: set[str] = set()
    _, _, residual = prob.fit(np.zeros((len(prob.r), 0)), np.ones(len(prob.r)))
    where = [describe_residual(o, residual[s]) for o, s in zip(obs, slices)]
    for _ in range(max_steps):
        X = _design(chosen, cols, len(prob.r))
        w, _ = prob.weights(prob.fit(X, np.ones(len(prob.r)))[2])
        sw = np.sqrt(w)
        _, _, residual = prob.fit(X, sw)
        e_w = residual * sw
        rss0 = float(e_w @ e_w)
        Q = _orth(np.column_stack([prob.nuisance, X]) * sw[:, None])
        dof0 = len(prob.r) - Q.shape[1]
        scored = []
        for order, g in enumerate(groups):
            if any(c.kind == g[0].kind and c.keys == g[0].keys for c in chosen):
                continue
            best = None
            for cand in g:
                B = cols[id(cand)] * sw[:, None]
                Bp = B - Q @ (Q.T @ B)
                if np.linalg.norm(Bp) <= 1e-6 * max(float(np.linalg.norm(B)), 1e-300):
                    if np.linalg.norm(B) > 0 and not chosen:  # hidden by the set-up offsets alone
                        not_observable.add(g[0].name)
                    continue
                Qb = _orth(Bp, 1e-6)
                gain = float(np.sum((Qb.T @ e_w) ** 2))
                if best is None or gain > best[1]:
                    best = (cand, gain, Qb)
            if best is None:
                continue
            cand, gain, Qb = best
            p = Qb.shape[1]
            s2 = max(1.0, (rss0 - gain) / max(dof0 - p, 1))
            stat = gain / s2
            thr = float(chdtri(p, alpha / n_tests))
            scored.append((stat / thr, cand, gain, Qb, stat, thr, order))
        significant = [s for s in scored if s[0] > 1.0]
        if not significant:
            break
        significant.sort(key=lambda s: -s[2])
        twins = [
            s
            for s in significant[1:]
            if np.linalg.svd(significant[0][3].T @ s[3], compute_uv=False).max() > ambiguity
        ]
        # The data cannot choose among twins: the effect table's order (simpler,
        # more common effects first) picks the representative, not the noise.
        group = [significant[0], *twins]
        _, cand, gain, Qb, stat, thr, _ = min(group, key=lambda s: s[6])
        ambiguous = tuple(s[1].name for s in group if s[1] is not cand)
        if cand.kind == "cyclic":
            cand = _refine_period(cand, prob, cols, Q, e_w, sw)
        chosen.append(cand)
        coef, cov, residual, chosen = _refit(prob, chosen, cols, sw)
        effects = tuple(c.build(coef[k]) for c, k in zip(chosen, _index(chosen)))
        updated = machine.replace(effects=machine.effects + effects)
        gap = _gap(updated, obs)
        params, unc = cand.parameters(
            coef[_index(chosen)[-1]], cov[np.ix_(_index(chosen)[-1], _index(chosen)[-1])]
        )
        contribution = cols[id(chosen[-1])] @ coef[_index(chosen)[-1]]
        for o, s in zip(obs, slices):  # what the set-up offsets absorb is not evidence
            contribution[s] -= o.nuisance @ np.linalg.lstsq(o.nuisance, contribution[s], rcond=None)[0]
        weights = [float(sw[s.start]) for s in slices]
        alternatives = tuple(_alternative(machine, prob, chosen, s[1], cols, sw, obs, weights, ambiguity)
                             for s in group if s[1] is not cand)  # fmt: skip
        share = gain / max(rss0, 1e-300)
        evidence = explain(obs, slices, contribution, stat, thr, share, alternatives, ambiguity)
        step = Step(chosen[-1], effects[-1], params, unc, gap, evidence, stat, thr, ambiguous, alternatives)
        steps.append(step)
    # Final joint values for every step (later steps refine earlier estimates).
    if chosen:
        X = _design(chosen, cols, len(prob.r))
        w, _ = prob.weights(residual)
        coef, cov, residual, chosen = _refit(prob, chosen, cols, np.sqrt(w))
        for step, c, k in zip(steps, chosen, _index(chosen)):
            step.candidate = c
            step.effect = c.build(coef[k])
            step.parameters, step.uncertainty = c.parameters(coef[k], cov[np.ix_(k, k)])
    updated = machine.replace(effects=machine.effects + tuple(s.effect for s in steps))
    gap_after = _gap(updated, obs) if steps else gap_before
    _, sig = prob.weights(residual)
    for c in chosen:
        not_observable.discard(c.name)
    return Diagnosis(machine, updated, obs, sig, gap_before, steps, gap_after, where, sorted(not_observable))


def _alternative(
    machine: Machine,
    prob: _Problem,
    chosen: list[Candidate],
    twin: Candidate,
    cols: dict[int, NDArray],
    sw: NDArray,
    obs: list[Observation],
    weights: list[float],
    ambiguity: float,
) -> Alternative:
    """`twin` fitted in place of the last chosen effect, and the tests that would tell them apart."""
    coef, cov, _, fitted = _refit(prob, [*chosen[:-1], twin], cols, sw)
    k = _index(fitted)[-1]
    params, unc = fitted[-1].parameters(coef[k], cov[np.ix_(k, k)])
    tests = separating(machine, chosen[-1], twin, obs, weights, ambiguity)
    return Alternative(fitted[-1], params, unc, tests)


def _index(chosen: list[Candidate]) -> list[list[int]]:
    out, k = [], 0
    for c in chosen:
        out.append(list(range(k, k + len(c.basis))))
        k += len(c.basis)
    return out


def _design(chosen: list[Candidate], cols: dict[int, NDArray], n: int) -> NDArray:
    return np.column_stack([cols[id(c)] for c in chosen]) if chosen else np.zeros((n, 0))


def _refit(prob: _Problem, chosen: list[Candidate], cols: dict[int, NDArray], sw: NDArray):
    """Joint weighted fit of the chosen effects; nonlinear ones re-linearised at
    their estimate (a few Gauss–Newton-like secant steps).  The covariance is
    scaled by s² = max(1, RSS/dof) in whitened units."""
    for _ in range(4):
        X = _design(chosen, cols, len(prob.r))
        coef, cov, residual = prob.fit(X, sw)
        if not any(c.nonlinear for c in chosen):
            break
        again = []
        for c, k in zip(chosen, _index(chosen)):
            new = c.relinearise(coef[k])
            if new is not c:
                cols[id(new)] = prob.columns(new)
            again.append(new)
        chosen = again
    X = _design(chosen, cols, len(prob.r))
    coef, cov, residual = prob.fit(X, sw)
    e_w = residual * sw
    dof = max(len(prob.r) - prob.nuisance.shape[1] - X.shape[1], 1)
    return coef, cov * max(1.0, float(e_w @ e_w) / dof), residual, chosen


def _refine_period(cand: Candidate, prob: _Problem, cols, Q: NDArray, e_w: NDArray, sw: NDArray) -> Candidate:
    """Scan the screw lead around the best standard one (±8 %)."""
    basis = cand.basis[0]
    assert isinstance(basis, Cyclic)  # called for the cyclic candidates
    period = basis.period_mm
    axis = cand.keys["axis"]
    best, best_gain = cand, -1.0
    for p in period * np.linspace(0.92, 1.08, 33):
        c = cyclic_variant(axis, float(p))
        X = prob.columns(c)
        B = X * sw[:, None]
        Bp = B - Q @ (Q.T @ B)
        gain = float(np.sum((_orth(Bp, 1e-6).T @ e_w) ** 2))
        if gain > best_gain:
            best, best_gain = c, gain
            cols[id(c)] = X
    return best


# ------------------------------------------------------------- the account
def _ballbar_split(o: Observation, r: NDArray) -> tuple[float, float] | None:
    """rms of the part common to CW and CCW and of the part that flips with
    direction (half sum / half difference at common angles)."""
    d = o.label
    if not (np.any(d == "CW") and np.any(d == "CCW")):
        return None
    grid = np.arange(0.0, 360.0, 1.0)
    a = np.interp(grid, o.position[d == "CCW"], r[d == "CCW"], period=360.0)
    b = np.interp(grid, o.position[d == "CW"], r[d == "CW"], period=360.0)
    return float(np.sqrt(np.mean(((a + b) / 2) ** 2))), float(np.sqrt(np.mean(((a - b) / 2) ** 2)))


def _setup(o: Observation) -> str:
    m = o.measurement
    if m.instrument == "ballbar":
        return f"ball bar {m.plane} R{m.radius_mm:g} F{o.feed:g}"
    if m.instrument == "laser":
        return f"laser {m.axis} {m.quantity}"
    return f"comparator {m.axis}"


def describe_residual(o: Observation, r: NDArray) -> str:
    """One line: where the residual of this file sits."""
    i = int(np.argmax(np.abs(r)))
    unit = "deg" if o.measurement.instrument == "ballbar" else "mm"
    text = (f"{o.name}: {_setup(o)}: rms {np.sqrt(np.mean(r**2)):.2f}, max {r[i]:+.2f} "
            f"at {o.position[i]:g} {unit} ({o.label[i]})")  # fmt: skip
    split = _ballbar_split(o, r) if o.measurement.instrument == "ballbar" else None
    if split:
        text += f"; same in CW and CCW {split[0]:.2f}, flips with direction {split[1]:.2f}"
    return text


def explain(obs, slices, contribution: NDArray, stat: float, thr: float, share: float,
            alternatives: Sequence[Alternative] = (), ambiguity: float = 0.98) -> str:  # fmt: skip
    """The step's evidence: where its contribution shows and how sure it is."""
    parts = []
    rms = [float(np.sqrt(np.mean(contribution[s] ** 2))) for s in slices]
    top = int(np.argmax(rms))
    o, c = obs[top], contribution[slices[top]]
    i = int(np.argmax(np.abs(c)))
    unit = "deg" if o.measurement.instrument == "ballbar" else "mm"
    parts.append(f"largest in {_setup(o)} ({c[i]:+.2f} um at {o.position[i]:g} {unit} {o.label[i]})")
    seen = [_setup(o) for o, v in zip(obs, rms) if v > 0.2 * rms[top]]
    if len(seen) > 1:
        parts.append("also in " + ", ".join(s for s in seen if s != _setup(o)))
    split = _ballbar_split(o, c) if o.measurement.instrument == "ballbar" else None
    if split:
        common, flip = split
        parts.append("same sign in CW and CCW" if common > 3 * flip else
                     "flips sign with direction (CW vs CCW)" if flip > 3 * common else "differs between CW and CCW")  # fmt: skip
    feeds = sorted({o.feed for o, v in zip(obs, rms) if v > 0 and o.measurement.instrument == "ballbar"})
    if len(feeds) > 1:
        by_feed = {f: float(np.mean([v for o, v in zip(obs, rms) if o.feed == f and v > 0])) for f in feeds}
        ratio = by_feed[feeds[-1]] / max(by_feed[feeds[0]], 1e-12)
        if ratio > 1.3:
            parts.append(f"grows with feed (x{ratio:.1f} from F{feeds[0]:g} to F{feeds[-1]:g})")
        elif ratio > 0.77:
            parts.append("independent of feed")
    parts.append(
        f"explains {100 * share:.0f} % of the remaining gap; test statistic {stat:.0f} vs threshold {thr:.1f}"
    )
    text = "; ".join(parts)
    if alternatives:
        names = ", ".join(a.candidate.name for a in alternatives)
        text = (f"ambiguous: cannot be told apart from {names} on this data (columns correlated > "
                f"{ambiguity:g}; kept the first in the effect table as representative; "
                f"{separation_text(alternatives)}); " + text)  # fmt: skip
    return text


def separation_text(alternatives: Sequence[Alternative]) -> str:
    """The further tests that tell every alternative apart (each, alone), in words."""
    tests = [set(a.separated_by) for a in alternatives]
    common = [t for t in alternatives[0].separated_by if all(t in s for s in tests)] if alternatives else []
    if common:
        return "any one of these tells the representative apart from them all: " + "; ".join(common)
    if any(tests):
        return "no single further test tells them all apart: see the alternatives' separated_by"
    return "no variation of the given ball-bar tests (direction, radius, feed, plane, height) separates them"
