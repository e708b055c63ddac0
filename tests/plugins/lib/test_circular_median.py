"""The running circular median of facing estimates (plugins.lib.root_frame) unwraps only near the middle (issue 22):
the same numbers as unwrapping every element."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.root_frame import HeadingFilter, _unwrapped, _unwrapped_median, smooth_heading


def angles(rng, kind, shape):
    if kind == "walk":  # a body turning, across ±π
        return np.angle(np.exp(1j * np.cumsum(rng.normal(0, 0.1, shape), axis=-1)))
    if kind == "flips":  # estimates flipped by half a turn now and then
        return np.where(rng.random(shape) < 0.2, np.pi * np.sign(rng.normal(size=shape)), rng.normal(0, 0.3, shape))
    if kind == "ties":
        return np.round(rng.normal(0, 1, shape), 1)
    if kind == "wrap":  # all about ±π
        return np.angle(np.exp(1j * (np.pi + rng.normal(0, 0.01, shape))))
    if kind == "turns":  # many turns: not wrapped at all
        return rng.normal(0, 100, shape)
    return rng.uniform(-np.pi, np.pi, shape)


KINDS = ["walk", "flips", "ties", "wrap", "turns", "uniform"]


@given(seed=st.integers(0, 100_000), n=st.integers(1, 60), w=st.integers(1, 40), kind=st.sampled_from(KINDS))
@settings(max_examples=300, deadline=None)
def test_the_median_unwrapped_near_the_middle_is_the_median_of_everything_unwrapped(seed, n, w, kind):
    rng = np.random.default_rng(seed)
    rows = angles(rng, kind, (n, w))
    ref = np.angle(np.exp(1j * rows).sum(axis=1))[:, None]
    expected = np.median(_unwrapped(rows, ref), axis=1)
    assert np.array_equal(_unwrapped_median(rows, ref), expected)


def everything_unwrapped(windows):
    """The circular median of each row (n, w), written out: every element unwrapped around the row's circular mean,
    the median of the finite ones (NaN: none), wrapped to (-π, π]."""
    ok = np.isfinite(windows)
    a = np.where(ok, windows, 0.0)
    ref = np.angle(np.where(ok, np.exp(1j * a), 0.0).sum(axis=1))[:, None]
    unwrapped = np.where(ok, ref + np.angle(np.exp(1j * (a - ref))), np.nan)
    full, some = ok.all(axis=1), ok.any(axis=1)
    out = np.full(len(windows), np.nan)
    out[full] = np.median(unwrapped[full], axis=1)
    out[some & ~full] = np.nanmedian(unwrapped[some & ~full], axis=1)
    return np.angle(np.exp(1j * out))


@given(seed=st.integers(0, 100_000), n=st.integers(1, 200), w=st.integers(1, 60), kind=st.sampled_from(KINDS),
       hidden=st.floats(0.0, 0.5))
@settings(max_examples=150, deadline=None)
def test_a_block_and_a_recording_filter_as_every_window_unwrapped_whole(seed, n, w, kind, hidden):
    """update_many and smooth_heading (each estimate's rotation computed once, only the middle unwrapped exactly)
    give, bit for bit, the circular median of each frame's window with every element unwrapped."""
    rng = np.random.default_rng(seed)
    h = angles(rng, kind, n)
    h[rng.random(n) < hidden] = np.nan
    finite = h[np.isfinite(h)]
    padded = np.concatenate([np.full(w - 1, np.nan), finite])
    ends = np.cumsum(np.isfinite(h))  # estimates seen up to each frame
    expected = np.full(n, np.nan)
    if len(finite):
        windows = np.lib.stride_tricks.sliding_window_view(padded, w)[np.maximum(ends - 1, 0)]
        expected = np.where(ends > 0, everything_unwrapped(windows), np.nan)
    assert np.array_equal(HeadingFilter(w).update_many(h), expected, equal_nan=True)
    if w > 1 and np.isfinite(h).any():
        half = w // 2
        centred = np.lib.stride_tricks.sliding_window_view(np.pad(h, half, constant_values=np.nan), 2 * half + 1)
        assert np.array_equal(smooth_heading(h, w), everything_unwrapped(centred), equal_nan=True)
