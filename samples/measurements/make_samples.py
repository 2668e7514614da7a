"""Make the sample measurement files of this folder (fixed seed, reproducible).

    python samples/measurements/make_samples.py [OUTDIR]

The ball-bar and grid traces come from a small first-principles simulation
of two axes moving round a circle (`simulate_circle`): servo lag per axis,
backlash as a play operator, reversal spikes, scale and squareness errors act
on the axis positions, and the bar length is the exact distance between the
balls.  The tests use the same simulation to check that the ISO 230-4
diagnosis recovers each effect with the right sign.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))  # run from a source checkout without installing

from ncpp.instruments.files import make_measurement, write_measurement  # noqa: E402


def play(x: np.ndarray, width: float) -> np.ndarray:
    """Play (backlash) operator: the output follows x only once x has taken up the play."""
    out = np.empty_like(x)
    y = x[0] - width / 2  # as if the lead-in approached from below
    for k, xk in enumerate(x):
        y = min(max(y, xk - width / 2), xk + width / 2)
        out[k] = y
    return out


def reversal_spike(cmd: np.ndarray, travel_deg: np.ndarray, height: float, width_deg: float) -> np.ndarray:
    """Outward transient after each reversal of the commanded axis position `cmd`."""
    out = np.zeros_like(cmd)
    v = np.diff(cmd)
    flips = np.nonzero(np.sign(v[1:]) * np.sign(v[:-1]) < 0)[0] + 1
    for k in flips:
        after = slice(k, None)
        phi = travel_deg[after] - travel_deg[k]
        out[after] += height * np.sign(cmd[k]) * np.exp(-phi / width_deg)
    return out


def simulate_circle(
    radius_mm: float,
    direction: str,
    *,
    points: int = 360,
    feed_mm_min: float = 1000.0,
    squareness_um_per_m: float = 0.0,
    scale_um_per_m: tuple[float, float] = (0.0, 0.0),
    backlash_um: tuple[float, float] = (0.0, 0.0),
    lag_ms: tuple[float, float] = (0.0, 0.0),
    spike_um: tuple[float, float] = (0.0, 0.0),
    spike_width_deg: float = 3.0,
    cyclic_um: tuple[float, float] = (0.0, 0.0),
    cyclic_period_mm: float = 10.0,
    setup_offset_um: tuple[float, float] = (0.0, 0.0),
    noise_um: float = 0.0,
    rng: np.random.Generator | None = None,
    overshoot_deg: float = 45.0,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Simulate one direction of a circular test in a plane (p, q) about the origin.

    Returns (angle_deg in [0,360), bar length minus radius in µm, actual points
    in mm relative to the fixed ball).  Angles are the commanded angles, one
    revolution starting at 0 after a lead-in arc of `overshoot_deg`.
    """
    sigma = 1.0 if direction == "CCW" else -1.0
    step = 360.0 / points
    # Lead-in, one revolution, lead-out: commanded angle as travel goes on.
    fine = 4  # simulate at a quarter of the sampling step, keep every fourth point
    lead = int(round(overshoot_deg / step)) * fine
    index = np.arange(-lead, points * fine + lead)
    travel = index * step / fine
    theta = np.radians(sigma * travel)
    omega = feed_mm_min / 60.0 / radius_mm  # rad/s
    lag = sigma * omega * np.array(lag_ms) / 1000.0  # angle (rad) the axis is behind
    p_cmd, q_cmd = radius_mm * np.cos(theta), radius_mm * np.sin(theta)
    p = radius_mm * np.cos(theta - lag[0])
    q = radius_mm * np.sin(theta - lag[1])
    p = play(p, backlash_um[0] / 1000.0) + reversal_spike(
        p_cmd, travel, spike_um[0] / 1000.0, spike_width_deg
    )
    q = play(q, backlash_um[1] / 1000.0) + reversal_spike(
        q_cmd, travel, spike_um[1] / 1000.0, spike_width_deg
    )
    wave = 2 * np.pi / cyclic_period_mm
    p_act = (
        p * (1 + scale_um_per_m[0] * 1e-6)
        + squareness_um_per_m * 1e-6 * q
        + cyclic_um[0] / 1000.0 * np.sin(wave * p)
    )
    q_act = q * (1 + scale_um_per_m[1] * 1e-6) + cyclic_um[1] / 1000.0 * np.sin(wave * q)
    ball = np.array(setup_offset_um) / 1000.0
    length = np.hypot(p_act - ball[0], q_act - ball[1])
    keep = (index >= 0) & (index < points * fine) & (index % fine == 0)
    angle = np.round((sigma * travel[keep]) % 360.0, 9) % 360.0
    dev = (length[keep] - radius_mm) * 1000.0
    if noise_um:
        dev = dev + (rng or np.random.default_rng(0)).normal(0.0, noise_um, dev.size)
    return angle, dev, np.column_stack([p_act[keep], q_act[keep]])


def laser_position(rng: np.random.Generator) -> dict:
    targets = np.linspace(0.0, 1000.0, 11)
    systematic = 0.012 * targets + 2.5 * np.sin(2 * np.pi * targets / 400.0)  # 12 µm/m + pitch error
    rows = []
    for run in range(1, 6):
        for direction, seq, shift in (("+", targets, -1.6), ("-", targets[::-1], 1.6)):
            for t in seq:
                i = int(round(t / 100))
                rows.append((t, run, direction, round(systematic[i] + shift + rng.normal(0, 0.6), 2)))
    return _columns(("target_mm", "run", "direction", "deviation_um"), rows)


def laser_angular(rng: np.random.Generator, amplitude_urad: float) -> dict:
    targets = np.linspace(0.0, 1000.0, 11)
    profile = amplitude_urad * (targets / 500.0 - 1.0) ** 2 - amplitude_urad / 2
    rows = [
        (t, run, d, round(profile[int(round(t / 100))] + rng.normal(0, 0.4), 2))
        for run in (1, 2, 3)
        for d, seq in (("+", targets), ("-", targets[::-1]))
        for t in seq
    ]
    return _columns(("target_mm", "run", "direction", "deviation_urad"), rows)


def laser_straightness(rng: np.random.Generator) -> dict:
    targets = np.linspace(0.0, 1000.0, 11)
    bow = -8.0 * (1 - ((targets - 500.0) / 500.0) ** 2) + 0.004 * targets  # 8 µm bow + 4 µm/m slope
    rows = [
        (t, run, d, round(bow[int(round(t / 100))] + rng.normal(0, 0.3), 2))
        for run in (1, 2, 3)
        for d, seq in (("+", targets), ("-", targets[::-1]))
        for t in seq
    ]
    return _columns(("target_mm", "run", "direction", "deviation_um"), rows)


def comparator(rng: np.random.Generator) -> dict:
    targets = np.linspace(-400.0, 400.0, 17)
    rows = []
    for run in range(1, 4):
        for direction, seq, shift in (("+", targets, -1.0), ("-", targets[::-1], 1.0)):
            for t in seq:
                linear = 0.015 * t + 1.2 * np.sin(2 * np.pi * t / 250.0) + shift + rng.normal(0, 0.4)
                transverse = 3.0 * (t / 400.0) ** 2 + 0.005 * t + rng.normal(0, 0.3)
                rows.append((t, run, direction, round(linear, 2), round(transverse, 2)))
    return _columns(("target_mm", "run", "direction", "linear_um", "transverse_um"), rows)


def level(rng: np.random.Generator) -> dict:
    x = np.linspace(0.0, 1000.0, 21)
    roll = 6.0 * np.sin(np.pi * x / 1000.0) - 2.0 + rng.normal(0, 0.3, x.size)
    return {"position_mm": x, "inclination_um_per_m": np.round(roll, 2)}


def ballbar(rng: np.random.Generator, radius: float, feed: float, **effects) -> dict:
    rows = []
    for direction in ("CCW", "CW"):
        angle, dev, _ = simulate_circle(radius, direction, feed_mm_min=feed, rng=rng, **effects)
        rows += [(direction, a, round(d, 2)) for a, d in zip(angle, dev)]
    return _columns(("direction", "angle_deg", "deviation_um"), rows)


def grid_circle(rng: np.random.Generator, radius: float, centre: tuple[float, float]) -> dict:
    angle, _, actual = simulate_circle(
        radius,
        "CCW",
        points=180,
        squareness_um_per_m=-15.0,
        backlash_um=(3.0, 2.0),
        lag_ms=(0.4, 0.0),
        feed_mm_min=2000.0,
        noise_um=0.0,
        rng=rng,
    )
    th = np.radians(angle)
    nominal = np.column_stack([radius * np.cos(th), radius * np.sin(th)])
    dev = (actual - nominal) * 1000.0 + rng.normal(0, 0.15, nominal.shape)
    return {
        "s_mm": np.round(radius * th, 4),
        "x_mm": np.round(nominal[:, 0] + centre[0], 4),
        "y_mm": np.round(nominal[:, 1] + centre[1], 4),
        "dev_x_um": np.round(dev[:, 0], 2),
        "dev_y_um": np.round(dev[:, 1], 2),
    }


def cutting(rng: np.random.Generator, radius: float) -> dict:
    angle = np.arange(0.0, 360.0, 5.0)
    th = np.radians(angle)
    # Squareness and X/Y scale mismatch make an ellipse; the cutter adds a small lobing.
    dev = (
        20e-6 * radius * 1000 / 2 * np.sin(2 * th)
        + 8e-6 * radius * 1000 / 2 * np.cos(2 * th)
        + 0.8 * np.cos(3 * th + 0.4)
        - 2.0
    )
    return {"angle_deg": angle, "radius_dev_um": np.round(dev + rng.normal(0, 0.25, angle.size), 2)}


def _columns(names: tuple[str, ...], rows: list[tuple]) -> dict:
    return {name: [row[i] for row in rows] for i, name in enumerate(names)}


def samples() -> dict[str, tuple[str, dict, dict]]:
    """File name -> (instrument, metadata, columns)."""
    rng = np.random.default_rng(20040101)
    common = {"machine": "Mitsui Seiki HR5B (simulated)", "date": "2026-11-21", "temperature_c": 20.3}
    return {
        "laser_X_position.csv": (
            "laser",
            {
                **common,
                "axis": "X",
                "quantity": "position",
                "fixed": "Y=-250 Z=300",
                "offset_mm": "0,0,120",
                "feed_mm_min": 1000,
            },
            laser_position(rng),
        ),
        "laser_X_pitch.csv": (
            "laser",
            {
                **common,
                "axis": "X",
                "quantity": "pitch",
                "component": "EBX",
                "fixed": "Y=-250 Z=300",
                "offset_mm": "0,0,120",
            },
            laser_angular(rng, 12.0),
        ),
        "laser_X_straightness_y.csv": (
            "laser",
            {
                **common,
                "axis": "X",
                "quantity": "straightness_y",
                "component": "EYX",
                "fixed": "Y=-250 Z=300",
                "offset_mm": "0,0,120",
            },
            laser_straightness(rng),
        ),
        "comparator_X.csv": (
            "comparator",
            {**common, "axis": "X", "transverse": "Y", "fixed": "Y=0 Z=350", "offset_mm": "0,0,100"},
            comparator(rng),
        ),
        "level_X_roll.csv": (
            "level",
            {**common, "axis": "X", "quantity": "roll", "fixed": "Y=0 Z=350"},
            level(rng),
        ),
        "ballbar_XY_R150.csv": (
            "ballbar",
            {**common, "plane": "XY", "radius_mm": 150, "center_mm": "400,-200,350", "feed_mm_min": 1000},
            ballbar(
                rng,
                150.0,
                1000.0,
                squareness_um_per_m=40.0,
                backlash_um=(4.0, 2.5),
                lag_ms=(0.5, 0.0),
                scale_um_per_m=(15.0, 5.0),
                setup_offset_um=(6.0, -3.0),
                noise_um=0.2,
            ),
        ),
        "ballbar_ZX_R100.csv": (
            "ballbar",
            {**common, "plane": "ZX", "radius_mm": 100, "center_mm": "400,-200,300", "feed_mm_min": 2000},
            ballbar(
                rng,
                100.0,
                2000.0,
                squareness_um_per_m=-25.0,
                backlash_um=(1.5, 5.0),
                spike_um=(0.0, 3.0),
                setup_offset_um=(-4.0, 2.0),
                noise_um=0.2,
            ),
        ),
        "grid_XY_circle.csv": (
            "grid",
            {**common, "plane": "XY", "radius_mm": 115, "center_mm": "0,0,0", "feed_mm_min": 2000},
            grid_circle(rng, 115.0, (0.0, 0.0)),
        ),
        "cutting_XY_R50.csv": (
            "cutting",
            {
                **common,
                "plane": "XY",
                "radius_mm": 50,
                "center_mm": "300,-150,0",
                "feed_mm_min": 600,
                "direction": "CCW",
                "tool_diameter_mm": 10,
            },
            cutting(rng, 50.0),
        ),
    }


def main(outdir: Path = HERE) -> None:
    for name, (instrument, meta, columns) in samples().items():
        write_measurement(make_measurement(instrument, meta, columns, name), outdir / name)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else HERE)
