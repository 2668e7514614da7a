"""ISO 230-2:2014 evaluation of positioning accuracy and repeatability.

For target i and run j of one approach direction (↑ = `+`, ↓ = `-`) the
positional deviation is x_ij = actual − target (the file's deviation column).
Per target (clause 3.3):

* x̄_i↑ = mean_j x_ij↑, x̄_i↓ likewise           mean unidirectional positional deviation
* x̄_i  = (x̄_i↑ + x̄_i↓) / 2                      mean bidirectional positional deviation
* B_i  = x̄_i↑ − x̄_i↓                            reversal value
* s_i↑ = sqrt(Σ_j (x_ij↑ − x̄_i↑)² / (n − 1))     estimator of unidirectional standard uncertainty
* R_i↑ = 4 s_i↑                                  unidirectional repeatability
* R_i  = max(2 s_i↑ + 2 s_i↓ + |B_i|, R_i↑, R_i↓) bidirectional repeatability

and for the axis:

* B = max_i |B_i|,  B̄ = mean_i B_i
* R↑ = max_i R_i↑,  R↓,  R = max_i R_i
* E↑ = max x̄_i↑ − min x̄_i↑,  E↓;  E = max(x̄↑, x̄↓) − min(x̄↑, x̄↓)
* M  = max x̄_i − min x̄_i
* A↑ = max(x̄_i↑ + 2 s_i↑) − min(x̄_i↑ − 2 s_i↑),  A↓;
  A  = max(x̄↑ + 2s↑, x̄↓ + 2s↓) − min(x̄↑ − 2s↑, x̄↓ − 2s↓)

A unidirectional test (one approach direction only) has no reversal: B and
B̄ are undefined (None), and the bidirectional figures reduce to those of the
one direction (A = A↑, E = E↑, R = R↑, M = E↑), which is what the
definitions above give when the other direction's set is empty.  With a
single run per direction s is undefined (NaN), and so are A and R.
Targets are matched by value (to 1 µm); a target measured in only one
direction of a bidirectional test is used only for the unidirectional figures.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ncpp.errors import NcppError
from ncpp.instruments.files import MAX_LENGTH_UM, Measurement

SYMBOLS = ("A", "A_up", "A_down", "E", "E_up", "E_down", "M", "B", "B_mean", "R", "R_up", "R_down")


@dataclass(frozen=True, eq=False)
class Direction:
    """Per-target statistics of one approach direction (arrays over `targets`; NaN where unmeasured)."""

    mean: np.ndarray  # x̄_i
    s: np.ndarray  # s_i (NaN with fewer than two runs)
    runs: np.ndarray  # n_i, number of readings

    @property
    def measured(self) -> np.ndarray:
        return self.runs > 0

    @property
    def repeatability(self) -> np.ndarray:  # R_i = 4 s_i
        return 4.0 * self.s

    @property
    def E(self) -> float | None:
        x = self.mean[self.measured]
        return float(x.max() - x.min()) if x.size else None

    @property
    def A(self) -> float | None:
        ok = self.measured
        if not ok.any():
            return None
        return float(np.max(self.mean[ok] + 2 * self.s[ok]) - np.min(self.mean[ok] - 2 * self.s[ok]))

    @property
    def R(self) -> float | None:
        ok = self.measured
        return float(np.max(self.repeatability[ok])) if ok.any() else None


@dataclass(frozen=True, eq=False)
class Iso230_2:
    """ISO 230-2 evaluation of one axis; figures in the unit of the data (µm)."""

    targets: np.ndarray
    up: Direction
    down: Direction

    @property
    def bidirectional(self) -> bool:
        return bool(self.up.measured.any() and self.down.measured.any())

    @property
    def both(self) -> np.ndarray:
        """Targets approached from both directions."""
        return self.up.measured & self.down.measured

    @property
    def mean(self) -> np.ndarray:
        """x̄_i = (x̄_i↑ + x̄_i↓)/2; in a unidirectional test, that direction's mean."""
        if not self.bidirectional:
            return self._only.mean
        return np.where(self.both, (self.up.mean + self.down.mean) / 2, np.nan)

    @property
    def reversal(self) -> np.ndarray:
        """B_i = x̄_i↑ − x̄_i↓ (NaN where not approached both ways)."""
        return np.where(self.both, self.up.mean - self.down.mean, np.nan)

    @property
    def repeatability(self) -> np.ndarray:
        """R_i = max(2s↑ + 2s↓ + |B_i|, R_i↑, R_i↓)."""
        if not self.bidirectional:
            return self._only.repeatability
        both = 2 * self.up.s + 2 * self.down.s + np.abs(self.reversal)
        return np.where(
            self.both, np.maximum(both, np.maximum(self.up.repeatability, self.down.repeatability)), np.nan
        )

    @property
    def _only(self) -> Direction:
        return self.up if self.up.measured.any() else self.down

    def _directions(self) -> list[Direction]:
        return [d for d in (self.up, self.down) if d.measured.any()]

    @property
    def B(self) -> float | None:
        return float(np.nanmax(np.abs(self.reversal))) if self.bidirectional and self.both.any() else None

    @property
    def B_mean(self) -> float | None:
        return float(np.nanmean(self.reversal)) if self.bidirectional and self.both.any() else None

    @property
    def E(self) -> float:
        x = np.concatenate([d.mean[d.measured] for d in self._directions()])
        return float(x.max() - x.min())

    @property
    def A(self) -> float:
        hi = np.concatenate([(d.mean + 2 * d.s)[d.measured] for d in self._directions()])
        lo = np.concatenate([(d.mean - 2 * d.s)[d.measured] for d in self._directions()])
        return float(hi.max() - lo.min())

    @property
    def M(self) -> float:
        x = self.mean[~np.isnan(self.mean)]
        return float(x.max() - x.min()) if x.size else math.nan

    @property
    def R(self) -> float:
        r = self.repeatability
        if self.bidirectional:
            r = r[self.both]
            # Targets approached one way only still bound R through their R_i↑/R_i↓.
            singles = [d.repeatability[d.measured & ~self.both] for d in self._directions()]
            r = np.concatenate([r, *singles])
        else:
            r = r[self._only.measured]
        return float(np.max(r))

    def figures(self) -> dict[str, float | None]:
        """The axis figures under their standard symbols (NaN/undefined -> None)."""
        values = {
            "A": self.A, "A_up": self.up.A, "A_down": self.down.A,
            "E": self.E, "E_up": self.up.E, "E_down": self.down.E,
            "M": self.M, "B": self.B, "B_mean": self.B_mean,
            "R": self.R, "R_up": self.up.R, "R_down": self.down.R,
        }  # fmt: skip
        return {k: (None if v is None or math.isnan(v) else v) for k, v in values.items()}


def evaluate_positioning(target_mm: np.ndarray, direction: np.ndarray, deviation: np.ndarray) -> Iso230_2:
    """Evaluate readings x_ij (deviation, any unit) at targets, approached `+`/`-`."""
    target_mm = np.asarray(target_mm, dtype=float)
    direction = np.asarray(direction)
    deviation = np.asarray(deviation, dtype=float)
    if target_mm.size == 0:
        raise ValueError("no readings")
    if not np.all(np.abs(target_mm) <= MAX_LENGTH_UM / 1e3):  # (read files are checked so: files.py)
        raise ValueError(
            f"targets must be finite and within ±{MAX_LENGTH_UM / 1e3:.4g} mm, where 1 µm is resolved"
        )
    keys = np.round(target_mm * 1e3).astype(np.int64)  # match targets to 1 µm (fits: |keys| <= 2**53)
    unique, index = np.unique(keys, return_inverse=True)
    targets = np.bincount(index, weights=target_mm) / np.bincount(index)
    return Iso230_2(
        targets,
        _direction_stats(index, deviation, direction == "+", len(unique)),
        _direction_stats(index, deviation, direction == "-", len(unique)),
    )


def _direction_stats(index: np.ndarray, x: np.ndarray, chosen: np.ndarray, size: int) -> Direction:
    n = np.bincount(index[chosen], minlength=size).astype(float)
    total = np.bincount(index[chosen], weights=x[chosen], minlength=size)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = total / n
        squares = np.bincount(index[chosen], weights=(x[chosen] - mean[index[chosen]]) ** 2, minlength=size)
        s = np.sqrt(squares / (n - 1))
    s[n < 2] = np.nan
    mean[n == 0] = np.nan
    return Direction(mean, s, n.astype(int))


def evaluate_measurement(m: Measurement, column: str | None = None) -> Iso230_2:
    """ISO 230-2 of a laser position file or the linear part of a comparator file."""
    if column is None:
        if m.instrument == "comparator":
            column = "linear_um"
        elif m.instrument == "laser":
            column = m.deviation_column
        else:
            raise NcppError(f"ISO 230-2 applies to laser and comparator files, not {m.instrument}", m.at())
    if len(m) == 0:
        raise NcppError("the file holds no readings", m.at())
    return evaluate_positioning(m["target_mm"], m["direction"], m[column])
