"""A command joined late (:mod:`plugins.matchers.forward_model.anchors`): every candidate's anchor, placed at once
and by groups of half strokes (compiled, as the compiled loop's plain-Python reference, or by numpy's steps), is the
plain computation's, to the bit: the first-half point of each stroke nearest to where the part was seen."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.matchers.forward_model import Track, anchors
from tests.plugins.matchers.forward_model.helpers import KERNELS, kernels, random_strokes


def _distances(x: np.ndarray, y: np.ndarray, z: np.ndarray, first: np.ndarray) -> np.ndarray:
    """The plain distances from ``first`` (k, 3) of points given as coordinate planes x, y, z (C, k, h): the squares
    summed x, y, z, then the root, as :meth:`anchors.Halves.place` computes them."""
    dx, dy, dz = x - first[:, 0, None], y - first[:, 1, None], z - first[:, 2, None]
    return np.sqrt(dx * dx + dy * dy + dz * dz)


def _direct_anchor(matcher, track: Track, name: str) -> np.ndarray:
    """Where each part joins command ``name``: the nearest point of the first half of its stroke to where it was
    seen at the onset (the formula, one command at a time, over the whole stroke)."""
    edge = matcher.tables.edge(name)
    far = np.linalg.norm(edge.positions - track.first[:, None], axis=-1)
    far[edge.arcs > 0.5 * edge.arcs[:, -1:]] = np.inf
    return edge.arcs[np.arange(len(far)), np.argmin(far, axis=1)]


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(first=arrays(np.float64, (2, 3), elements=st.floats(-1.0, 2.0)), seed=st.integers(0, 3))
def test_anchors_placed_at_once_are_placed_one_by_one(write, pm, first, seed):
    """The anchors of every candidate of a track, placed at once (:meth:`anchors.Anchors.anchor`: the strokes'
    first halves stacked), are each command's own nearest first-half point."""
    character, names = random_strokes(write, pm, strokes=6, seed=seed)
    matcher = character.matcher
    rest = character.motor.rest
    track = Track("wrists", 1.0, False, "hub", 0, {(name,): 0.0 for name in names}, sorted(names),
                  first=rest[2:4] + first * 0.2)
    for name in reversed(names):  # the first asked places them all
        np.testing.assert_array_equal(matcher.anchors.anchor(track, name), _direct_anchor(matcher, track, name))
    assert set(track.anchors) == set(names)


@given(seed=st.integers(0, 10_000), c=st.integers(1, 6), k=st.integers(1, 5), h=st.integers(1, 40),
       hidden=st.booleans())
@settings(max_examples=60, deadline=None)
def test_anchor_distances_from_coordinate_planes_are_the_stacked_norms_bit_for_bit(seed, c, k, h, hidden):
    """The anchors' distances from coordinate planes (:func:`_distances`, the reference of the next test) equal
    ``np.linalg.norm`` of the stacked positions exactly, a part never seen (NaN) included."""
    rng = np.random.default_rng(seed)
    positions = rng.normal(size=(c, k, h, 3)) * rng.uniform(0.01, 3.0)
    first = rng.normal(size=(k, 3))
    if hidden:
        first[rng.integers(k)] = np.nan
    want = np.linalg.norm(positions - first[:, None], axis=-1)
    got = _distances(*(np.ascontiguousarray(positions[..., i]) for i in range(3)), first)
    assert np.array_equal(got, want, equal_nan=True)


@given(seed=st.integers(0, 10_000), c=st.integers(1, 6), k=st.integers(1, 5), g=st.integers(2, 40),
       still=st.booleans(), hidden=st.booleans(), on_point=st.booleans(), groups=st.integers(1, 4),
       near=st.booleans(), scale=st.sampled_from([0, -3, -6, 120, -160]))
@settings(max_examples=150, deadline=None)
@pytest.mark.parametrize("mode", KERNELS)
def test_anchors_by_groups_of_half_strokes_are_the_masked_argmin_bit_for_bit(mode, seed, c, k, g, still, hidden,
                                                                             on_point, groups, near, scale):
    """:class:`anchors.Halves` (the moving strokes' first halves in groups, points past a half at x = +inf) places
    every part where the plain computation does: the masked argmin of :func:`_distances` over whole strokes. Strokes
    that do not move, repeated points (ties), a part seen exactly on a point or halfway between two (near ties), a
    part never seen (NaN), strokes a millimetre or a micrometre long, and coordinates whose squares overflow or
    underflow included; compiled, as the compiled loop's plain-Python reference, and by numpy's steps."""
    rng = np.random.default_rng(seed)
    positions = np.cumsum(rng.normal(size=(c, k, g, 3)) * (rng.random((c, k, g, 1)) < 0.8), axis=2)
    if still:
        positions[rng.integers(c), rng.integers(k)] = rng.normal(size=3)
    steps = np.linalg.norm(np.diff(positions, axis=2), axis=-1)
    arcs = np.concatenate([np.zeros((c, k, 1)), np.cumsum(steps, axis=2)], axis=2)
    first = rng.normal(size=(k, 3)) * 2
    positions *= 10.0**scale
    first *= 10.0**scale
    if on_point:
        first[0] = positions[0, 0, rng.integers(g)]
    if near:
        i = rng.integers(g - 1)
        first[-1] = 0.5 * (positions[-1, -1, i] + positions[-1, -1, i + 1])
    if hidden:
        first[rng.integers(k)] = np.nan
    later = arcs > 0.5 * arcs[..., -1:]
    far = np.where(later, np.inf, _distances(*(np.ascontiguousarray(positions[..., i]) for i in range(3)), first))
    want = np.take_along_axis(arcs, np.argmin(far, axis=-1)[..., None], axis=-1)[..., 0]
    original = anchors.Halves.GROUPS
    try:
        anchors.Halves.GROUPS = groups
        with kernels(mode):
            got = anchors.Halves(arcs, positions).place(first)
    finally:
        anchors.Halves.GROUPS = original
    assert np.array_equal(got, want)


@pytest.mark.parametrize("mode", KERNELS)
def test_points_whose_roots_tie_keep_the_earlier_one(mode):
    """Two points of a stroke whose summed squares differ by a rounding but whose roots are equal (one point's
    coordinates reversed: the sums round differently) are equally near: the earlier one is the anchor, as numpy's
    argmin of the roots says, although the later one's summed squares are smaller. Also an exact tie (two points
    at the same distance) keeps the earlier one."""
    p = np.array([0.5937480717858228, 0.8911669542823284, 0.3208483045665637])
    q = p[::-1].copy()
    squares = [(v[0] * v[0] + v[1] * v[1]) + v[2] * v[2] for v in (p, q)]
    assert squares[1] < squares[0] and np.sqrt(squares[1]) == np.sqrt(squares[0])
    exact = np.array([[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    positions = np.stack([np.stack([p, q, p + 10, p + 20, p + 30]),
                          np.stack([*exact, exact[1] + 2, exact[1] + 4, exact[1] + 6])])[None]  # (1, 2, 5, 3)
    arcs = np.concatenate([np.zeros((1, 2, 1)), np.cumsum(np.linalg.norm(np.diff(positions, axis=2), axis=-1),
                                                          axis=2)], axis=2)
    with kernels(mode):
        placed = anchors.Halves(arcs, positions).place(np.zeros((2, 3)))
    assert placed.tolist() == [[0.0, 0.0]]
