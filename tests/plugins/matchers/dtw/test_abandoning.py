"""dtw's early abandoning (issue 22) gives the answers of the plain computation."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

@settings(max_examples=200, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 30), st.integers(1, 30), st.floats(0.05, 3.0),
       st.sampled_from([None, 0.0, 0.3]))
def test_an_abandoned_dtw_is_surely_farther_and_one_not_abandoned_is_the_same_number(seed, n, m, share, window):
    from plugins.matchers.dtw import _band, _dtw

    rng = np.random.default_rng(seed)
    a, b = rng.normal(size=(n, 6)), rng.normal(size=(m, 6))
    band = None if window is None else _band(window, n, m)
    exact = _dtw(a, b, band)
    bound = exact * share
    got = _dtw(a, b, band, bound)
    assert got == exact or (got == np.inf and exact > bound * (1.0 - 1e-12))  # abandoned: farther up to rounding
    assert _dtw(a, b, band, exact * (1.0 + 1e-9)) == exact


def _dtw_matcher(labels, templates, **params):
    from plugins.matchers.dtw import DTW

    from plugins.matchers.decision import Distance

    matcher = DTW(**params)
    matcher.decision = Distance(0.0)  # always the nearest, as attach gives it by default
    matcher.labels, matcher.templates = list(labels), [np.ascontiguousarray(t) for t in templates]
    seen: set[str] = set()
    matcher._firsts, matcher._extras = [], []
    for i, label in enumerate(matcher.labels):
        (matcher._extras if label in seen else matcher._firsts).append(i)
        seen.add(label)
    return matcher


@settings(max_examples=150, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 12), st.integers(1, 4), st.booleans())
def test_dtw_answers_as_if_every_example_were_warped_in_full(seed, templates, movements, near):
    """Early abandoning changes no answer: the movement, confidence, distances and ranked candidates are those of
    the full distances to every example (the computation before it)."""
    from plugins.matchers.dtw import frame_distance
    from toolkit import Motion

    rng = np.random.default_rng(seed)
    parts = ("root", "a", "b")
    labels = [f"m{i}" for i in rng.integers(0, movements, templates)]
    series = [rng.normal(size=(int(rng.integers(2, 15)), 9)) for _ in labels]
    if near:  # examples close to each other and to the segment: little to abandon, ties possible
        series = [s * 0.01 + 1.0 for s in series]
    matcher = _dtw_matcher(labels, series, stride=1)
    positions = (series[0][: max(1, len(series[0]) - 1)] + rng.normal(size=1) * 0.1).reshape(-1, 3, 3)
    motion = Motion(positions, 30.0, parts)
    got = matcher.match(motion)
    flat = np.ascontiguousarray(np.nan_to_num(positions).reshape(-1, 9), dtype=np.double)
    distances = np.array([frame_distance(flat, t) for t in matcher.templates])
    best = int(np.argmin(distances))
    others = [d for d, lab in zip(distances, labels) if lab != labels[best]]
    runner_up = min(others) if others else np.inf
    nearest: dict[str, float] = {}
    for d, lab in sorted(zip(distances.tolist(), labels)):
        nearest.setdefault(lab, float(d))
    assert got.movement == labels[best]
    assert got.details == {"distance": float(distances[best]), "runner_up": float(runner_up)}
    assert got.candidates == tuple(nearest.items())
    confidence = float(1.0 - distances[best] / runner_up) if np.isfinite(runner_up) and runner_up > 0 else 1.0
    assert got.confidence == max(0.0, confidence)


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(2, 8), st.integers(1, 3), st.sampled_from([0.0, 0.5]))
def test_the_calibration_warped_one_by_one_scores_every_example_against_every_other(seed, templates, movements,
                                                                                    window):
    """Warped one by one (a ``window``, or no compiled kernel), the calibration is that of the full distances: a
    template scored against the others meets itself at distance 0, and a bound of 0 abandons none of its movement's
    other examples (every example has its own score)."""
    from unittest import mock

    from plugins.matchers import dtw
    from plugins.matchers.decision import Calibration

    rng = np.random.default_rng(seed)
    labels = [f"m{i}" for i in rng.integers(0, movements, templates)]
    series = [rng.normal(size=(int(rng.integers(2, 12)), 9)) for _ in labels]
    matcher = _dtw_matcher(labels, series, stride=1, window=window)
    rows = np.full((templates, templates), np.inf)
    for i, a in enumerate(matcher.templates):
        band = [None if not window else dtw._band(window, len(a), len(b)) for b in matcher.templates]
        full = [dtw._dtw(a, b, band[j]) for j, b in enumerate(matcher.templates)]
        lengths = len(a) + np.array([len(b) for b in matcher.templates])
        rows[i] = np.sqrt(np.square(full) / lengths) / dtw._still(a)
    with mock.patch.object(dtw, "_kernel", lambda: None):
        got = matcher._calibration()
    want = Calibration.of_rows(rows, labels)
    assert np.allclose(got.own, want.own) and np.allclose(got.other, want.other)
    assert len(got.own) == sum(labels.count(label) > 1 for label in labels)
