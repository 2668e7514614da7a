"""Figures a metrologist expects, one panel per analysed file.

* Circular tests (ball bar, cutting, circular grid): a polar plot of the
  LSC-centred radial deviation, magnified about the nominal circle (dashed),
  CCW and CW in two colours, with the scale (µm per division) and G, H in the
  title, like a Renishaw ballbar plot.
* Positioning (laser, comparator): mean deviation per direction along the
  axis with ±2s bands, the single runs as dots, the bidirectional mean.
* Straightness, angles and level: the mean profile and its least-squares line.

matplotlib is imported inside `plot_analyses` (Agg backend) so that importing
this module stays cheap.
"""

from __future__ import annotations

import io
import math
import os
from collections.abc import Sequence

import numpy as np

from ncpp.fileio import write_bytes_atomic
from ncpp.instruments import iso230_4
from ncpp.instruments.analysis import LABELS, Analysis, describe

COLOURS = {"CCW": "tab:red", "CW": "tab:blue", "+": "tab:red", "-": "tab:blue"}


def plot_analyses(analyses: Sequence[Analysis], path: str | os.PathLike[str], dpi: int = 110) -> None:
    """Draw one panel per kind of file into a PNG at `path` (written atomically)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = analyses_figure(analyses, plt)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=dpi)
    plt.close(fig)
    write_bytes_atomic(path, buffer.getvalue())


def analyses_figure(analyses: Sequence[Analysis], plt):
    """The figure `plot_analyses` draws: a file alone in its kind gets its own panel; several
    files of one kind (circular tests, one positioning quantity, one profile) share one panel,
    on one scale, so that they compare at a glance (pyplot passed in, its backend chosen)."""
    groups = list(kinds(analyses).values())
    n = len(groups)
    cols = 1 if n == 1 else 2
    rows = math.ceil(n / cols)
    fig = plt.figure(figsize=(7.5 * cols, 6.5 * rows))
    for k, group in enumerate(groups, 1):
        polar = group[0].test is not None
        ax = fig.add_subplot(rows, cols, k, projection="polar" if polar else None)
        _draw(ax, group)
    fig.tight_layout()
    return fig


def _draw(ax, group: Sequence[Analysis]) -> None:
    """One panel: a file alone in its kind in detail, several of one kind overlaid."""
    first, alone = group[0], len(group) == 1
    if first.test is not None:
        _polar_panel(ax, first) if alone else _polar_overlay(ax, group)
    elif first.positioning is not None:
        _positioning_panel(ax, first) if alone else _positioning_overlay(ax, group)
    else:
        _profile_panel(ax, first) if alone else _profile_overlay(ax, group)


def kinds(analyses: Sequence[Analysis]) -> dict[tuple[str, ...], list[Analysis]]:
    """The analyses grouped by what they can share a scale with, in the order first given."""
    out: dict[tuple[str, ...], list[Analysis]] = {}
    for a in analyses:
        m = a.measurement
        if a.test is not None:
            key: tuple[str, ...] = ("circular",)
        elif m.instrument == "comparator" or (m.instrument == "laser" and m.quantity == "position"):
            key = ("positioning",)
        else:
            key = (m.instrument, str(m.quantity if m.instrument != "grid" else m.plane))
        out.setdefault(key, []).append(a)
    return out


# Units of the figures' keys, by suffix (longest first), and how they are written.
UNITS = (
    ("_um_per_m_per_m", "µm/m per m"),
    ("_urad_per_m", "µrad/m"),
    ("_um_per_m", "µm/m"),
    ("_urad", "µrad"),
    ("_um", "µm"),
    ("_ms", "ms"),
)


def figure_text(key: str, value: float) -> str:
    """A figure in words with its unit: `straightness_um` 3.2 -> "straightness 3.20 µm"; the
    standards' symbols (A, B, G, ... in µm) keep their letters."""
    for suffix, unit in UNITS:
        if key.endswith(suffix):
            return f"{key.removesuffix(suffix).replace('_', ' ')} {value:.2f} {unit}"
    return f"{LABELS.get(key, key)} {value:.2f} µm"


def _titles(a: Analysis) -> str:
    return ", ".join(figure_text(k, v) for k, v in a.figures.items() if v is not None)


def _polar_overlay(ax, group: Sequence[Analysis]) -> None:
    """Several circular tests on one deviation scale: a colour per file, CCW solid, CW dashed."""
    traces = []
    for a in group:
        test, circle = a.test, a.circle
        assert test is not None and circle is not None
        traces += [(a, t, iso230_4.centred(t, circle.common_centre_um, test.radius_mm)) for t in test.traces]
    extreme = max(float(np.max(np.abs(d))) for _, _, d in traces)
    step = _nice_step(2 * extreme)
    outer = step * math.ceil(extreme / step + 0.5)
    ax.set_rorigin(-3 * outer)
    ax.set_rlim(-outer, outer)
    full = np.linspace(0, 2 * np.pi, 361)
    ax.plot(full, np.zeros_like(full), "k--", lw=0.8, label="nominal circle")
    colours = {id(a): f"C{k}" for k, a in enumerate(group)}
    for a, t, dev in traces:
        th, r = _closed_or_open(t.angle_deg, dev)
        name = os.path.basename(a.measurement.source)
        ax.plot(th, r, color=colours[id(a)], lw=1.1, ls="-" if t.direction == "CCW" else "--",
                label=f"{name} {t.direction} (G {a.figures['G']:.2f} µm)")  # fmt: skip
    ax.set_rticks(np.arange(-outer, outer + step / 2, step))
    ax.set_yticklabels([f"{v:+g}" for v in np.arange(-outer, outer + step / 2, step)], fontsize=7)
    ax.set_rlabel_position(67.5)
    scale = f"radial deviation, {step:g} µm/div (LSC centred)"
    ax.set_title(f"{len(group)} circular tests on one scale: {scale}", fontsize=9)
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.06), fontsize=6, ncol=2)


def _positioning_overlay(ax, group: Sequence[Analysis]) -> None:
    """Several positioning files on one scale: each file's mean deviation per direction."""
    for k, a in enumerate(group):
        r, name = a.positioning, os.path.basename(a.measurement.source)
        assert r is not None
        for stats, arrow, style in ((r.up, "↑", "-o"), (r.down, "↓", "--s")):
            ok = stats.measured
            if ok.any():
                label = f"{name} x̄{arrow}"
                ax.plot(r.targets[ok], stats.mean[ok], style, color=f"C{k}", ms=3, lw=1, label=label)
    ax.axhline(0, color="grey", lw=0.6)
    ax.set_xlabel("target position (mm)")
    ax.set_ylabel("positioning deviation, actual − target (µm)")
    ax.set_title(f"{len(group)} positioning files on one scale: mean deviation per direction", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)


def _profile_overlay(ax, group: Sequence[Analysis]) -> None:
    """Several profiles of one quantity on one scale."""
    m = group[0].measurement
    unit = _profile_unit(m)
    for k, a in enumerate(group):
        name, profile = next(iter(a.profiles.items()))
        ax.plot(profile.position_mm, profile.value, "-o", ms=3, color=f"C{k}",
                label=f"{os.path.basename(a.measurement.source)} ({_titles(a)})")  # fmt: skip
    ax.set_xlabel("position (mm)")
    ax.set_ylabel(f"{m.quantity} ({unit})")
    ax.set_title(f"{len(group)} {m.instrument} {m.quantity} profiles on one scale", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)


def _profile_unit(m) -> str:
    if m.instrument == "level":
        return "µm/m"
    return "µrad" if m.instrument == "laser" and m.deviation_column.endswith("urad") else "µm"


def _nice_step(span: float) -> float:
    """A 1-2-5 step that divides `span` into about four divisions."""
    raw = max(span, 1e-3) / 4
    power = 10 ** math.floor(math.log10(raw))
    return next(m * power for m in (1, 2, 5, 10) if m * power >= raw)


def _polar_panel(ax, a: Analysis) -> None:
    test, circle = a.test, a.circle
    assert test is not None and circle is not None
    centred = {
        t.direction: (t, iso230_4.centred(t, circle.common_centre_um, test.radius_mm)) for t in test.traces
    }
    extreme = max(float(np.max(np.abs(d))) for _, d in centred.values())
    step = _nice_step(2 * extreme)
    outer = step * math.ceil(extreme / step + 0.5)
    # Magnify: the deviation band [-outer, outer] fills the outer half of the radius.
    ax.set_rorigin(-3 * outer)
    ax.set_rlim(-outer, outer)
    full = np.linspace(0, 2 * np.pi, 361)
    ax.plot(full, np.zeros_like(full), "k--", lw=0.8, label=f"nominal R{test.radius_mm:g} mm")
    for direction, (t, dev) in centred.items():
        th, r = _closed_or_open(t.angle_deg, dev)
        ax.plot(th, r, color=COLOURS[direction], lw=1.2, label=direction)
    ax.set_rticks(np.arange(-outer, outer + step / 2, step))
    ax.set_yticklabels([f"{v:+g}" for v in np.arange(-outer, outer + step / 2, step)], fontsize=7)
    ax.set_rlabel_position(67.5)
    p, q = test.axes
    ax.set_xticks(np.radians([0, 90, 180, 270]))
    ax.set_xticklabels([f"+{p}", f"+{q}", f"−{p}", f"−{q}"])
    f = a.figures
    parts = [f"G {f['G']:.2f} µm"]
    if f.get("H") is not None:
        parts.append(f"H {f['H']:.2f} µm")
    parts.append(f"F {f['F_min']:+.2f}/{f['F_max']:+.2f} µm")
    ax.set_title(
        f"{os.path.basename(a.measurement.source)}\n{describe(a.measurement)}\n" + ", ".join(parts),
        fontsize=9,
    )
    ax.text(
        0.0,
        -0.08,
        f"scale {step:g} µm/div (LSC centred)\n" + _diagnosis_text(a),
        transform=ax.transAxes,
        fontsize=7,
        va="top",
    )
    ax.legend(loc="upper right", bbox_to_anchor=(1.18, 1.08), fontsize=7)


def _closed_or_open(angle_deg: np.ndarray, value: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Points in angle order; a full circle is closed, a partial arc starts after its gap."""
    order = np.argsort(angle_deg, kind="stable")
    a, v = angle_deg[order], value[order]
    gaps = np.diff(np.append(a, a[0] + 360.0))
    widest = int(np.argmax(gaps))
    if gaps[widest] > 3 * np.median(gaps):
        start = (widest + 1) % len(a)
        return np.radians(np.roll(a, -start)), np.roll(v, -start)
    return np.radians(np.append(a, a[0])), np.append(v, v[0])


def _diagnosis_text(a: Analysis) -> str:
    f = a.figures
    pieces = []
    for key, label, unit in (
        ("squareness_um_per_m", "squareness", "µm/m"),
        ("scale_mismatch_um_per_m", "scale mismatch", "µm/m"),
        ("servo_mismatch_ms", "servo mismatch", "ms"),
    ):
        if f.get(key) is not None:
            pieces.append(f"{label} {f[key]:+.1f} {unit}")
    for key, value in f.items():
        if value is not None and (key.startswith("backlash_") or key.startswith("reversal_spike_")):
            pieces.append(f"{key.rsplit('_', 1)[0].replace('_', ' ')} {value:+.2f} µm")
    return "; ".join(pieces[:3]) + "\n" + "; ".join(pieces[3:])


def _positioning_panel(ax, a: Analysis) -> None:
    m, r = a.measurement, a.positioning
    assert r is not None
    column = "linear_um" if m.instrument == "comparator" else m.deviation_column
    for sign, stats, name in (("+", r.up, "↑"), ("-", r.down, "↓")):
        ok = stats.measured
        if not ok.any():
            continue
        colour = COLOURS[sign]
        rows = m["direction"] == sign
        ax.plot(m["target_mm"][rows], m[column][rows], ".", color=colour, alpha=0.35, ms=4)
        ax.plot(r.targets[ok], stats.mean[ok], "-o", color=colour, ms=3, label=f"x̄{name} ({sign})")
        band = np.nan_to_num(2 * stats.s[ok])
        ax.fill_between(
            r.targets[ok],
            stats.mean[ok] - band,
            stats.mean[ok] + band,
            color=colour,
            alpha=0.15,
            label=f"x̄{name} ± 2s{name}",
        )
    if r.bidirectional:
        ok = ~np.isnan(r.mean)
        ax.plot(r.targets[ok], r.mean[ok], "k--", lw=1, label="x̄ bidirectional")
    for name, profile in a.profiles.items():
        if name != "transverse":  # the comparator's transverse reading has its own scale
            slope, intercept = profile.line
            ax.plot(
                profile.position_mm,
                slope * profile.position_mm + intercept,
                "k:",
                lw=1,
                label="least-squares line",
            )
    ax.axhline(0, color="grey", lw=0.6)
    ax.set_xlabel(f"target position {m.axis or ''} (mm)")
    unit = "µrad" if column.endswith("urad") else "µm"
    ax.set_ylabel(f"{column.removesuffix('_um').removesuffix('_urad')}, actual − target ({unit})")
    f = a.figures
    if a.standard == "ISO 230-2":
        title = "ISO 230-2 (µm): " + ", ".join(
            f"{k} {f[k]:.2f}" for k in ("A", "E", "M", "B", "R") if f.get(k) is not None
        )
    else:
        title = _titles(a)
    ax.set_title(f"{os.path.basename(m.source)}\n{describe(m)}\n{title}", fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)


def _profile_panel(ax, a: Analysis) -> None:
    m = a.measurement
    unit = _profile_unit(m)
    for k, (name, profile) in enumerate(a.profiles.items()):
        target = ax if k == 0 else ax.twinx()
        slope, intercept = profile.line
        colour = f"C{k}"
        label_unit = "µm" if name == "height" else unit
        target.plot(
            profile.position_mm, profile.value, "-o", ms=3, color=colour, label=f"{name} ({label_unit})"
        )
        target.plot(
            profile.position_mm,
            slope * profile.position_mm + intercept,
            ":",
            color=colour,
            lw=1,
            label=f"{name}: least-squares line",
        )
        target.set_ylabel(f"{name} ({label_unit})")
        target.legend(fontsize=7, loc="upper left" if k == 0 else "lower right")
    if m.instrument == "grid":
        p, q = (x.lower() for x in m.plane_axes)
        ax.plot(m["s_mm"], np.hypot(m[f"dev_{p}_um"], m[f"dev_{q}_um"]), "-", label="|deviation| (µm)")
        ax.set_xlabel("path length (mm)")
        ax.legend(fontsize=7)
    else:
        ax.set_xlabel(f"position {m.axis or ''} (mm)")
    ax.set_title(f"{os.path.basename(m.source)}\n{describe(m)}\n{_titles(a)}", fontsize=9)
    ax.grid(alpha=0.3)
