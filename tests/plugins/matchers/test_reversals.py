"""A part's path cut into strokes where it turns back (plugins.matchers.reversals)."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.matchers.reversals import _zigzag, parts_strokes, reversal_strokes

FPS = 30.0


def _through(*points: tuple[float, float, float], frames: int = 20) -> np.ndarray:
    """A path through ``points``, ``frames`` frames a leg, straight between them."""
    legs = [np.linspace(a, b, frames, endpoint=False) for a, b in zip(points[:-1], points[1:])]
    return np.concatenate([*legs, np.asarray(points[-1:], dtype=float)])


def test_a_stroke_ends_where_the_path_turns_back():
    path = _through((0, 0, 0), (1, 0, 0), (0.5, 0, 0), (0.5, 1, 0), (0.5, 0.2, 0))
    strokes = reversal_strokes(path, FPS, reversal=0.2)
    np.testing.assert_allclose(strokes, [[1, 0, 0], [-0.5, 1, 0], [0, -0.8, 0]], atol=1e-12)


def test_an_excursion_smaller_than_the_reversal_is_no_stroke():
    path = _through((0, 0, 0), (1, 0, 0), (0.9, 0, 0), (1.5, 0, 0))
    np.testing.assert_allclose(reversal_strokes(path, FPS, reversal=0.2), [[1.5, 0, 0]], atol=1e-12)
    assert reversal_strokes(path, FPS, reversal=2.0).shape == (0, 3)


@settings(max_examples=60, deadline=None)
@given(arrays(np.float64, (40, 3), elements=st.floats(-0.04, 0.04)),
       arrays(np.float64, (3,), elements=st.floats(-5, 5)))
def test_jitter_smaller_than_the_reversal_never_makes_a_stroke(noise, place):
    """Points at most 0.04 from a place on each axis lie at most 0.14 apart: with a reversal of 0.2, never a stroke,
    wherever the part is held."""
    assert reversal_strokes(place + noise, FPS, reversal=0.2).shape == (0, 3)


@settings(max_examples=60, deadline=None)
@given(arrays(np.float64, (25, 3), elements=st.floats(-1, 1)), st.integers(2, 4), st.floats(0.1, 10.0))
def test_the_strokes_know_no_tempo_and_scale_with_the_path(path, slower, scale):
    """Each frame held ``slower`` times (a performance that many times slower) gives the same strokes; a path
    ``scale`` times as big, with a reversal as much bigger, gives strokes as much bigger."""
    strokes = reversal_strokes(path, FPS, reversal=0.3)
    np.testing.assert_array_equal(reversal_strokes(np.repeat(path, slower, axis=0), FPS, reversal=0.3), strokes)
    np.testing.assert_allclose(reversal_strokes(path * scale, FPS, reversal=0.3 * scale), strokes * scale,
                               rtol=1e-9, atol=1e-9)


def test_smoothing_keeps_the_strokes_of_a_clean_path_and_drops_those_of_noise():
    path = _through((0, 0, 0), (0.6, 0, 0), (0, 0, 0), (0.6, 0, 0), frames=15)
    noisy = path + np.random.default_rng(0).normal(scale=0.03, size=path.shape)
    assert len(reversal_strokes(noisy, FPS, reversal=0.05)) > 3
    smoothed = reversal_strokes(noisy, FPS, reversal=0.05, smooth=1 / 3)
    assert len(smoothed) == 3
    np.testing.assert_allclose(np.abs(smoothed[:, 0]), 0.6, atol=0.1)


def test_the_compiled_loop_gives_the_reference_loops_strokes():
    path = np.random.default_rng(2).normal(size=(200, 3)).cumsum(axis=0)
    out = np.empty((200, 3))
    count = _zigzag(path, 0.5, out)
    np.testing.assert_array_equal(reversal_strokes(path, FPS, reversal=0.5), out[:count])
    assert reversal_strokes(path[:1], FPS, reversal=0.5).shape == (0, 3)


@settings(max_examples=50, deadline=None)
@given(arrays(np.float64, st.tuples(st.integers(2, 40), st.integers(1, 4), st.just(3)), elements=st.floats(-1.0, 1.0)),
       st.sampled_from([0.0, 0.2, 0.5]))
def test_every_part_at_once_gives_each_parts_own_strokes(paths, smooth):
    """The parts smoothed together (one Savitzky-Golay pass over every part) and cut one by one: each part's
    strokes are those of its path alone."""
    together = parts_strokes(paths, 30.0, 0.1, smooth)
    assert len(together) == paths.shape[1]
    for p, strokes in enumerate(together):
        alone = reversal_strokes(paths[:, p], 30.0, 0.1, smooth)
        assert strokes.shape == alone.shape and np.allclose(strokes, alone, atol=1e-12)
