"""The per-segment shortcuts of path search and dtw (issue 22) give the answers of the plain computation."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.matchers.path_search import PathSearch


def _search(per_movement: bool, labels: np.ndarray) -> PathSearch:
    """A path search whose movement tables are those of nodes labelled ``labels`` (no graph needed for the starts)."""
    ps = PathSearch(per_movement=per_movement)
    ps.labels = labels.astype(object)
    _, ps.label_ids = np.unique(labels.astype(str), return_inverse=True)
    ps._by_label = np.argsort(ps.label_ids, kind="stable")
    ps._label_starts = np.flatnonzero(np.diff(ps.label_ids[ps._by_label], prepend=-1))
    return ps


@settings(max_examples=300, deadline=None)
@given(st.integers(1, 60), st.integers(1, 12), st.integers(1, 5), st.booleans(), st.integers(0, 2**32 - 1))
def test_the_start_nodes_are_the_stable_sorts(n, k, movements, per_movement, seed):
    rng = np.random.default_rng(seed)
    labels = np.array(["", *(f"m{i}" for i in range(movements))])[rng.integers(0, movements + 1, n)]
    first = rng.choice([0.0, 0.5, 1.0, np.inf, np.nan], n) if seed % 3 == 0 else rng.integers(0, 4, n) / 4.0
    if seed % 5 == 0:
        first = np.where(rng.random(n) < 0.3, np.inf, first)  # excluded nodes
    ps = _search(per_movement, labels)
    expected = ps._best(np.argsort(first, kind="stable"), np.arange(n), k)
    assert np.array_equal(ps._starts(first, k), expected)
