"""The styled comparison estimated online (:mod:`plugins.lib.online_style`): held posture and pace fitted to the
frames seen so far from running sums.

Hand-worked cases and hypothesis properties: an observation that is a prediction moved by a constant offset, or
played at another of the paces tried, is fitted exactly (no residual) with the styled comparison and not without;
the running sums give what the whole frames give; nothing has a unit.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.online_style import STEP, Fit, Observed, paces, residuals


def curve(t: np.ndarray) -> np.ndarray:
    """Two parts moving along curves (len(t), 2, 3): a command's prediction at command times ``t``."""
    a = np.stack([np.sin(t), np.cos(2 * t) - 1, 0.3 * t], axis=-1)
    b = np.stack([0.5 * t ** 2, np.zeros_like(t), np.sin(3 * t)], axis=-1)
    return np.stack([a, b], axis=1)


def run(o: np.ndarray, p: np.ndarray, centred: bool) -> list[tuple[np.ndarray, int]]:
    """Frame by frame: the running sums of ``o`` (n, k, 3) and ``p`` (S, n, k, 3), and each frame's residuals."""
    obs, fit, out = Observed.empty(o.shape[1]), Fit.empty(len(p), o.shape[1]), []
    for i in range(len(o)):
        obs.add(o[i:i + 1])
        fit.add(o[i:i + 1], p[:, i:i + 1])
        out.append(residuals(obs, fit, o[i], p[:, i], centred))
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


@settings(max_examples=60, deadline=None)
@given(offset=st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3), pace=st.sampled_from(list(paces(2.0))))
def test_an_offset_or_faster_observation_is_fitted_exactly_with_the_styled_comparison(offset, pace):
    """The observation: the prediction played at ``pace`` and moved by ``offset``. With the posture removed and the
    paces of tempo 2 the best fit explains every frame, at that pace; the plain comparison (one pace, kept) does not,
    unless nothing was changed."""
    t = np.arange(25) / 30.0
    p = np.stack([curve(s * t) for s in paces(2.0)])  # (S, n, k, 3)
    o = curve(pace * t) + np.asarray(offset)
    styled = run(o, p, True)
    for d, best in styled[2:]:
        assert d.max() == pytest.approx(0.0, abs=1e-6)
    assert paces(2.0)[styled[-1][1]] == pytest.approx(pace)
    plain = run(o, curve(t)[None], False)
    if max(abs(v) for v in offset) > 1e-3 or abs(pace - 1) > 1e-3:
        assert plain[-1][0].max() > 1e-4
    else:
        assert plain[-1][0].max() == pytest.approx(0.0, abs=1e-9)


@settings(max_examples=60, deadline=None)
@given(scale=st.floats(1e-2, 1e2), shift=st.floats(-10.0, 10.0))
def test_the_styled_residual_scales_with_the_body_and_ignores_where_it_stands(scale, shift):
    """No length enters: the observation and the prediction scaled together give residuals scaled alike and the same
    pace; the observation moved (posture removed) gives the same residuals."""
    rng = np.random.default_rng(1)
    t = np.arange(15) / 30.0
    p = np.stack([curve(s * t) for s in paces(2.0)])
    o = curve(1.2 * t) + rng.normal(scale=0.05, size=(15, 2, 3))
    base = run(o, p, True)
    scaled = run(o * scale, p * scale, True)
    moved = run(o + shift, p, True)
    for (d, b), (ds, bs), (dm, bm) in zip(base[1:], scaled[1:], moved[1:]):
        assert b == bs == bm
        np.testing.assert_allclose(ds, d * scale, rtol=1e-6, atol=1e-9 * scale)
        np.testing.assert_allclose(dm, d, rtol=1e-6, atol=1e-6)
