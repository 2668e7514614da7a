"""Volumetric error: chain geometry, Abbe terms, linearisation, squareness."""

import time

import numpy as np
import pytest

from ncpp.machine import Machine, Polynomial, Table, load_machine

SAMPLES = "samples/machines"


def const(value: float) -> Table:
    return Table([0.0], [value])


def test_roll_example_of_section_3_2():
    # Roll of the X table, 0.001 degree, tool point 500 mm above the roll axis.
    roll = np.deg2rad(0.001)
    m = Machine("t", "XYFZ", tool=(0, 0, 0), components={"EAX": const(roll)})
    dev = m.deviation([100.0, 0.0, 500.0])
    assert abs(dev[1]) * 1e3 == pytest.approx(8.73, abs=0.005)
    assert dev[0] == pytest.approx(0.0, abs=1e-12)


def test_pure_translations_add_up_everywhere():
    m = Machine("t", "XZFY", components={"EXX": const(0.003), "EYX": const(-0.001), "EZY": const(0.002)})
    P = np.random.default_rng(1).uniform(-500, 500, (50, 3))
    assert np.allclose(m.deviation(P), [0.003, -0.001, 0.002], atol=1e-15)


def test_abbe_offset_is_tool_plus_outboard_axes_minus_reference():
    m = Machine("t", "XZFY", tool=(1, 2, -200), references={"X": (0, 10, 20)})
    P = np.array([[300.0, 40.0, 70.0]])
    # X carries Z and Y between it and the tool: both count; X itself does not.
    assert np.allclose(m.abbe_offset("X", P), [[1, 2 + 40 - 10, -200 + 70 - 20]])
    assert np.allclose(m.abbe_offset("Z", P), [[1, 42, -200]])  # only Y outboard of Z
    assert np.allclose(m.abbe_offset("Y", P), [[1, 2, -200]])


def test_chain_order_changes_abbe_terms():
    # The same pitch of Z (EAZ, about X) seen with Y outboard of Z (XZFY) or not (XYFZ).
    eaz = 20e-6
    P = np.array([[100.0, 300.0, 200.0]])
    hr5b = Machine("a", "XZFY", components={"EAZ": const(eaz)})
    tl = Machine("b", "XYFZ", components={"EAZ": const(eaz)})
    # XZFY: lever y·e_y, rotation about X moves z by +eaz·y
    assert hr5b.deviation(P)[0, 2] == pytest.approx(eaz * 300.0, rel=1e-9)
    assert tl.deviation(P)[0, 2] == pytest.approx(0.0, abs=1e-12)
    assert not np.allclose(hr5b.deviation(P), tl.deviation(P))


def test_frame_position_alone_does_not_change_relative_error():
    comps = {"EAX": const(7e-6), "ECY": const(-5e-6), "EBZ": const(9e-6)}
    P = np.random.default_rng(2).uniform(0, 600, (20, 3))
    a = Machine("a", "XYFZ", tool=(0, 0, -150), components=comps).deviation(P)
    b = Machine("b", "XFYZ", tool=(0, 0, -150), components=comps).deviation(P)
    assert np.allclose(a, b, atol=1e-15)


def test_member_rotation_sees_the_frame():
    eps = 10e-6
    P = np.array([[0.0, 0.0, 0.0]])
    work_side = Machine("a", "XYFZ", components={"EBX": const(eps)})
    tool_side = Machine("b", "YFXZ", components={"EBX": const(eps)})
    # Relative rotation is the same; the table turns −ε, a tool-side carriage +ε.
    assert np.allclose(work_side.rotation(P), tool_side.rotation(P))
    assert work_side.member_rotation("work", P)[0, 1] == pytest.approx(-eps)
    assert tool_side.member_rotation("X", P)[0, 1] == pytest.approx(eps)
    assert tool_side.member_rotation("work", P)[0, 1] == pytest.approx(0.0)


def _scaled(m: Machine, k: float) -> Machine:
    return m.replace(
        components={n: c.scaled(k) for n, c in m.components.items()},
        squareness={n: v * k for n, v in m.squareness.items()},
    )


@pytest.mark.parametrize("name", ["hr5b", "tl_tuotanto", "valmet"])
def test_exact_agrees_with_linear_to_second_order(name):
    m = load_machine(f"{SAMPLES}/{name}.toml")
    lo = np.array([m.limits[a][0] for a in "XYZ"])
    hi = np.array([m.limits[a][1] for a in "XYZ"])
    P = lo + np.random.default_rng(3).random((2000, 3)) * (hi - lo)
    gap1 = np.abs(m.deviation(P) - m.deviation_linear(P)).max()
    m10 = _scaled(m, 10.0)
    gap10 = np.abs(m10.deviation(P) - m10.deviation_linear(P)).max()
    first_order = np.abs(m.deviation_linear(P)).max()
    assert gap1 < 1e-4 * first_order  # second-order: tiny
    assert 80 < gap10 / gap1 < 120  # and it scales with the square of the errors


def test_xy_squareness_on_a_ball_bar_circle():
    s = 30e-6  # δx = s·y, i.e. C0Y = −s
    R = 150.0
    m = Machine("t", "XYFZ", squareness={"C0Y": -s})
    theta = np.linspace(0, 2 * np.pi, 361)
    centre = np.array([400.0, 200.0, 100.0])
    u = np.column_stack([np.cos(theta), np.sin(theta), np.zeros_like(theta)])
    P = centre + R * u
    # bar length change: radial projection of the tool-minus-centre deviation
    dR = np.einsum("ij,ij->i", m.deviation(P) - m.deviation(centre), u)
    # first-order formula; the exact chain differs by ~R·s²  (1e-7 µm here)
    assert np.allclose(dR, s * R / 2 * np.sin(2 * theta), rtol=0, atol=1e-7)


def test_squareness_directions():
    m = Machine("t", "XYFZ", squareness={"C0Y": 1e-5, "B0Z": 2e-5, "A0Z": 3e-5})
    d = m.deviation_linear([0.0, 100.0, 0.0])
    assert np.allclose(d, [-1e-3, 0, 0])
    d = m.deviation_linear([0.0, 0.0, 100.0])
    assert np.allclose(d, [2e-3, -3e-3, 0])


def test_direction_dependent_tables():
    t = Table([0, 100], [0.0, 0.001], values_minus=[0.004, 0.005])
    m = Machine("t", "XYFZ", components={"EXX": t})
    P = np.array([[50.0, 0, 0]] * 3)
    d = m.deviation(P, direction=[[1, 0, 0], [-1, 0, 0], [0, 0, 0]])[:, 0]
    assert np.allclose(d, [0.0005, 0.0045, 0.0025])


def test_polynomial_and_single_point_shapes():
    m = Machine("t", "XYFZ", components={"EYX": Polynomial([0.0, 1e-5, 1e-8], reference=100.0)})
    assert m.deviation([300.0, 0, 0])[1] == pytest.approx(1e-5 * 200 + 1e-8 * 200**2)
    assert m.deviation(np.zeros((0, 3))).shape == (0, 3)


def test_bad_inputs():
    with pytest.raises(ValueError, match="chain"):
        Machine("t", "XYZ")
    with pytest.raises(ValueError, match="unknown error component"):
        Machine("t", "XYFZ", components={"EQX": const(0.0)})
    with pytest.raises(ValueError, match=r"shape \(n, 3\)"):
        Machine("t", "XYFZ").deviation(np.zeros((4, 2)))


def test_with_components_and_immutability():
    m = Machine("t", "XYFZ")
    m2 = m.with_components(xx=const(0.001), kxy=1e-5)  # thesis names accepted
    assert m.components == {} and m2.components["EXX"] == const(0.001)
    assert m2.squareness["C0Y"] == 1e-5
    assert m2.with_components(EXX=None).components == {}
    with pytest.raises(AttributeError):  # (dataclasses.FrozenInstanceError)
        m.name = "other"  # type: ignore[misc]


def test_limits():
    m = load_machine(f"{SAMPLES}/hr5b.toml")
    assert m.axes == ("X", "Z", "Y") and m.chain == "XZFY"
    assert m.limits["X"] == (0.0, 800.0)
    assert list(m.within_limits([[10, 10, 10], [900, 10, 10]])) == [True, False]


def test_timing_million_points():
    m = load_machine(f"{SAMPLES}/hr5b.toml")
    P = np.random.default_rng(4).uniform(0, 700, (10**6, 3))
    start = time.perf_counter()
    E = m.deviation(P)
    elapsed = time.perf_counter() - start
    print(f"\n10^6 points, exact chain, 18 smooth tables + squareness: {elapsed:.3f} s")
    assert E.shape == (10**6, 3)
