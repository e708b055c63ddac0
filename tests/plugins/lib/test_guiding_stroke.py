"""Guiding strokes (Kopp & Graeser 2006, §3) and the inverse model (§4.3): stroke -> trajectory -> stroke."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st

from plugins.lib.guiding_stroke import SHAPES, GuidingStroke, progress, velocity_profile
from plugins.lib.inverse_model import stroke_from_segment, trajectory_error

vec = st.tuples(st.floats(-0.4, 0.4), st.floats(0.6, 1.4), st.floats(0.0, 0.5)).map(np.array)


@st.composite
def strokes(draw):
    start = draw(vec)
    target = draw(vec)
    if np.linalg.norm(target - start) < 0.1:
        target = start + np.array([0.15, 0.05, 0.05])
    shape = draw(st.sampled_from(SHAPES))
    return GuidingStroke(
        start=start, target=target, duration=draw(st.floats(0.3, 1.5)), peak=draw(st.floats(0.3, 0.7)),
        end_gain=draw(st.floats(0.0, 0.3)), shape=shape,
        normal=draw(st.sampled_from([np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0]), np.array([1.0, 0.0, 0.0]),
                                      np.array([0.3, 0.4, 0.85])])),
        curvature=0.0 if shape == "linear" else draw(st.floats(0.2, 0.9)),
        roundness=draw(st.floats(0.1, 0.9)), skewness=draw(st.floats(-0.6, 0.6)),
    )


@settings(max_examples=60, deadline=None)
@given(stroke=strokes())
def test_stroke_to_trajectory_to_inverse_model_round_trip(stroke):
    fps = 60.0
    observed = stroke.trajectory(fps)
    recovered = stroke_from_segment(observed, fps)
    tolerance = 0.03 * stroke.amplitude + 0.002
    assert trajectory_error(recovered, observed, fps) <= tolerance
    assert np.allclose(recovered.start, stroke.start) and np.allclose(recovered.target, stroke.target)
    assert recovered.duration == pytest.approx(stroke.duration, abs=1 / fps)


def error_within_half_a_frame(stroke: GuidingStroke, positions: np.ndarray, fps: float) -> float:
    """Largest distance between ``positions`` sampled at ``fps`` and the stroke's trajectory at the same moment give
    or take half a frame: :func:`trajectory_error` with each sample's time known only to the nearest frame."""
    t = np.arange(len(positions)) / fps
    shifts = np.linspace(-0.5, 0.5, 11) / fps
    return float(np.min([np.linalg.norm(stroke.position(np.clip(t + h, 0.0, None)) - positions, axis=1)
                         for h in shifts], axis=0).max())


@settings(max_examples=30, deadline=None)
@given(stroke=strokes(), seed=st.integers(0, 1000))
@example(stroke=GuidingStroke(np.array([0.0, 1.0, 0.25]), np.array([0.15, 1.05, 0.3]), 1.375, 0.5, 0.0, "left-c",
                              np.array([0.0, 0.0, 1.0]), 0.25, 0.5, 0.0), seed=0)  # noise once made this C an S
@example(stroke=GuidingStroke(np.array([0.0, 1.0, 0.0]), np.array([0.15, 1.05, 0.05]), 1.46875, 0.51953125, 0.0,
                              "right-s", np.array([0.0, 0.0, 1.0]), 0.75, 0.25, -0.5), seed=226)  # see below
@example(stroke=GuidingStroke(np.array([0.0, 1.0, 0.0]), np.array([0.15, 1.05, 0.05]), 1.5, 0.6875, 0.25, "left-s",
                              np.array([0.0, 0.0, 1.0]), 0.75, 0.5, 0.0), seed=323)  # noise faster than the stroke
def test_inverse_model_under_observation_noise(stroke, seed):
    """Noisy observations of a stroke give back its trajectory, each sample's moment taken to the nearest frame.

    An S whose skewness is below 0 crosses its chord with no bound on its sideways speed (the bump grows as
    ``x ** 2 ** skewness`` from the crossing, an exponent below 1), so one frame can jump further than the tolerance:
    the example above (hypothesis, seed 110) moves 21 mm between frames 45 and 46, and its recovered stroke, fitted to
    noisy samples, crosses a fraction of a frame later, 17.5 mm from the clean sample at frame 46 (the tolerance is
    16.3 mm) though within 5 mm of it half a frame away. A sampled observation does not fix when it crossed closer
    than that, so the error is measured allowing half a frame (a few millimetres where the stroke moves at usual
    speeds, the jump itself at the crossing).

    The last example (hypothesis, seed 323 of ps18b's run) is a slow stroke (0.17 m in 1.5 s) whose 2 mm of noise at
    60 fps moves as fast from frame to frame as the stroke: the speed profile's peak was read in the first tenth and
    the fit, started there, ended 51 mm off. The inverse model then also starts from a symmetric bell.
    """
    fps = 60.0
    clean = stroke.trajectory(fps)
    noisy = clean + np.random.default_rng(seed).normal(0, 0.002, clean.shape)
    recovered = stroke_from_segment(noisy, fps)
    assert error_within_half_a_frame(recovered, clean, fps) <= 0.05 * stroke.amplitude + 0.008


def test_bell_shaped_velocity_peaks_where_asked():
    u = np.linspace(0, 1, 1001)
    for peak in (0.3, 0.5, 0.7):
        v = velocity_profile(u, peak, 0.0)
        assert u[np.argmax(v)] == pytest.approx(peak, abs=0.002)
        assert v[0] == pytest.approx(0.0) and v[-1] == pytest.approx(0.0)
    s = progress(u, 0.5, 0.4)
    assert s[0] == 0.0 and s[-1] == pytest.approx(1.0) and np.all(np.diff(s) >= 0)
    assert velocity_profile(np.array([1.0]), 0.5, 0.4)[0] == pytest.approx(0.4)  # end gain keeps some speed


def test_shapes_bend_the_right_way():
    start, target = np.zeros(3), np.array([0.3, 0.0, 0.0])
    normal = np.array([0.0, 0.0, 1.0])  # plane x-y; normal x chord = +y: "left" bends towards +y
    mid = lambda shape: GuidingStroke(start, target, 1.0, shape=shape, normal=normal, curvature=1.0).position(0.5)  # noqa: E731
    assert mid("left-c")[1] == pytest.approx(0.15, abs=0.01)  # a semicircle: half the chord sideways
    assert mid("right-c")[1] == pytest.approx(-0.15, abs=0.01)
    s_curve = GuidingStroke(start, target, 1.0, shape="left-s", normal=normal, curvature=1.0).trajectory(100)
    assert s_curve[:, 1].max() > 0.05 and s_curve[:, 1].min() < -0.05
    assert np.allclose(GuidingStroke(start, target, 1.0).position(np.array([0.0, 1.0, 2.0])), [start, target, target])


def test_retimed_stroke_keeps_its_path():
    stroke = GuidingStroke(np.zeros(3), np.array([0.2, 0.1, 0.0]), 0.8, shape="right-c", curvature=0.5)
    slow = stroke.retimed(1.6)
    assert np.allclose(slow.position(1.6 * np.linspace(0, 1, 9)), stroke.position(0.8 * np.linspace(0, 1, 9)))


def test_invalid_strokes_are_refused():
    with pytest.raises(ValueError, match="unknown stroke shape"):
        GuidingStroke(np.zeros(3), np.ones(3), 1.0, shape="zigzag")
    with pytest.raises(ValueError, match="positive duration"):
        GuidingStroke(np.zeros(3), np.ones(3), 0.0)
    with pytest.raises(ValueError, match="two or more finite positions"):
        stroke_from_segment(np.zeros((1, 3)), 30)
