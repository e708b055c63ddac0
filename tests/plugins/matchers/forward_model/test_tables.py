"""The commands' strokes on a fine grid (:mod:`plugins.matchers.forward_model.tables`): the points along the table
of every stroke, and their counts by one binary search, are those of the plain computation (:func:`_along_rows`,
``np.interp`` row by row), to the bit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.matchers.forward_model.tables import EdgeTable, StrokeRows, row_keys
from tests.plugins.matchers.forward_model.helpers import KERNELS, kernels


def _along_rows(arcs: np.ndarray, positions: np.ndarray, x: np.ndarray) -> np.ndarray:
    """The plain computation: per row r, the point of ``positions[r]`` (G, 3) at path length ``x[r]`` along
    ``arcs[r]`` (G,), linearly interpolated, the points at most ``x[r]`` counted by comparing every point."""
    count = (arcs <= x[:, None]).sum(axis=1)
    j = np.clip(count - 1, 0, arcs.shape[1] - 2)
    rows = np.arange(len(x))
    a0, a1 = arcs[rows, j], arcs[rows, j + 1]
    step = a1 - a0
    w = np.divide(x - a0, step, out=np.zeros_like(x), where=step > 0)
    return positions[rows, j] + np.clip(w, 0.0, 1.0)[:, None] * (positions[rows, j + 1] - positions[rows, j])


@given(seed=st.integers(0, 10_000), rows=st.integers(1, 30), points=st.integers(2, 40), ties=st.booleans(),
       nan=st.booleans())
@settings(max_examples=200, deadline=None)
def test_point_counts_by_binary_search_are_the_compared_ones(seed, rows, points, ties, nan):
    """:class:`StrokeRows` counting the points by one binary search over the keys of :func:`row_keys` (numpy's
    steps) gives the points of comparing every point: lengths at a stroke's start, its end, exactly on a point,
    between points, on steps of no length (ties), NaN."""
    rng = np.random.default_rng(seed)
    steps = rng.random((rows, points - 1))
    if ties:  # steps of no length, and lengths that repeat
        steps = np.round(steps, 1) * (rng.random(steps.shape) < 0.6)
    arcs = np.concatenate([np.zeros((rows, 1)), np.cumsum(steps, axis=1)], axis=1)
    positions = rng.normal(size=(rows, points, 3))
    x = rng.random(rows) * arcs[:, -1]
    pick = rng.integers(0, 4, rows)
    x = np.where(pick == 1, arcs[:, -1], np.where(pick == 2, arcs[np.arange(rows), rng.integers(0, points, rows)],
                                                   np.where(pick == 3, 0.0, x)))
    if nan:
        x[rng.integers(rows)] = np.nan
    assert row_keys(arcs) is not None
    table = StrokeRows(points)
    table.rows("e", EdgeTable([], positions, arcs, 0))
    assert table.sorted
    with kernels("numpy"):
        got = table.along(np.arange(rows), x)
    np.testing.assert_array_equal(got, _along_rows(arcs, positions, x))


def test_rows_that_do_not_grow_have_no_keys():
    assert row_keys(np.array([[0.0, 1.0, 0.5]])) is None
    assert row_keys(np.array([[0.0, np.nan, 1.0]])) is None
    assert row_keys(np.array([[0.0, 0.0, 1.0], [0.0, 2.0, 2.0]])) is not None


@given(seed=st.integers(0, 10_000), commands=st.lists(st.integers(1, 4), min_size=1, max_size=12),
       changed=st.booleans(), unsorted=st.booleans())
@settings(max_examples=100, deadline=None)
@pytest.mark.parametrize("mode", KERNELS)
def test_the_table_of_every_stroke_predicts_as_the_stacked_strokes(mode, seed, commands, changed, unsorted):
    """:class:`StrokeRows` (every command's strokes as rows of one growing table, a set of candidates as row
    numbers) gives the points :func:`_along_rows` gives of the same strokes stacked: commands added one by one (the
    table grows past its first size), a command whose table changed (new rows), a stroke whose lengths do not grow
    (then every point is compared); compiled, as the compiled loop's plain-Python reference, and by numpy's steps.
    Lengths at a stroke's end, past it, before its start, -0 and NaN included; the values to the bit."""
    rng = np.random.default_rng(seed)
    g = 12
    table = StrokeRows(g)

    def edge(k: int) -> EdgeTable:
        steps = np.round(rng.random((k, g - 1)), 1) * (rng.random((k, g - 1)) < 0.7)
        arcs = np.concatenate([np.zeros((k, 1)), np.cumsum(steps, axis=1)], axis=1)
        positions = rng.normal(size=(k, g, 3))
        positions[rng.random(k) < 0.3, 0] = -0.0  # strokes from -0: the sign of a zero weight shows
        return EdgeTable([], positions, arcs, 0)

    edges = {f"e{i}": edge(k) for i, k in enumerate(commands * 8)}
    if unsorted:
        edges["e0"].arcs[0, 3] = -1.0
    for name, e in edges.items():
        table.rows(name, e)
    if changed:
        edges["e0"] = edge(len(edges["e0"].arcs))
    names = list(rng.permutation(list(edges)))[: rng.integers(1, len(edges) + 1)]
    rows = np.concatenate([table.rows(n, edges[n]) + np.arange(len(edges[n].arcs)) for n in names])
    arcs = np.concatenate([edges[n].arcs for n in names])
    positions = np.concatenate([edges[n].positions for n in names])
    x = rng.random(len(rows)) * arcs[:, -1]
    x = np.where(rng.random(len(x)) < 0.2, arcs[:, -1], x)
    pick = rng.random(len(x))
    x = np.where(pick < 0.05, -0.0, np.where(pick < 0.1, np.nan, np.where(pick < 0.15, arcs[:, -1] + 1.0,
                                                                         np.where(pick < 0.2, -1.0, x))))
    assert table.sorted == (not unsorted)
    with kernels(mode):
        got = table.along(rows, x)
    want = _along_rows(arcs, positions, x)
    assert np.array_equal(np.isnan(got), np.isnan(want))
    assert np.array_equal(np.where(np.isnan(got), 0.0, got).view(np.uint64),
                          np.where(np.isnan(want), 0.0, want).view(np.uint64))
