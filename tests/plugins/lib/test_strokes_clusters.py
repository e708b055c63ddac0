"""The stroke analysis's vectorised steps (issue 22, "fast at every size") give exactly what their formulas written
out step by step give (hypothesis): the direction clustering, the speed minima and the stroke analysis that uses them.

:func:`plugins.lib.strokes.analyse` cuts every movement the ``velocity-direction`` segmenter closes and everything the
motor command graph learns. A different last bit in a cluster mean could move a cluster boundary, so each vectorised
function is held bit for bit to the straightforward version it replaced, kept here as the reference.
"""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

import plugins.lib.strokes as strokes
from plugins.lib.strokes import (StrokeAnalysis, StrokeCriteria, _centres, _cluster_means, _dots, _relabel, _renormed,
                                 _round_kernels, _smoothed, _unit, analyse, breaks, direction_breaks,
                                 direction_clusters, held, speed_breaks)

values = st.floats(-10.0, 10.0, allow_nan=False, allow_infinity=False)


def reference_direction_clusters(vectors: np.ndarray, angle: float, max_clusters: int = 12) -> np.ndarray:
    """The divisive clustering as it was written before it was vectorised: means a list, one mask per cluster."""
    n = len(vectors)
    if n == 0:
        return np.zeros(0, dtype=int)
    cos_limit = np.cos(np.radians(angle))
    means = [_unit(vectors.mean(axis=0))]
    for _ in range(4 * max_clusters):
        sims = vectors @ np.array(means).T
        labels = np.argmax(sims, axis=1)
        best = sims[np.arange(n), labels]
        worst = int(np.argmin(best))
        if best[worst] >= cos_limit or len(means) >= max_clusters:
            break
        means.append(vectors[worst].copy())
        for _ in range(10):
            labels = np.argmax(vectors @ np.array(means).T, axis=1)
            new = [_unit(vectors[labels == k].mean(axis=0)) if np.any(labels == k) else means[k]
                   for k in range(len(means))]
            if np.allclose(np.array(new), np.array(means)):
                break
            means = new
    return np.argmax(vectors @ np.array(means).T, axis=1)


@st.composite
def unit_vectors(draw, most=120):
    """Unit movement vectors (N, 3k) as the analysis gives them: a few directions with noise, some zero rows."""
    n = draw(st.integers(1, most))
    d = 3 * draw(st.integers(1, 8))
    k = draw(st.integers(1, 6))
    centres = draw(arrays(np.float64, (k, d), elements=values))
    which = np.array(draw(st.lists(st.integers(0, k - 1), min_size=n, max_size=n)))
    noise = draw(arrays(np.float64, (n, d), elements=st.floats(-1.0, 1.0)))
    scale = draw(st.sampled_from([0.0, 0.05, 0.3, 1.0, 5.0]))
    vectors = centres[which] + scale * noise
    zero = draw(st.lists(st.integers(0, n - 1), max_size=3))
    vectors[zero] = 0.0
    norms = np.sqrt(np.array([v.dot(v) for v in vectors]))
    long = norms > 1e-12
    return np.where(long[:, None], vectors / np.where(long, norms, 1.0)[:, None], vectors)


@given(unit_vectors(), st.floats(1.0, 180.0), st.integers(1, 12))
@settings(max_examples=300, deadline=None)
def test_direction_clusters_are_the_reference_clustering(vectors, angle, max_clusters):
    """Compiled rounds (with numba) and numpy's steps (without) both give the reference's labels."""
    expected = reference_direction_clusters(vectors, angle, max_clusters)
    np.testing.assert_array_equal(direction_clusters(vectors, angle, max_clusters), expected)
    np.testing.assert_array_equal(_numpy_direction_clusters(vectors, angle, max_clusters), expected)


def _numpy_direction_clusters(vectors, angle, max_clusters=12):
    """:func:`direction_clusters` as it runs without numba (numpy's steps)."""
    kernels = strokes._round_kernels
    strokes._round_kernels = lambda: None
    try:
        return direction_clusters(vectors, angle, max_clusters)
    finally:
        strokes._round_kernels = kernels


def _kernel_pairs():
    """The round's steps as written (plain Python) and, with numba, compiled."""
    pairs = [(_relabel, _renormed)]
    if _round_kernels() is not None:
        pairs.append(_round_kernels())
    return pairs


@given(arrays(np.float64, st.tuples(st.integers(1, 40), st.integers(2, 24)), elements=values), st.integers(1, 12),
       st.data())
@settings(max_examples=300, deadline=None)
def test_a_compiled_round_is_numpys_round(vectors, k, data):
    """:func:`_relabel` and :func:`_renormed` (as written and compiled) give the labels of ``argmax`` (ties to the
    first, NaN first), say when they are unchanged, and give :func:`_centres` and :func:`_allclose` bit for bit,
    zero signs, empty clusters and unnormalisable means included. Vectors of two or more dimensions, as the stroke
    analysis's are: see :func:`test_centres_are_each_clusters_mean`."""
    vectors = np.where(np.array(data.draw(arrays(bool, vectors.shape))), -0.0, vectors)
    if data.draw(st.booleans()):
        vectors[: data.draw(st.integers(0, len(vectors)))] = 0.0  # means too short to normalise
    means = data.draw(arrays(np.float64, (k, vectors.shape[1]), elements=values))
    sims = np.round(vectors @ means.T, data.draw(st.sampled_from([0, 1, 8])))  # ties too
    if data.draw(st.booleans()):
        sims[data.draw(st.integers(0, len(sims) - 1)), data.draw(st.integers(0, k - 1))] = np.nan
    expected_labels = sims.argmax(axis=1)
    for relabel, renormed in _kernel_pairs():
        labels, centre, counts = np.zeros(len(vectors), dtype=np.intp), np.empty((k, vectors.shape[1])), np.empty(
            k, dtype=np.intp)
        assert not relabel(sims, labels, True, vectors, centre, counts)
        np.testing.assert_array_equal(labels, expected_labels)
        np.testing.assert_array_equal(counts, np.bincount(expected_labels, minlength=k))
        new = np.empty_like(means)
        close = renormed(centre, np.sqrt(_dots(centre, centre)), counts, means, new)
        expected = _centres(vectors, expected_labels, means)
        np.testing.assert_array_equal(new, expected)
        np.testing.assert_array_equal(np.signbit(new), np.signbit(expected))
        assert close == strokes._allclose(expected, means)
        before = centre.copy()
        assert relabel(sims, labels, False, vectors, centre, counts)  # the same labels again: nothing else done
        np.testing.assert_array_equal(centre, before)
        if k > 1 and len(sims) and not np.isnan(sims[0]).any():
            changed = sims.copy()
            changed[0] = 0.0
            changed[0, (expected_labels[0] + 1) % k] = 1.0
            assert not relabel(changed, labels, False, vectors, centre, counts)
            assert labels[0] == (expected_labels[0] + 1) % k


@given(arrays(np.float64, st.tuples(st.integers(1, 40), st.integers(2, 24)), elements=values), st.integers(1, 12),
       st.data())
@settings(max_examples=300, deadline=None)
def test_centres_are_each_clusters_mean(vectors, k, data):
    """:func:`_centres` (one array) gives what :func:`_cluster_means` (a list) and the masked mean give, zero
    signs included, with empty clusters keeping their old mean.

    Vectors of two or more dimensions, as the stroke analysis's are (3 per part): numpy sums the rows of a single
    column pairwise, from 8 rows on (one ulp away from the sum in order, which hypothesis found), and the rows of
    wider arrays in their order, as :func:`_centres` does."""
    labels = np.array(data.draw(st.lists(st.integers(0, k - 1), min_size=len(vectors), max_size=len(vectors))))
    vectors = np.where(np.array(data.draw(arrays(bool, vectors.shape))), -0.0, vectors)  # signed zeros too
    means = data.draw(arrays(np.float64, (k, vectors.shape[1]), elements=values))
    expected = np.array([_unit(vectors[labels == c].mean(axis=0)) if np.any(labels == c) else means[c]
                         for c in range(k)])
    got = _centres(vectors, labels, means)
    np.testing.assert_array_equal(got, expected)
    np.testing.assert_array_equal(np.signbit(got), np.signbit(expected))
    np.testing.assert_array_equal(got, np.array(_cluster_means(vectors, labels, list(means))))


def test_a_long_cluster_is_summed_in_order():
    """More rows than numpy's pairwise summation block (8), in one cluster and several: still the masked mean."""
    rng = np.random.default_rng(22)
    vectors = rng.normal(size=(300, 69)) * 10.0 ** rng.uniform(-3, 3, size=(300, 1))
    labels = rng.integers(0, 3, size=300)
    means = np.zeros((4, 69))
    expected = [_unit(vectors[labels == c].mean(axis=0)) for c in range(3)] + [means[3]]
    np.testing.assert_array_equal(_centres(vectors, labels, means), np.array(expected))


def reference_speed_breaks(speed: np.ndarray, drop: float, moving: float = 0.0) -> list[int]:
    """:func:`speed_breaks` as it was written before it was vectorised: a hold at a time."""
    from scipy.signal import argrelextrema

    speed = np.asarray(speed, dtype=float)
    n = len(speed)
    if n < 3:
        return []
    low = argrelextrema(speed, np.less_equal, order=2)[0]
    low = low[(low >= 2) & (low <= n - 3)]
    if not len(low):
        return []
    holds = [[int(low[0])]]
    for m in low[1:]:
        previous = holds[-1][-1]
        if m == previous + 1 or speed[previous : m + 1].max() <= moving:
            holds[-1].append(int(m))
        else:
            holds.append([int(m)])
    minima = [(h[0] + h[-1]) // 2 for h in holds]
    bounds = [0, *(h[-1] for h in holds[:-1])], [*(h[0] for h in holds[1:]), n - 1]
    out = []
    for i, (m, hold) in enumerate(zip(minima, holds)):
        left, right = speed[bounds[0][i] : hold[0] + 1].max(), speed[hold[-1] : bounds[1][i] + 1].max()
        side = min(left, right)
        if speed[hold].min() < drop * side and side > moving:
            out.append(m)
    return out


def reference_analyse(window: np.ndarray, fps: float, c: StrokeCriteria) -> StrokeAnalysis:
    """:func:`analyse` as it was written before it was vectorised: a cluster change, a slow vector at a time."""
    from scipy.signal import savgol_filter

    window = held(window)
    n = len(window)
    empty = np.zeros(max(0, n - 1))
    if n < 4:
        return StrokeAnalysis(np.asarray(window, dtype=float), empty, np.full(len(empty), -1), [], [], [])
    smooth = int(round(c.smooth * fps)) | 1
    if smooth >= 5 and n > smooth:
        window = savgol_filter(window, smooth, 2, axis=0, mode="interp")
    vectors = np.diff(window, axis=0)
    speed = np.linalg.norm(vectors.reshape(len(vectors), -1, 3), axis=2).max(axis=1) * fps
    moving = speed > c.rest_speed
    by_speed = sorted(b + 1 for b in reference_speed_breaks(speed, c.drop, c.rest_speed))
    cuts = set(by_speed)
    by_direction: list[int] = []
    units = np.array([_unit(v) for v in vectors])
    labels = np.full(len(units), -1)
    if moving.any():
        labels[moving] = reference_direction_clusters(units[moving], c.angle)
        for i in range(1, len(labels)):
            if labels[i] < 0:
                labels[i] = labels[i - 1]
        k = max(2, int(round(0.1 * fps)))
        dips = np.array(reference_speed_breaks(speed, c.corner, c.rest_speed), dtype=int) + 1
        for b in direction_breaks(labels):
            before, after = _unit(vectors[max(0, b - k) : b].sum(axis=0)), _unit(vectors[b : b + k].sum(axis=0))
            sharp = np.degrees(np.arccos(np.clip(before @ after, -1.0, 1.0))) >= 0.5 * c.angle
            near = dips[np.abs(dips - b) <= k]
            if sharp and near.size:
                by_direction.append(int(near[np.argmin(np.abs(near - b))]))
    cuts.update(by_direction)
    shortest = max(1, int(round(c.min_stroke * fps)))
    kept: list[int] = []
    for cut in sorted(cuts):
        if cut - (kept[-1] if kept else 0) >= shortest and n - cut >= shortest:
            kept.append(cut)
    return StrokeAnalysis(window, speed, labels, by_speed, sorted(set(by_direction)), kept)


@st.composite
def speeds(draw):
    """Speed profiles with holds, plateaus, pauses below the rest speed and repeated values."""
    levels = st.sampled_from([0.0, 0.01, 0.05, 0.08, 0.1, 0.3, 0.5, 1.0, 1.5])
    return np.array(draw(st.lists(st.one_of(levels, st.floats(0.0, 2.0)), max_size=60)))


@given(speeds(), st.floats(0.0, 1.0), st.sampled_from([0.0, 0.05, 0.08, 0.3]))
@settings(max_examples=400, deadline=None)
def test_speed_breaks_are_the_reference_minima(speed, drop, moving):
    assert speed_breaks(speed, drop, moving) == reference_speed_breaks(speed, drop, moving)


@st.composite
def movements(draw):
    """A movement's working memory (N, 3k): strokes in a few directions at changing speeds, pauses, turns, a part
    hidden now and then (NaN)."""
    parts = draw(st.integers(1, 4))
    n = draw(st.integers(0, 90))
    turns = draw(st.lists(st.integers(1, max(1, n)), max_size=6))
    directions = draw(arrays(np.float64, (len(turns) + 1, 3 * parts), elements=st.floats(-1.0, 1.0)))
    which = np.searchsorted(np.sort(turns), np.arange(n), side="right")
    pace = draw(arrays(np.float64, n, elements=st.sampled_from([0.0, 0.001, 0.002, 0.01, 0.02, 0.05])))
    noise = draw(arrays(np.float64, (n, 3 * parts), elements=st.floats(-0.003, 0.003)))
    steps = directions[which] * pace[:, None] + noise if n else np.zeros((0, 3 * parts))
    window = np.cumsum(steps, axis=0)
    hidden = draw(st.lists(st.tuples(st.integers(0, max(0, n - 1)), st.integers(0, parts - 1)), max_size=4))
    for row, part in hidden:
        if n:
            window[row, 3 * part : 3 * part + 3] = np.nan
    return window


@given(movements(), st.sampled_from([30.0, 60.0, 120.0]),
       st.builds(StrokeCriteria, rest_speed=st.sampled_from([0.05, 0.08, 0.3]), drop=st.floats(0.1, 0.9),
                 angle=st.floats(10.0, 120.0), corner=st.floats(0.3, 1.0),
                 min_stroke=st.sampled_from([0.0, 0.05, 0.15]),
                 smooth=st.sampled_from([0.0, 0.1, 0.2])))
@settings(max_examples=300, deadline=None)
def test_analysis_is_the_reference_analysis(window, fps, criteria):
    """The whole stroke analysis, vectorised, gives the same window, speed, clusters and breaks as the reference."""
    got, expected = analyse(window, fps, criteria), reference_analyse(window, fps, criteria)
    np.testing.assert_array_equal(got.window, expected.window)
    np.testing.assert_array_equal(got.speed, expected.speed)
    np.testing.assert_array_equal(got.clusters, expected.clusters)
    assert (got.speed_breaks, got.direction_breaks, got.breaks) == (
        expected.speed_breaks, expected.direction_breaks, expected.breaks)


@given(movements(), st.sampled_from([30.0, 60.0, 120.0]),
       st.builds(StrokeCriteria, rest_speed=st.sampled_from([0.05, 0.08, 0.3]), drop=st.floats(0.1, 0.9),
                 angle=st.floats(10.0, 120.0), corner=st.floats(0.0, 1.0),
                 min_stroke=st.sampled_from([0.0, 0.05, 0.15, 0.5]),
                 smooth=st.sampled_from([0.0, 0.1, 0.2])))
@settings(max_examples=300, deadline=None)
def test_breaks_alone_are_the_analysis_breaks(window, fps, criteria):
    """:func:`breaks` leaves out what cannot change them (a movement too short for two strokes, the clustering where
    no speed dip could accompany a direction break): the same breaks as the whole analysis."""
    assert breaks(window, fps, criteria) == reference_analyse(window, fps, criteria).breaks


@given(st.sampled_from([5, 7, 9, 13, 25]), st.integers(1, 60), st.integers(1, 8), st.integers(0, 2**32 - 1),
       st.sampled_from([1e-3, 1.0, 100.0]))
@settings(max_examples=200, deadline=None)
def test_smoothing_is_savgol_filter(length, extra, parts, seed, size):
    """The working memory's smoothing (the filter's coefficients and the ends' least-squares fits prepared once per
    window length) is scipy's savgol_filter in interp mode: bit for bit with the scipy it was written against (1.17),
    and to rounding with any other (it repeats savgol_filter's steps, which a later scipy may order differently)."""
    import scipy
    from scipy.signal import savgol_filter

    rng = np.random.default_rng(seed)
    window = np.cumsum(rng.normal(size=(length + extra, 3 * parts)), axis=0) * size
    ours, theirs = _smoothed(window, length), savgol_filter(window, length, 2, axis=0, mode="interp")
    np.testing.assert_allclose(ours, theirs, rtol=1e-9, atol=1e-12 * np.abs(theirs).max())
    if scipy.__version__.startswith("1.17."):
        np.testing.assert_array_equal(ours, theirs)


@given(arrays(np.float64, st.tuples(st.integers(1, 60), st.integers(1, 80)),
              elements=st.floats(-1e6, 1e6, allow_nan=False, allow_infinity=False)), st.integers(0, 2**32 - 1))
@settings(max_examples=300, deadline=None)
def test_row_dot_products_at_once_are_each_rows_dot(a, seed):
    """:func:`_dots` (one stacked matmul) gives each row's own ``dot``, bit for bit (the norms and turn angles of
    the analysis rest on it)."""
    b = np.random.default_rng(seed).normal(size=a.shape) * 10.0 ** np.random.default_rng(seed).uniform(-3, 3)
    np.testing.assert_array_equal(_dots(a, b), np.array([u.dot(v) for u, v in zip(a, b)]))
    np.testing.assert_array_equal(_dots(a, a), np.array([u.dot(u) for u in a]))
