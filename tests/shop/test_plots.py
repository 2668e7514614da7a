"""The plots hold what they say: the artists' data, not pixels."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from ncpp.cli import main  # noqa: E402
from ncpp.cli.simulate import contour_figure, program_events  # noqa: E402
from ncpp.diagnose import diagnose  # noqa: E402
from ncpp.diagnose.report import gap_figure  # noqa: E402
from ncpp.errors import Warnings  # noqa: E402
from ncpp.instruments.analysis import analyze  # noqa: E402
from ncpp.instruments.files import read_measurement  # noqa: E402
from ncpp.instruments.forward import predict_ballbar  # noqa: E402
from ncpp.instruments.plots import analyses_figure, figure_text  # noqa: E402
from ncpp.machine import load_machine  # noqa: E402
from ncpp.machine.effects import Backlash  # noqa: E402
from ncpp.motion.offsets import WorkOffsets  # noqa: E402
from ncpp.simulate import contour_error, sample_events  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
STORY = ROOT / "samples" / "story"
MEASUREMENTS = ROOT / "samples" / "measurements"


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


def test_simulate_plot_draws_the_contour_error_along_the_path_and_a_map_coloured_by_it(tmp_path):
    machine = load_machine(STORY / "warm_machine.toml")
    events = program_events(str(STORY / "circle.ngc"), Warnings(), WorkOffsets.at((400.0, 350.0, 350.0)))
    path = sample_events(events, 2.0)
    report = contour_error(machine, path, path)
    fig = contour_figure(report, plt)
    along, plan = fig.axes[0], fig.axes[1]
    (line,) = along.get_lines()
    assert len(line.get_ydata()) == report.samples > 100
    assert np.max(line.get_ydata()) == pytest.approx(report.max_um)
    assert line.get_xdata()[-1] == pytest.approx(2 * np.pi * 150, rel=0.01)  # the circle's length, mm
    (dots,) = plan.collections
    assert len(dots.get_offsets()) == report.samples
    np.testing.assert_allclose(dots.get_array(), report.error_um)
    radius = np.hypot(
        dots.get_offsets()[:, 0] - 400.0, dots.get_offsets()[:, 1] - 350.0
    )  # machine XY of the circle
    np.testing.assert_allclose(radius, 150.0, atol=0.01)
    out = tmp_path / "sim.png"
    assert main(["simulate", "--machine", str(STORY / "warm_machine.toml"), "--work-offset", "400,350,350",
                 str(STORY / "circle.ngc"), "--step", "5", "--plot", str(out)]) == 0  # fmt: skip
    assert out.read_bytes()[:4] == b"\x89PNG"


def test_analyze_overlays_files_of_one_kind_on_one_scale():
    analyses = [analyze(read_measurement(MEASUREMENTS / name)) for name in
                ("ballbar_XY_R150.csv", "ballbar_ZX_R100.csv", "comparator_X.csv", "laser_X_position.csv",
                 "laser_X_straightness_y.csv")]  # fmt: skip
    fig = analyses_figure(analyses, plt)
    assert len(fig.axes) == 3  # circular tests, positioning, straightness
    polar, positioning, straightness = fig.axes
    labels = [line.get_label() for line in polar.get_lines()]
    assert any(lab.startswith("ballbar_XY_R150.csv CCW") for lab in labels)
    assert any(lab.startswith("ballbar_ZX_R100.csv CW") for lab in labels)
    extreme = max(np.max(np.abs(line.get_ydata())) for line in polar.get_lines())
    assert polar.get_ylim()[1] >= extreme  # one deviation scale holds both files
    names = {
        line.get_label().split()[0]
        for line in positioning.get_lines()
        if line.get_label().endswith(("↑", "↓"))
    }
    assert names == {"comparator_X.csv", "laser_X_position.csv"}
    assert all(
        len(line.get_ydata()) > 3 for line in positioning.get_lines() if line.get_label().endswith("↑")
    )
    title = straightness.get_title()
    assert "straightness 8.02 µm" in title and "slope 3.93 µm/m" in title and "_um" not in title


def test_figures_are_named_in_words_with_units():
    assert figure_text("straightness_um", 3.2) == "straightness 3.20 µm"
    assert figure_text("slope_um_per_m_per_m", 0.5) == "slope 0.50 µm/m per m"
    assert figure_text("slope_urad_per_m", 0.5) == "slope 0.50 µrad/m"
    assert figure_text("B_mean", 1.0) == "B̄ 1.00 µm"


def test_diagnose_plot_shows_measured_and_modelled_before_and_after_each_step():
    model = load_machine(ROOT / "samples/machines/hr5b.toml")
    truth = model.replace(effects=(Backlash("Y", 8.0),))
    data = [predict_ballbar(truth, "XY", 100, (400, 350, 300), step_deg=2.0, noise_um=0.3, seed=0)]
    d = diagnose(model, data)
    assert len(d.steps) == 1
    fig = gap_figure(d, plt)
    panel = fig.axes[1]
    lines = {line.get_label(): line for line in panel.get_lines()}
    o = d.observations[0]
    ccw = o.label == "CCW"
    order = np.argsort(o.position[ccw])
    np.testing.assert_allclose(lines["measured CCW"].get_ydata(), o.y[ccw][order])
    before, after = lines["model as given CCW"].get_ydata(), lines["after backlash Y CCW"].get_ydata()
    measured = o.y[ccw][order]
    # the step brings the model to the measurement: what is left is the noise
    assert np.sqrt(np.mean((measured - after) ** 2)) < 0.5 < np.sqrt(np.mean((measured - before) ** 2))
