"""Ball bar → error components (4.8.4.5) and ball bar → comparator (5.2.3) of M. Rahman,
*Modeling and measurement of multi-axis machine tools to improve positioning accuracy in a
software way*, University of Oulu, 2004.

Ground truth: the HR5B sample machine (XZFY, tens of µm positioning, a few
µrad angles, tens of µm/m squareness, reversal in its ± tables).  "Measured":
ball-bar files of it with 0.3 µm noise and fixed seeds.  The fit starts from
the structure alone (chain, offsets, no errors)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ncpp.cli import main
from ncpp.identify import account, identify
from ncpp.instruments.files import read_measurement, write_measurement
from ncpp.instruments.forward import predict_ballbar, predict_comparator, predict_laser
from ncpp.machine import load_machine

ROOT = Path(__file__).resolve().parents[2]
TRUE = load_machine(ROOT / "samples/machines/hr5b.toml")
BASE = load_machine(ROOT / "samples/thesis/hr5b_structure.toml")
NOISE = 0.3
# 3 planes (XY at two heights), 2 radii, both directions.
SETUPS = [(p, r, c) for p, c in (("XY", (400, 350, 200)), ("XY", (400, 350, 500)), ("ZX", (400, 350, 350)),
                                 ("YZ", (400, 350, 350))) for r in (100.0, 150.0)]  # fmt: skip
HELD_OUT = [("XY", 120.0, (350, 300, 350)), ("ZX", 200.0, (450, 350, 300)), ("YZ", 125.0, (500, 300, 400))]
X_TARGETS = np.arange(250.0, 551.0, 25.0)  # inside the tested X range


def measured() -> list:
    return [
        predict_ballbar(TRUE, p, r, c, step_deg=1.0, noise_um=NOISE, seed=i)
        for i, (p, r, c) in enumerate(SETUPS)
    ]


@pytest.fixture(scope="module")
def fitted():
    return identify(measured(), BASE)


def without_setup(angle_deg, values):
    """Residual of a ball-bar trace after the set-up offsets (length, centre)."""
    t = np.radians(angle_deg)
    N = np.column_stack([np.ones_like(t), np.cos(t), np.sin(t)])
    return values - N @ np.linalg.lstsq(N, values, rcond=None)[0]


def rms(v) -> float:
    return float(np.sqrt(np.mean(np.square(v))))


def detrended(x, v):
    return v - np.polyval(np.polyfit(x, v, 1), x)


def test_fit_explains_the_files_to_the_noise(fitted):
    machine, fit = fitted
    assert fit.rms_um < 1.15 * NOISE
    for f in fit.files:
        assert f.rms_before_um > 1.0  # the structure alone is far off
        assert f.rms_after_um < 1.2 * f.noise_um and f.noise_um == pytest.approx(NOISE, rel=0.2)
    assert 1.0 < fit.effective_parameters < sum(b.size for b in fit.blocks)  # the penalty acts (GCV λ)
    # Squareness, reversal and the tables come with uncertainties.
    for name in ("C0Y", "B0Z", "A0Z", "EXX reversal", "EZZ"):
        _, values, u = fit.block(name)
        assert np.all(np.isfinite(u)) and np.all(u > 0) and np.all(u < 1.0), name
    # Reversal of the ± tables (HR5B: EXX− − EXX+ ≈ 4 µm, EYY ≈ 6.5 µm): plus − minus.
    b, values, u = fit.block("EXX reversal")
    truth = (TRUE.component("EXX")(b.knots, 1.0) - TRUE.component("EXX")(b.knots, -1.0)) * 1e3
    assert np.max(np.abs(values - truth)) < 0.5
    assert machine.component("EXX").directional


def test_fitted_model_predicts_held_out_ballbar_tests(fitted):
    machine, _ = fitted
    for plane, radius, centre in HELD_OUT:
        truth = predict_ballbar(TRUE, plane, radius, centre, step_deg=1.0)
        model = predict_ballbar(machine, plane, radius, centre, step_deg=1.0)
        signal = rms(without_setup(truth["angle_deg"], truth["deviation_um"]))
        error = rms(without_setup(truth["angle_deg"], truth["deviation_um"] - model["deviation_um"]))
        assert signal > 1.5 and error < 0.2 * signal and error < 0.5, (plane, signal, error)


def test_ballbar_fit_predicts_the_comparator(fitted):
    """Section 5.2.3: the VM182 trace of X from ball-bar data.  The bar cannot
    see a scale common to all axes (its length offset is a set-up nuisance) nor
    the alignment of a straightness, so the linear trace is compared without its
    trend and the transverse one without its slope (as a comparator is aligned)."""
    machine, fit = fitted
    for transverse in ("Y", "Z"):
        truth = predict_comparator(TRUE, "X", transverse, X_TARGETS, fixed="Y=350 Z=350")
        model = predict_comparator(machine, "X", transverse, X_TARGETS, fixed="Y=350 Z=350")
        x = truth["target_mm"]
        for column in ("linear_um", "transverse_um"):
            error = rms(detrended(x, truth[column] - model[column]))
            assert error < 0.5, (transverse, column, error)
        signal = rms(detrended(x, truth["linear_um"]))
        assert rms(detrended(x, truth["linear_um"] - model["linear_um"])) < 0.2 * signal
    # ... and the fit says that the common scale is the bar's length.
    assert any({"EXX", "EYY"} <= set(g.components) or "EXX" in g.components for g in fit.unobservable)


def test_a_laser_file_of_one_axis_fixes_the_scale_and_the_comparator_follows():
    laser = predict_laser(TRUE, "Y", "position", np.arange(200.0, 501.0, 25.0), fixed="X=400 Z=350", runs=3,
                          noise_um=NOISE, seed=99)  # fmt: skip
    machine, fit = identify(measured() + [laser], BASE)
    assert "EYY" not in [b.component for b in fit.blocks]  # held: the laser gives it
    truth = predict_comparator(TRUE, "X", "Y", X_TARGETS, fixed="Y=350 Z=350")
    model = predict_comparator(machine, "X", "Y", X_TARGETS, fixed="Y=350 Z=350")
    error = rms(truth["linear_um"] - model["linear_um"])
    assert error < 1.0 and error < 0.2 * rms(truth["linear_um"]), error


def test_one_xy_plane_lists_what_it_cannot_separate_instead_of_inventing():
    one = predict_ballbar(TRUE, "XY", 150.0, (400, 350, 350), step_deg=1.0, noise_um=NOISE, seed=7)
    machine, fit = identify([one], BASE)
    assert fit.rms_um < 1.15 * NOISE  # its own data are explained ...
    names = {n for g in fit.unobservable for n in g.components}
    hints = {g.components: g.hint for g in fit.unobservable}
    # ... but out-of-plane straightness and the roll of X are not seen at all,
    assert "does not change" in hints[("EZX",)] and "does not change" in hints[("EAX",)]
    # a common scale of X and Y is the bar's length,
    assert "length offset" in hints[("EXX", "EYY")]
    # yaw of X through one lever arm looks like straightness,
    assert {"ECX", "EYX"} <= names
    # and those values are reported as not determined and are not written.
    for name in ("EZX", "EAX", "EBX"):
        _, _, u = fit.block(name)
        assert np.all(np.isnan(u))
        assert machine.component(name) is None
    assert "Z" not in {b.axis for b in fit.blocks}  # Z never moved: nothing of Z is fitted
    text = account(fit)
    assert "cannot separate" in text and "n.d." in text and "±" in text


def test_reversal_from_one_direction_is_not_separable():
    ccw = predict_ballbar(
        TRUE, "XY", 150.0, (400, 350, 350), step_deg=1.0, noise_um=NOISE, seed=3, directions="CCW"
    )
    _, fit = identify([ccw], BASE)
    reversal = [g for g in fit.unobservable if any("reversal" in n for n in g.components)]
    assert reversal and all("both directions" in g.hint or len(g.components) > 1 for g in reversal)
    _, _, u = fit.block("EXX reversal")
    assert np.isnan(u).sum() >= len(u) - 2  # the ends, where the axis turns, are seen


def test_fit_and_predict_commands_with_ballbar_files(tmp_path, capsys):
    files = []
    for i, m in enumerate(measured()):
        path = tmp_path / f"bb{i}.csv"
        write_measurement(m, path)
        files.append(str(path))
    structure = str(ROOT / "samples/thesis/hr5b_structure.toml")
    out = tmp_path / "comparator.csv"
    saved = tmp_path / "fitted.toml"
    args = ["predict", "--from", *files, "--base", structure, "--instrument", "comparator", "--axis", "X",
            "--transverse", "Y", "--targets", "250:550:25", "--fixed", "Y=350 Z=350", "--runs", "1",
            "--save-machine", str(saved), "-o", str(out)]  # fmt: skip
    assert main(args) == 0
    predicted = read_measurement(out)
    truth = predict_comparator(TRUE, "X", "Y", X_TARGETS, fixed="Y=350 Z=350")
    x = truth["target_mm"]
    assert rms(detrended(x, truth["linear_um"] - predicted["linear_um"])) < 0.5
    assert load_machine(saved).squareness["C0Y"] != 0.0
    capsys.readouterr()
    assert main(["fit", files[0], "--base", structure, "-o", str(tmp_path / "one.toml")]) == 0
    text = capsys.readouterr().out
    assert "ball-bar fit: 1 file(s)" in text and "cannot separate" in text and "C0Y" in text
