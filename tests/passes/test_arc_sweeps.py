"""replace_arcs' sweeps of a batch of arcs, computed together (`_ArcGeometry`), are
`Arc.sweep`'s: whole turns, full circles, both ways, every plane.  To 1e-12 rad, not bit for
bit: numpy's arctan2 may be another implementation than math.atan2 (SIMD builds)."""

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from ncpp.motion.segments import PLANE_AXES, Arc, Context
from ncpp.passes.geometry import plane_axes, points
from ncpp.passes.replace_arcs import _ArcGeometry, _ArcRows
from ncpp.program.blocks import Block

_BLOCK = Block("G2", "\n", (), 1)
_angle = st.floats(-math.pi, math.pi)


def _arc(plane: int, centre: tuple, radius: float, a0: float, a1: float, turn: int) -> Arc:
    u, v, w = PLANE_AXES[plane]
    start, end, c = [0.0] * 3, [0.0] * 3, [0.0] * 3
    c[u], c[v] = centre
    for p, a in ((start, a0), (end, a1)):
        p[u], p[v], p[w] = centre[0] + radius * math.cos(a), centre[1] + radius * math.sin(a), 1.0
    c[w] = 1.0
    return Arc(tuple(start), tuple(end), tuple(c), turn, 100.0, _BLOCK, Context(plane=plane))


def _geometry(arcs: list[Arc]) -> _ArcGeometry:
    n = len(arcs)
    rows = _ArcRows(points([a.start for a in arcs]), points([a.end for a in arcs]), points([a.center for a in arcs]), plane_axes(arcs),
                    np.array([a.turn for a in arcs], dtype=float), np.zeros((n, 3)), np.ones(n), None, np.ones(n, dtype=np.int64), np.zeros(n))  # fmt: skip
    return _ArcGeometry(rows)


@settings(max_examples=60, deadline=None)
@given(
    arcs=st.lists(
        st.tuples(
            st.sampled_from(sorted(PLANE_AXES)),
            st.floats(-500, 500),
            st.floats(-500, 500),
            st.floats(0.01, 300),
            _angle,
            _angle,
            st.sampled_from([-3, -2, -1, 1, 2, 3]),
            st.booleans(),
        ),  # fmt: skip
        min_size=1,
        max_size=20,
    )
)
def test_batch_sweeps_are_arc_sweeps(arcs):
    made = [
        _arc(plane, (cu, cv), r, a0, a0 if closed else a1, turn)
        for plane, cu, cv, r, a0, a1, turn, closed in arcs
    ]
    np.testing.assert_allclose(_geometry(made).sweep, [a.sweep() for a in made], rtol=0, atol=1e-12)


def test_a_full_circle_sweeps_a_whole_turn_each_way():
    ccw, cw = (_arc(17, (10.0, 20.0), 5.0, 0.3, 0.3, turn) for turn in (1, -2))
    assert _geometry([ccw, cw]).sweep.tolist() == [2 * math.pi, -4 * math.pi] == [ccw.sweep(), cw.sweep()]
