"""Each non-geometric effect does what its definition says."""

import numpy as np
import pytest

from ncpp.machine import Machine, Table, Trajectory, effect_from_dict
from ncpp.machine.effects import (
    EFFECTS,
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


def there_and_back(axis=0, length=100.0, step=0.5) -> Trajectory:
    end = np.zeros(3)
    end[axis] = length
    return Trajectory.line(np.zeros(3), end, 1000.0, step).then(
        Trajectory.line(end, np.zeros(3), 1000.0, step)
    )


def radial(traj: Trajectory, dev: np.ndarray, centre) -> np.ndarray:
    u = traj.positions - centre
    u /= np.linalg.norm(u, axis=1)[:, None]
    return np.einsum("ij,ij->i", dev, u)


def test_backlash_is_a_play_operator():
    traj = there_and_back()
    d = Backlash("X", 6.0).apply(traj)[:, 0] * 1e3
    n = len(traj) // 2
    assert np.allclose(d[5 : n - 1], -3.0)  # lags half the play behind going +
    assert np.allclose(d[n + 20 :], 3.0)  # and the other half going −
    # after the reversal it stands still: lost motion of exactly b
    x = traj.positions[:, 0]
    actual = x + d * 1e-3
    turn = np.argmax(x)
    still = np.flatnonzero(np.isclose(actual[turn : turn + 30], actual[turn]))
    assert (x[turn] - x[turn + still[-1]]) == pytest.approx(6e-3, abs=0.5)  # within one sample
    assert np.ptp(d) == pytest.approx(6.0)


def test_negative_backlash_leads_and_jumps_ahead_on_reversal():
    # machine-file.md, [[effects]]: um < 0 is a control's backlash compensation set larger than the
    # play (as ISO 230-4's signed backlash of a ball-bar trace says, `instruments/iso230_4.py`)
    traj = there_and_back()
    d = Backlash("X", -6.0).apply(traj)[:, 0] * 1e3
    n = len(traj) // 2
    assert np.allclose(d[5 : n - 1], 3.0)  # ahead of the command by half of it going +
    assert np.allclose(d[n + 1 :], -3.0)  # and going −, from the first step after the turn
    x = traj.positions[:, 0]
    turn = int(np.argmax(x))
    jump = (x[turn + 1] + d[turn + 1] * 1e-3) - (x[turn] + d[turn] * 1e-3)
    assert jump == pytest.approx(-(0.5 + 6e-3))  # one step back and 6 µm more: the overshoot


def test_backlash_step_on_circle_at_axis_reversal():
    c = np.array([0.0, 0.0, 0.0])
    traj = Trajectory.circle("XY", c, 100.0, "CCW", step_deg=0.1)
    dev = Backlash("X", 8.0).apply(traj)
    # X reverses at 180° (x min): deviation goes from +4 (moving −x) to −4 µm
    x_dev = dev[:, 0] * 1e3
    assert x_dev[500] == pytest.approx(4.0) and x_dev[2500] == pytest.approx(-4.0)


def test_lateral_play_flips_on_reversal():
    traj = there_and_back()
    d = LateralPlay("X", 5.0).apply(traj) * 1e3
    assert np.allclose(d[:, 0], 0) and np.allclose(d[:, 2], 0)
    assert d[10, 1] == pytest.approx(2.5) and d[-10, 1] == pytest.approx(-2.5)
    assert LateralPlay("X", 5.0, direction="Z").apply(traj)[10, 2] == pytest.approx(2.5e-3)


def test_reversal_spike_peaks_after_reversal_and_decays():
    traj = there_and_back()
    d = ReversalSpike("X", 3.0, decay_mm=2.0).apply(traj)[:, 0] * 1e3
    turn = int(np.argmax(traj.positions[:, 0]))
    assert np.all(d[:turn] == 0)
    assert d[turn] == pytest.approx(3.0)  # outward (+x at the +x end)
    assert d[turn + 4] == pytest.approx(3.0 * np.exp(-1.0))  # 2 mm later
    assert abs(d[-1]) < 1e-6
    t = ReversalSpike("X", 3.0, decay_ms=50.0).apply(traj)[:, 0] * 1e3
    dt = traj.time[turn + 4] - traj.time[turn]
    assert t[turn + 4] == pytest.approx(3.0 * np.exp(-dt / 0.05))


@pytest.mark.parametrize("feed", [500.0, 2000.0])
def test_servo_mismatch_flips_with_direction_and_grows_with_feed(feed):
    c, R, ms = np.zeros(3), 100.0, 1.0
    eff = ServoMismatch("XY", ms)
    out = {}
    for direction in ("CCW", "CW"):
        traj = Trajectory.circle("XY", c, R, direction, feed_mm_min=feed, step_deg=0.5)
        theta = np.arctan2(traj.positions[:, 1], traj.positions[:, 0])
        dR = radial(traj, eff.apply(traj), c)
        expected = (1 if direction == "CCW" else -1) * feed / 60 * ms * 1e-3 / 2 * np.sin(2 * theta)
        assert np.allclose(dR[1:-1], expected[1:-1], atol=1e-6)
        out[direction] = dR
    assert np.abs(out["CCW"]).max() == pytest.approx(feed / 60 * ms * 1e-3 / 2, rel=1e-3)


def test_scale_cyclic_squareness_straightness():
    traj = Trajectory.line([0, 0, 0], [1000, 500, 200], 1000.0, 5.0)
    x, y, z = traj.positions.T
    assert np.allclose(Scale("X", 10.0, ref_mm=100).apply(traj)[:, 0], 10e-6 * (x - 100))
    cyc = Cyclic("Y", 2.0, 10.0, 90.0).apply(traj)[:, 1]
    assert np.allclose(cyc, 2e-3 * np.cos(2 * np.pi * y / 10.0))
    for plane, (dev, drive) in {"XY": (0, 1), "YZ": (1, 2), "ZX": (2, 0)}.items():
        sq = Squareness(plane, 20.0).apply(traj)
        assert np.allclose(sq[:, dev], 20e-6 * traj.positions[:, drive])
    bow = Straightness("X", "Z", 4.0).apply(traj)[:, 2]
    assert bow[0] == 0 and bow[-1] == pytest.approx(0) and bow.max() == pytest.approx(4e-3)
    assert bow[np.argmin(abs(x - 500))] == pytest.approx(4e-3)


def test_angular_uses_the_machine_abbe_offset():
    # Z roll growing with z makes XY squareness vary with Z on an XZFY machine.
    eff = Angular("ECZ", 50.0)
    hr5b = Machine("m", "XZFY")
    c = np.array([0.0, 0.0, 0.0])
    skew = []
    for z in (0.0, 400.0):
        traj = Trajectory.circle("XY", c + [0, 0, z], 100.0, "CCW")
        dR = radial(traj, eff.apply(traj, machine=hr5b), c + [0, 0, z])
        theta = np.arctan2(traj.positions[:, 1], traj.positions[:, 0])
        skew.append(2 * np.mean(dR * np.sin(2 * theta)))  # ΔR amplitude of sin 2θ
    assert skew[0] == pytest.approx(0.0, abs=1e-12)
    # ε = 50 µrad/m · 0.4 m = 20 µrad; δx = −ε·y  ->  ΔR = −(εR/2) sin 2θ
    assert skew[1] == pytest.approx(-20e-6 * 100 / 2, rel=1e-3)


def test_dict_round_trip_for_every_kind():
    samples = [
        Scale("X", 5.0),
        Backlash("Y", 3.0),
        LateralPlay("Z", 2.0, "Y"),
        ReversalSpike("X", 1.0, decay_ms=20.0),
        ServoMismatch("YZ", 0.5),
        Squareness("ZX", 12.0),
        Straightness("Y", "X", 3.0, (0.0, 500.0)),
        Cyclic("Z", 1.0, 5.0, 30.0),
        Angular("EAY", 10.0),
    ]
    assert {e.kind for e in samples} == set(EFFECTS)
    for e in samples:
        assert effect_from_dict(e.to_dict()) == e
    with pytest.raises(ValueError, match="unknown effect"):
        effect_from_dict({"kind": "gravity"})
    with pytest.raises(ValueError, match="missing"):
        effect_from_dict({"kind": "backlash", "axis": "X"})


def test_simulate_adds_geometry_direction_and_effects():
    t = Table([0, 100], [0.0, 0.0], values_minus=[0.002, 0.002])
    m = Machine("m", "XYFZ", components={"EXX": t}, effects=(Scale("X", 100.0),))
    traj = there_and_back()
    actual = m.simulate(traj)
    dev = actual - traj.positions
    n = len(traj) // 2
    assert np.allclose(dev[10, 0], 100e-6 * traj.positions[10, 0])
    assert np.allclose(dev[n + 10, 0], 0.002 + 100e-6 * traj.positions[n + 10, 0])


def test_trajectory_constructors():
    circ = Trajectory.circle("ZX", [1, 2, 3], 50.0, "CW", feed_mm_min=600, start_deg=90, overshoot_deg=10)
    # ZX: angle from +Z towards +X; start 90° -> +X; CW turns towards +Z first... decreasing angle
    ang = np.rad2deg(np.arctan2(circ.positions[:, 0] - 1, circ.positions[:, 2] - 3))
    assert ang[0] == pytest.approx(100.0) and ang[1] < ang[0]
    assert circ.time[-1] == pytest.approx(2 * np.pi * 50 * 380 / 360 / 10.0, rel=1e-4)  # 10 mm/s
    with pytest.raises(ValueError):
        Trajectory.circle("XX", [0, 0, 0], 1.0)
    line = Trajectory.line([0, 0, 0], [10, 0, 0], 600.0, 1.0)
    assert len(line) == 11 and np.allclose(line.velocity[:, 0], 10.0)
    assert list(there_and_back(step=25.0).directions()[:, 0]) == [1, 1, 1, 1, 1, -1, -1, -1, -1]


def test_floating_point_noise_is_not_motion():
    """A still axis whose position went through another frame (400 mm = 15.748... in + its
    offset, back to mm) may differ by 1e-13 mm: that must not reverse it."""
    y = np.array([350.0, 350.0, 350.0 + 5.7e-14, 350.0 - 5.7e-14, 350.0, 351.0])
    path = Trajectory(np.column_stack([np.linspace(0.0, 10.0, 6), y, np.zeros(6)]), 1000.0)
    assert list(path.directions()[:, 1]) == [1, 1, 1, 1, 1, 1]
    assert len(path.reversals(1)) == 0
