"""eq. 1-3 of Buchsbaum & Blumberg 2005 (plugins/lib/pose_distance.py), each against numbers worked out by hand.

eq. 2 is the Euclidean distance of one part; eq. 1 the *mean* of eq. 2 over the parts visible now; eq. 3 the *sum* of
eq. 1 along a path. Each test fails if its formula changes (another norm, a sum for the mean, hidden parts counted).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.lib.pose_distance import path_distance, pose_distance

A = np.zeros((3, 3))
B = np.array([[3.0, 4.0, 0.0],    # eq. 2: 5 (Euclidean: not 7, not 25)
              [0.0, 0.0, 2.0],    # 2
              [0.0, 6.0, 8.0]])   # 10


def test_eq_2_is_the_euclidean_distance_of_each_part_and_eq_1_their_mean():
    assert pose_distance(A, B) == pytest.approx((5 + 2 + 10) / 3)


def test_eq_1_averages_over_the_visible_parts_only():
    assert pose_distance(A, B, np.array([True, True, False])) == pytest.approx((5 + 2) / 2)  # not / 3
    assert pose_distance(A, B, np.array([False, False, True])) == pytest.approx(10.0)
    hidden = B.copy()
    hidden[2] = np.nan  # a hidden part's coordinates are never read
    assert pose_distance(A, hidden, np.array([True, True, False])) == pytest.approx(3.5)


def test_eq_1_without_evidence_is_nan_not_zero():
    assert np.isnan(pose_distance(A, B, np.zeros(3, dtype=bool)))


def test_eq_1_broadcasts_over_candidate_poses():
    candidates = np.stack([A, B, 2 * B])  # (3, P, 3) against one pose
    np.testing.assert_allclose(pose_distance(candidates, A, np.ones(3, dtype=bool)), [0.0, 17 / 3, 34 / 3])


def test_eq_3_sums_eq_1_over_the_frames_that_have_evidence():
    observed = np.stack([A, A, A])
    path = np.stack([B, 2 * B, B])
    visible = np.array([[True, True, True], [True, False, False], [False, False, False]])  # nothing seen last
    assert path_distance(observed, path, visible) == pytest.approx(17 / 3 + 10.0)  # frame 3 adds nothing


finite = st.floats(-2.0, 2.0, allow_nan=False, width=64)


@settings(max_examples=60, deadline=None)
@given(arrays(np.float64, (4, 3), elements=finite), arrays(np.float64, (4, 3), elements=finite),
       arrays(np.bool_, 4))
def test_eq_1_is_a_symmetric_mean_of_per_part_distances(a, b, visible):
    d = pose_distance(a, b, visible)
    if not visible.any():
        assert np.isnan(d)
        return
    per_part = np.linalg.norm(a - b, axis=1)[visible]
    assert d == pytest.approx(per_part.mean())
    assert d == pytest.approx(pose_distance(b, a, visible))
    assert pose_distance(a, a, visible) == 0.0
