"""`in_plane` / `from_plane`: points in each row's plane coordinates and back, whether a
batch holds one plane (slices) or several (gathered per row)."""

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from ncpp.motion.segments import PLANE_AXES
from ncpp.passes.geometry import from_plane, in_plane


@settings(max_examples=50, deadline=None)
@given(
    planes=st.lists(st.sampled_from(sorted(PLANE_AXES)), min_size=1, max_size=12),
    samples=st.integers(1, 4),
    seed=st.integers(0, 2**16),
)
def test_each_row_in_its_plane_and_back(planes, samples, seed):
    axes = np.array([PLANE_AXES[p] for p in planes])
    q = np.random.default_rng(seed).normal(size=(len(planes), samples, 3))
    u, v, w = in_plane(q, axes)
    for k, (a, b, c) in enumerate(axes.tolist()):  # the u, v and normal axes of row k
        assert (
            np.array_equal(u[k], q[k, :, a])
            and np.array_equal(v[k], q[k, :, b])
            and np.array_equal(w[k], q[k, :, c])
        )
    assert np.array_equal(from_plane(u, v, w, axes), q)
    # rows of points (p,3) too
    u1, v1, w1 = in_plane(q[:, 0], axes)
    assert np.array_equal(from_plane(u1, v1, w1, axes), q[:, 0])
