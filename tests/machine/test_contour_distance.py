"""`ncpp simulate`'s contour error: a point's distance to the nominal path, a polyline of samples,
is to its nearest segment wherever the nearest samples lie (a densely sampled arc beside a line
sampled every half mm holds every sample near a point of the line): the largest one exactly."""

from __future__ import annotations

import numpy as np

from ncpp.simulate import distance_to_path


def test_a_point_on_a_sparse_line_is_on_the_path_beside_a_dense_cluster():
    cluster = np.column_stack([np.linspace(-1.0, 1.0, 501), np.full(501, 0.14), np.zeros(501)])
    line = np.column_stack([np.zeros(13), np.linspace(-3.0, 3.0, 13), np.zeros(13)])  # every 0.5 mm
    path = np.vstack([cluster, line])
    on_line = np.array([[0.0, 0.25, 0.0], [0.0, 1.75, 0.0]])  # between the line's samples
    beside = np.array([[0.003, 0.25, 0.0]])  # 3 µm off it
    got = distance_to_path(np.vstack([on_line, beside]), path)
    np.testing.assert_allclose(got, [0.0, 0.0, 0.003], atol=1e-12)
