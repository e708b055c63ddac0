"""The styled comparison estimated online (:mod:`plugins.lib.online_style`): posture, amplitude and pace fitted to the
frames seen so far from running sums.

Hand-worked cases and hypothesis properties: an observation that is a prediction moved by a constant offset, made
larger or smaller within the limit, or played at another of the paces tried, is fitted exactly (no residual) with
the matching setting and not without; the running sums give what the whole frames give; nothing has a unit.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.online_style import Fit, Observed, STEP, fitted, paces, residuals


def curve(t: np.ndarray) -> np.ndarray:
    """Two parts moving along curves (len(t), 2, 3): a command's prediction at command times ``t``."""
    a = np.stack([np.sin(t), np.cos(2 * t) - 1, 0.3 * t], axis=-1)
    b = np.stack([0.5 * t ** 2, np.zeros_like(t), np.sin(3 * t)], axis=-1)
    return np.stack([a, b], axis=1)


def run(o: np.ndarray, p: np.ndarray, centred: bool, limit: float) -> list[tuple[np.ndarray, int, float]]:
    """Frame by frame: the running sums of ``o`` (n, k, 3) and ``p`` (S, n, k, 3), and each frame's residuals."""
    obs, fit, out = Observed.empty(o.shape[1]), Fit.empty(len(p), o.shape[1]), []
    for i in range(len(o)):
        obs.add(o[i:i + 1])
        fit.add(o[i:i + 1], p[:, i:i + 1])
        out.append(residuals(obs, fit, o[i], p[:, i], centred, limit))
    return out


def test_paces_are_twelve_percent_apart_within_the_limit_with_one_among_them():
    s = paces(2.0)
    assert len(s) == 15 and s[0] == pytest.approx(0.5) and s[-1] == pytest.approx(2.0)
    assert s[7] == pytest.approx(1.0)
    assert np.all(s[1:] / s[:-1] <= STEP + 1e-9)
    np.testing.assert_array_equal(paces(0.0), [1.0])
    np.testing.assert_array_equal(paces(1.0), [1.0])


def test_the_running_sums_are_the_sums_over_the_frames():
    rng = np.random.default_rng(0)
    o, p = rng.normal(size=(7, 2, 3)), rng.normal(size=(3, 7, 2, 3))
    obs, fit = Observed.empty(2), Fit.empty(3, 2)
    obs.add(o[:4]), fit.add(o[:4], p[:, :4])
    obs.add(o[4:]), fit.add(o[4:], p[:, 4:])
    assert obs.n == 7 and obs.soo == pytest.approx((o * o).sum())
    np.testing.assert_allclose(fit.sp, p.sum(axis=1))
    np.testing.assert_allclose(fit.sop, [(o * q).sum() for q in p])
    np.testing.assert_allclose(fit.spp, [(q * q).sum() for q in p])


def test_the_amplitude_is_the_least_squares_factor_kept_within_the_limit():
    p = curve(np.linspace(0, 1, 20))[None]
    for factor, limit, expected in ((1.5, 2.0, 1.5), (3.0, 2.0, 2.0), (0.25, 2.0, 0.5), (1.5, 0.0, 1.0)):
        obs, fit = Observed.empty(2), Fit.empty(1, 2)
        obs.add(factor * p[0]), fit.add(factor * p[0], p)
        a, rss, _ = fitted(obs, fit, False, limit)
        assert a[0] == pytest.approx(expected)
        assert (rss[0] == pytest.approx(0.0, abs=1e-12)) == (expected == factor)


@settings(max_examples=60, deadline=None)
@given(offset=st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3), factor=st.floats(0.5, 2.0),
       pace=st.sampled_from(list(paces(2.0))))
def test_an_offset_larger_or_faster_observation_is_fitted_exactly_with_the_styled_comparison(offset, factor, pace):
    """The observation: the prediction played at ``pace``, ``factor`` times as large about its mean, and moved by
    ``offset``. With posture removed, amplitude 2 and the paces of tempo 2 the best fit explains every frame; the
    plain comparison (one pace, kept, as performed) does not, unless nothing was changed."""
    t = np.arange(25) / 30.0
    p = np.stack([curve(s * t) for s in paces(2.0)])  # (S, n, k, 3)
    shown = curve(pace * t)
    o = (shown - shown.mean(axis=0)) * factor + shown.mean(axis=0) + np.asarray(offset)
    styled = run(o, p, True, 2.0)
    for d, best, a in styled[2:]:
        assert d.max() == pytest.approx(0.0, abs=1e-6)
    assert styled[-1][2] == pytest.approx(factor, rel=1e-6)
    assert paces(2.0)[styled[-1][1]] == pytest.approx(pace)
    plain = run(o, curve(t)[None], False, 0.0)
    changed = max(abs(v) for v in offset) > 1e-3 or abs(factor - 1) > 1e-3 or abs(pace - 1) > 1e-3
    if changed:
        assert plain[-1][0].max() > 1e-4


@settings(max_examples=60, deadline=None)
@given(scale=st.floats(1e-2, 1e2), shift=st.floats(-10.0, 10.0))
def test_the_styled_residual_scales_with_the_body_and_ignores_where_it_stands(scale, shift):
    """No length enters: the observation and the prediction scaled together give residuals scaled alike, the same
    pace and amplitude; the observation moved (posture removed) gives the same residuals."""
    rng = np.random.default_rng(1)
    t = np.arange(15) / 30.0
    p = np.stack([curve(s * t) for s in paces(2.0)])
    o = curve(1.2 * t) * 1.3 + rng.normal(scale=0.05, size=(15, 2, 3))
    base = run(o, p, True, 2.0)
    scaled = run(o * scale, p * scale, True, 2.0)
    moved = run(o + shift, p, True, 2.0)
    for (d, b, a), (ds, bs, as_), (dm, bm, am) in zip(base[1:], scaled[1:], moved[1:]):
        assert b == bs == bm and a == pytest.approx(as_) and a == pytest.approx(am)
        np.testing.assert_allclose(ds, d * scale, rtol=1e-6, atol=1e-9 * scale)
        np.testing.assert_allclose(dm, d, rtol=1e-6, atol=1e-9)
