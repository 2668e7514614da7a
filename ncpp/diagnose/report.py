"""The readable account and the gap plot of a `Diagnosis`."""

from __future__ import annotations

import os

import numpy as np

from ncpp.diagnose.workflow import Diagnosis


def _params(values: dict[str, float], unc: dict[str, float]) -> str:
    return ", ".join(f"{v:.3g} ± {unc[k]:.2g} {k}" if k in unc else f"{v:.4g} {k}" for k, v in values.items())


def account(d: Diagnosis) -> str:
    """What was compared, where the gap sits, each step, the gap table."""
    lines = [
        f"model: {d.base.name} ({len(d.base.effects)} effect(s) before diagnosis)",
        "",
        "where the gap sits (µm):",
    ]
    lines += [f"  {w}" for w in d.where]
    noise = np.sqrt(np.mean(np.square(d.noise)))
    lines += ["", f"noise (high-frequency part / repeat runs): {noise:.2f} µm rms", ""]
    if not d.steps:
        lines.append(
            "no candidate effect is significant: the model explains the measurements within their noise"
        )
    for i, s in enumerate(d.steps, 1):
        keys = " ".join(s.candidate.keys.values())
        variant = f" [{s.candidate.variant}]" if s.candidate.variant else ""
        lines.append(f"step {i}: {s.candidate.kind} {keys}{variant}: {_params(s.parameters, s.uncertainty)}")
        lines.append(f"  evidence: {s.evidence}")
        for a in s.alternatives:
            tests = " or ".join(a.separated_by) or "no variation of the given ball-bar tests"
            fitted = _params(a.parameters, a.uncertainty)
            lines.append(f"  or, as the data cannot tell: {a.candidate.name}: {fitted}")
            lines.append(f"    to tell them apart, measure {tests}")
    if d.not_observable:
        lines += ["", "not observable with these measurements: " + ", ".join(d.not_observable)]
    lines += [
        "",
        "gap, re-simulated (set-up offsets removed):",
        f"  {'model':<40} {'rms µm':>8} {'max µm':>8}",
    ]
    lines.append(f"  {'as given':<40} {d.gap_before.rms_um:8.2f} {d.gap_before.max_um:8.2f}")
    for s in d.steps:
        label = "+ " + s.candidate.kind + " " + " ".join(s.candidate.keys.values())
        lines.append(f"  {label:<40} {s.gap_after.rms_um:8.2f} {s.gap_after.max_um:8.2f}")
    return "\n".join(lines)


def plot_gap(d: Diagnosis, path: str | os.PathLike[str]) -> None:
    """Gap rms per step (top) and, per file, measured against modelled before and after each step."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ncpp.fileio import atomic_output

    fig = gap_figure(d, plt)
    with atomic_output(path) as f:
        fig.savefig(f, format="png", dpi=110)
    plt.close(fig)


def gap_figure(d: Diagnosis, plt):
    """The figure `plot_gap` draws (pyplot passed in, its backend chosen).  The modelled
    readings are the measured ones minus the residual the model leaves (set-up offsets
    fitted), so measured and modelled share the set-up."""
    n = len(d.observations)
    cols = min(n, 3)
    rows = 1 + -(-n // cols)
    fig = plt.figure(figsize=(4.2 * cols, 3.2 * rows))
    ax = fig.add_subplot(rows, 1, 1)
    labels = ["model"] + [f"+{s.candidate.kind} {' '.join(s.candidate.keys.values())}" for s in d.steps]
    rms = [d.gap_before.rms_um] + [s.gap_after.rms_um for s in d.steps]
    ax.bar(range(len(rms)), rms, color="tab:blue")
    ax.axhline(float(np.sqrt(np.mean(np.square(d.noise)))), color="k", ls="--", lw=1, label="noise")
    ax.set_xticks(range(len(rms)), labels, fontsize=8)
    ax.set_ylabel("gap rms / µm")
    ax.legend(fontsize=8)
    ax.set_title("diagnosis: the gap between measurement and model, step by step", fontsize=10)
    models = [("model as given", d.gap_before)]
    models += [(f"after {label[1:]}", s.gap_after) for label, s in zip(labels[1:], d.steps, strict=True)]
    for i, o in enumerate(d.observations):
        a = fig.add_subplot(rows, cols, cols + i + 1)
        for lab in dict.fromkeys(o.label):
            sel = o.label == lab
            order = np.argsort(o.position[sel])
            x, measured = o.position[sel][order], o.y[sel][order]
            style = "-" if lab in ("CCW", "+") else ":"
            a.plot(x, measured, color="k", lw=1.2, ls=style, label=f"measured {lab}")
            for k, (name, gap) in enumerate(models):
                modelled = measured - gap.residuals[i][sel][order]
                a.plot(x, modelled, color=f"C{k + 1}", lw=0.8, ls=style, label=f"{name} {lab}")
        setup = o.measurement.plane if o.measurement.instrument == "ballbar" else o.measurement.axis
        a.set_title(f"{o.measurement.instrument} {setup} F{o.feed:g}: measured and modelled", fontsize=8)
        a.set_xlabel("angle / deg" if o.measurement.instrument == "ballbar" else "target / mm", fontsize=8)
        a.set_ylabel("reading / µm", fontsize=8)
        a.tick_params(labelsize=7)
        if i == 0:
            a.legend(fontsize=5)
    fig.tight_layout()
    return fig
