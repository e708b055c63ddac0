"""A tracker's jitter measured on the recording itself (plugins.lib.jitter): white noise of a known size found
again, a person's movement not taken for noise, a bridged gap not counted, and the noise carried through the
derivative and the low-pass as a simulation of many noisy recordings finds it."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.jitter import feature_noise, jitter_variance
from plugins.lib.lowpass import low_passed
from plugins.lib.velocity import derivative
from toolkit import Motion


def _gesture(n: int, fps: float) -> np.ndarray:
    """Three parts (n, 3, 3): one still, one waving at 2 Hz by 10 cm, one swinging at half a hertz by 50 cm."""
    t = np.arange(n) / fps
    x = np.zeros((n, 3, 3))
    x[:, 1, 0] = 0.1 * np.sin(2 * np.pi * 2.0 * t)
    x[:, 2, 1] = 0.5 * np.sin(2 * np.pi * 0.5 * t)
    return x


@settings(max_examples=25, deadline=None)
@given(sigma=st.floats(0.002, 0.03), fps=st.sampled_from([25.0, 30.0, 60.0, 120.0]), seed=st.integers(0, 10**6))
def test_white_noise_of_a_known_size_is_found_again_on_a_moving_body(sigma, fps, seed):
    # a minute: the median's own spread is then a few percent (over 10 s at 25 frames/s, one estimate in a few
    # hundred lay 18% low, and the test failed on a clean clone)
    n = int(60 * fps)
    noisy = _gesture(n, fps) + np.random.default_rng(seed).normal(0.0, sigma, (n, 3, 3))
    found = np.sqrt(jitter_variance(noisy, np.ones((n, 3), dtype=bool), fps))
    assert found == pytest.approx(np.full(3, sigma), rel=0.15)


def test_a_movement_without_noise_is_not_taken_for_noise():
    found = np.sqrt(jitter_variance(_gesture(300, 30.0), np.ones((300, 3), dtype=bool), 30.0))
    assert found.max() < 0.001  # a 2 Hz wave of 10 cm leaves under a millimetre


def test_hidden_frames_and_the_bridges_over_them_are_not_counted():
    """A part hidden for 0.3 s every second, its positions there set far off: the straight bridges the fit sees
    are not noise, and the frames beside them do not count."""
    fps, n = 30.0, 300
    x = _gesture(n, fps) + np.random.default_rng(1).normal(0.0, 0.005, (n, 3, 3))
    seen = np.ones((n, 3), dtype=bool)
    seen[(np.arange(n) % 30) < 9, 1] = False
    x[~seen] = 5.0
    found = np.sqrt(jitter_variance(x, seen, fps))
    assert found == pytest.approx(np.full(3, 0.005), rel=0.2)


def test_too_short_or_never_seen_is_no_noise():
    assert not jitter_variance(np.zeros((6, 2, 3)), np.ones((6, 2), dtype=bool), 30.0).any()
    x = np.random.default_rng(0).normal(0.0, 0.01, (100, 2, 3))
    seen = np.ones((100, 2), dtype=bool)
    seen[:, 1] = False
    found = jitter_variance(x, seen, 30.0)
    assert found[1] == 0.0 and found[0] > 0.0


@pytest.mark.parametrize("fps", [30.0, 60.0])
@pytest.mark.parametrize("low", [False, True])
def test_the_noise_carried_through_the_derivative_and_the_low_pass_is_what_a_simulation_finds(fps, low):
    """Many recordings of pure noise, 1 cm per axis, through what a recording goes through before it is compared:
    the mean squared position and velocity away from the ends is what feature_noise says."""
    n, runs, sigma = 400, 300, 0.01
    noise = np.random.default_rng(2).normal(0.0, sigma, (n, runs, 3))
    if low:
        noise = low_passed(Motion(noise, fps, tuple(f"p{k}" for k in range(runs)))).positions
    velocity = derivative(noise, fps)
    middle = slice(n // 4, 3 * n // 4)
    simulated = [np.einsum("nrk,nrk->nr", v[middle], v[middle]).mean() for v in (noise, velocity)]
    (expected,) = feature_noise(np.array([sigma**2]), fps, n, low_passed=low)
    assert expected == pytest.approx(simulated, rel=0.05)
    if not low:
        assert expected[0] == pytest.approx(3 * sigma**2)
