"""The diagnosis finds an effect hidden in simulated measurements.

Ground truth: the HR5B sample machine plus one (or two) effects the model
lacks; the measurements are the instruments' forward models of the truth
with 0.3 µm rms noise (fixed seeds).  The diagnosis starts from the sample
machine without the effect and must name it (kind and axis/plane/component),
estimate its size within 20 % and bring the gap down to the noise level."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ncpp.diagnose import diagnose
from ncpp.diagnose.report import account
from ncpp.instruments.forward import predict_ballbar, predict_comparator, predict_laser
from ncpp.machine import load_machine
from ncpp.machine.effects import (
    Angular,
    Backlash,
    Cyclic,
    LateralPlay,
    ReversalSpike,
    Scale,
    ServoMismatch,
    Squareness,
    Straightness,
)

ROOT = Path(__file__).resolve().parents[2]
NOISE = 0.3
MODEL = load_machine(ROOT / "samples/machines/hr5b.toml")
CENTRE = (400.0, 350.0, 350.0)
THREE_PLANES = (("XY", (400.0, 350.0, 300.0)), ("YZ", CENTRE), ("ZX", CENTRE))


def ballbars(truth, setups=THREE_PLANES, feeds=(1000.0,), directions=("CCW", "CW"), step_deg=1.0, seed=0):
    out = []
    for plane, centre in setups:
        for feed in feeds:
            out.append(predict_ballbar(truth, plane, 100.0, centre, feed_mm_min=feed, directions=directions,
                                       step_deg=step_deg, noise_um=NOISE, seed=seed))  # fmt: skip
            seed += 1
    return out


def hidden(*effects):
    return MODEL.replace(effects=MODEL.effects + effects)


def check_found(d, effect, size_key, truth_size, keys):
    assert len(d.steps) == 1, [s.candidate.name for s in d.steps]
    step = d.steps[0].to_dict()
    assert step["effect"] == effect.kind
    for k, v in keys.items():
        assert step[k] == v
    assert step["parameters"][size_key] == pytest.approx(truth_size, rel=0.2)
    assert d.gap_before.rms_um > 1.5 * NOISE  # the effect was visible
    assert d.gap_after.rms_um < 1.5 * NOISE
    return step


CASES = [
    # (id, hidden effect, report keys, size key, size, measurement options)
    ("scale", Scale("X", 20.0), {"axis": "X"}, "um_per_m", 20.0, {}),
    ("backlash", Backlash("Y", 8.0), {"axis": "Y"}, "um", 8.0, {}),
    ("lateral_play", LateralPlay("X", 6.0), {"axis": "X"}, "um", 6.0, {}),
    ("reversal_spike", ReversalSpike("Z", 10.0), {"axis": "Z"}, "um", 10.0, {}),
    ("servo_mismatch", ServoMismatch("XY", 1.0), {"axes": "XY"}, "ms", 1.0, {"feeds": (1000.0, 3000.0)}),
    ("squareness", Squareness("ZX", 25.0), {"plane": "ZX"}, "um_per_m", 25.0, {}),
    ("straightness", Straightness("X", "Y", 6.0), {"axis": "X", "direction": "Y"}, "um", 6.0, {}),
    ("cyclic", Cyclic("X", 3.0, 10.0, 30.0), {"axis": "X"}, "um", 3.0, {}),
    ("angular", Angular("ECZ", 40.0), {"component": "ECZ"}, "urad_per_m", 40.0,
     {"setups": THREE_PLANES + (("XY", (400.0, 350.0, 600.0)),)}),
]  # fmt: skip


@pytest.mark.parametrize(
    "effect, keys, size_key, size, options", [c[1:] for c in CASES], ids=[c[0] for c in CASES]
)
def test_one_hidden_effect_is_named_sized_and_closes_the_gap(effect, keys, size_key, size, options):
    d = diagnose(MODEL, ballbars(hidden(effect), **options))
    step = check_found(d, effect, size_key, size, keys)
    if effect.kind == "cyclic":
        assert step["parameters"]["period_mm"] == pytest.approx(10.0, rel=0.02)
    # The updated model carries the effect (and nothing else new).
    assert [e.kind for e in d.updated.effects] == [effect.kind]


def test_nothing_hidden_adds_no_step():
    d = diagnose(MODEL, ballbars(MODEL, feeds=(1000.0, 2500.0)))
    assert d.steps == []
    assert d.gap_after.rms_um == pytest.approx(NOISE, rel=0.15)
    assert d.report("m")["steps"] == []


def test_two_hidden_effects_are_both_found():
    truth = hidden(Backlash("X", 6.0), Squareness("XY", -25.0))
    d = diagnose(MODEL, ballbars(truth))
    found = {(s.candidate.kind, tuple(s.candidate.keys.values())): s.parameters for s in d.steps}
    assert set(found) == {("backlash", ("X",)), ("squareness", ("XY",))}
    assert found[("backlash", ("X",))]["um"] == pytest.approx(6.0, rel=0.2)
    assert found[("squareness", ("XY",))]["um_per_m"] == pytest.approx(-25.0, rel=0.2)
    assert d.gap_after.rms_um < 1.5 * NOISE
    rms = [d.gap_before.rms_um] + [s.gap_after.rms_um for s in d.steps]
    assert rms == sorted(rms, reverse=True)  # the gap shrinks step by step


def test_squareness_and_servo_mismatch_from_one_direction_are_ambiguous():
    # One direction at one feed: servo lag of X behind Y and an XY squareness
    # both give the same 2θ ovality; the report must say so, not guess.
    truth = hidden(ServoMismatch("XY", 1.5))
    d = diagnose(MODEL, ballbars(truth, setups=(("XY", (400.0, 350.0, 300.0)),), directions=("CCW",)))
    assert len(d.steps) == 1
    step = d.steps[0].to_dict()
    assert {step["effect"]} <= {"servo_mismatch", "squareness"}
    assert "ambiguous" in step["evidence"]
    other = "squareness" if step["effect"] == "servo_mismatch" else "servo_mismatch"
    assert other in step["evidence"]
    alternatives = {(a["effect"], a.get("plane") or a.get("axes")): a for a in step["alternatives"]}
    assert ("squareness", "XY") in alternatives or ("servo_mismatch", "XY") in alternatives
    # With both directions it is a servo mismatch, no longer confused with
    # squareness (one plane still cannot say which axis pair lags: XY, YZ, ZX
    # all put the same lag difference between X and Y).
    d2 = diagnose(MODEL, ballbars(truth, setups=(("XY", (400.0, 350.0, 300.0)),)))
    step = d2.steps[0].to_dict()
    assert (step["effect"], step["axes"]) == ("servo_mismatch", "XY")
    assert step["parameters"]["ms"] == pytest.approx(1.5, rel=0.2)
    assert "squareness" not in step["evidence"]


def test_laser_and_comparator_show_thermal_growth_and_lateral_play():
    truth = hidden(Scale("Y", 30.0), LateralPlay("X", 5.0, "Y"))
    targets = np.arange(0.0, 701.0, 100.0)
    files = [
        predict_laser(truth, "Y", "position", targets, fixed={"X": 400, "Z": 350}, runs=3, noise_um=NOISE, seed=1),
        predict_comparator(truth, "X", "Y", np.arange(0.0, 801.0, 100.0), fixed={"Y": 350, "Z": 350}, runs=3,
                           noise_um=NOISE, seed=2),
    ]  # fmt: skip
    d = diagnose(MODEL, files)
    found = {(s.candidate.kind, tuple(s.candidate.keys.values())): s.parameters for s in d.steps}
    assert found[("scale", ("Y",))]["um_per_m"] == pytest.approx(30.0, rel=0.2)
    assert found[("lateral_play", ("X",))]["um"] == pytest.approx(5.0, rel=0.2)
    assert len(found) == 2
    assert d.gap_after.rms_um < 1.5 * NOISE


def test_alternatives_are_listed_fitted_and_told_how_to_separate():
    # One XY ball bar, one direction: a servo lag of X behind Y looks like an XY squareness
    # (both a 2θ ovality) and, in that plane, like the same lag of the pair YZ or ZX.
    truth = hidden(ServoMismatch("XY", 1.5))
    data = ballbars(truth, setups=(("XY", (400.0, 350.0, 300.0)),), directions=("CCW",))
    d = diagnose(MODEL, data)
    (step,) = d.steps
    assert (step.candidate.kind, step.candidate.keys) == ("servo_mismatch", {"axes": "XY"})
    report = step.to_dict()
    alternatives = {(a["effect"], a.get("plane") or a.get("axes")): a for a in report["alternatives"]}
    assert {("squareness", "XY"), ("servo_mismatch", "YZ"), ("servo_mismatch", "ZX")} <= set(alternatives)
    square = alternatives[("squareness", "XY")]
    # A squareness only shapes the circle; a lag flips with the direction and grows with the feed.
    assert "the ball bar XY R100 F1000 run in the other direction (CW) too" in square["separated_by"]
    assert "the ball bar XY R100 F1000 at another feed (F2000)" in square["separated_by"]
    # The lag of another axis pair differs only where that pair moves: another plane, not another direction.
    lag = alternatives[("servo_mismatch", "YZ")]
    assert any("another plane" in t for t in lag["separated_by"])
    assert not any("other direction" in t or "another radius" in t for t in lag["separated_by"])
    # The squareness fitted in the step's place explains the data as well: nothing is left to add.
    again = diagnose(hidden(Squareness("XY", square["parameters"]["um_per_m"])), data)
    assert again.steps == [] and again.gap_before.rms_um < 1.5 * NOISE
    text = account(d)
    assert "or, as the data cannot tell: squareness XY" in text
    assert (
        "to tell them apart, measure the ball bar XY R100 F1000 run in the other direction (CW) too" in text
    )
