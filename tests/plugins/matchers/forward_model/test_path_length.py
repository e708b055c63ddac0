"""The path length observed (:mod:`plugins.matchers.forward_model.path_length`), kept frame by frame: held to the
direct formula to the last bit, so an answer (a drop-out at a threshold, a commitment) can never differ."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.matchers.forward_model.path_length import Walk, lengths

coordinates = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)


@given(st.integers(1, 6), st.lists(st.integers(1, 5), min_size=1, max_size=60), st.data())
@settings(max_examples=150, deadline=None)
def test_the_running_path_length_is_the_whole_segments_to_the_last_bit(k, steps, data):
    """:class:`Walk`, fed a working memory that grows by a few rows at a time, gives exactly :func:`lengths` of
    the whole of it after every step (the filter's running sum and numpy's summation order reproduced)."""
    n = sum(steps)
    observed = data.draw(arrays(np.float64, (n, k, 3), elements=coordinates))
    walk, seen = Walk(k), 0
    for step in steps:
        seen += step
        np.testing.assert_array_equal(walk.lengths(observed[:seen]), lengths(observed[:seen]))


def test_a_running_path_length_refuses_a_memory_that_shrank():
    walk = Walk(1)
    walk.lengths(np.zeros((5, 1, 3)))
    with pytest.raises(ValueError, match="shrank"):
        walk.lengths(np.zeros((4, 1, 3)))
