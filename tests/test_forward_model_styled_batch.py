"""The styled comparison's paces predicted for every candidate at once (issue 18, fmstyled2): the same values as path by
path.

:meth:`ForwardModel._at_times_all` stacks every command a subsystem's candidates run along (:class:`_TimedTables`) and
places each candidate's times on the edge of its path that has begun by then, as :meth:`ForwardModel._at_times` does
edge after edge; :meth:`ForwardModel._styled_predict_all` gives :meth:`ForwardModel._styled_predict` of every
candidate at once, and without ``tempo`` (one pace on the path-length clock) every candidate's prediction at once as
:meth:`ForwardModel._styled_predict` gives it path by path. On the hand-built ``arms`` graph of ``tests/test_forward_model.py`` with two more edges after
``out`` (paths of one to three edges of different durations), random times and random demonstrations: bit for bit the
same positions, places along the paths and ends, and a followed demonstration's fitted paces and errors frame by frame
the same as with the reference (the candidates predicted one by one).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.test_forward_model import arms, demonstration, stroke_path  # noqa: F401 (arms: the fixture)
from tests.test_forward_model_relative import use
from plugins.lib.guiding_stroke import GuidingStroke
from plugins.matchers.forward_model import ForwardModel, Track
from toolkit.watching import feed

SETTINGS = dict(deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])


@pytest.fixture
def chained(arms):
    """``out`` (1 s), then ``on`` (0.7 s, the left wrist 20 cm up from out's end) and ``back`` (1.6 s, back down);
    paths of one, two and three edges."""
    motor = arms.motor
    left, right = motor.rest[2], motor.rest[3]
    end = left + [0.3, 0.0, 0.0]
    node = motor.edge(arms.out).target
    on = motor.learn("wrists", node, [GuidingStroke(end, end + [0.0, 0.2, 0.0], 0.7), GuidingStroke(right, right, 0.5)])
    back = motor.learn("wrists", motor.edge(on).target, [GuidingStroke(end + [0.0, 0.2, 0.0], end, 1.6),
                                                         GuidingStroke(right, right + [0.0, 0.1, 0.0], 1.6)])
    arms.paths = [(arms.out,), (arms.up,), (arms.out, on), (arms.out, on, back)]
    return arms


@settings(max_examples=40, **SETTINGS)
@given(data=st.data())
def test_every_path_at_once_is_each_path_alone_bit_for_bit(chained, data):
    matcher = chained.matcher
    paths = data.draw(st.lists(st.sampled_from(chained.paths), min_size=1, max_size=6))
    n = data.draw(st.integers(1, 12))
    times = np.array(data.draw(st.lists(st.lists(st.floats(-0.5, 5.0), min_size=n, max_size=n),
                                        min_size=len(paths), max_size=len(paths))))
    points, along, past = matcher._at_times_all("wrists", paths, times)
    for c, path in enumerate(paths):
        p, a, e = matcher._at_times(path, times[c])
        np.testing.assert_array_equal(points[c], p)
        np.testing.assert_array_equal(along[c], a)
        np.testing.assert_array_equal(past[c], e)


def run(arms, path, batched: bool, monkeypatch, **params):
    """``path`` (the left wrist) followed with the styled comparison: each frame's errors, and the fitted paces."""
    if not batched:
        monkeypatch.setattr(ForwardModel, "_styled_predict_all", lambda *args: None)  # the reference: path by path
    arms.motor.reset()
    matcher = use(arms, **{"dropout": "relative", "error": "moving", "relative": True, "learn": False, "tempo": 2.0,
                           **params})
    demo = demonstration(arms, path)
    answers = [(a.movement, a.decided_at) for a in feed(matcher, demo) if a is not None]
    matcher.conclude(demo)
    paces = {p: fit.extra.get("pace") for track in matcher.tracks.values() for p, fit in track.styled.items()}
    monkeypatch.undo()
    return answers, matcher.inspect()["trace"], paces


@settings(max_examples=25, **SETTINGS)
@given(chord=st.lists(st.floats(-0.3, 0.3), min_size=3, max_size=3), seconds=st.floats(0.4, 2.5),
       noise=st.floats(0.0, 0.01), seed=st.integers(0, 2**16), posture=st.sampled_from(["kept", "removed"]))
def test_a_followed_demonstration_fits_the_same_paces_and_errors_batched_as_path_by_path(chained, monkeypatch, chord,
                                                                                      seconds, noise, seed, posture):
    path = stroke_path(chained.motor.rest[2], chord, seconds)
    path = path + np.random.default_rng(seed).normal(0.0, noise, path.shape)
    batched = run(chained, path, True, monkeypatch, posture=posture)
    alone = run(chained, path, False, monkeypatch, posture=posture)
    assert batched == alone


@settings(max_examples=40, **SETTINGS)
@given(data=st.data(), relative=st.booleans(), clock=st.sampled_from(["parts", "lead"]))
def test_every_path_on_the_path_length_clock_at_once_is_each_path_alone_bit_for_bit(chained, data, relative, clock):
    """Without ``tempo`` (one pace, the path-length clock): :meth:`ForwardModel._styled_predict_all` against
    :meth:`ForwardModel._styled_predict` path by path, on random observations of the wrists from a random onset and
    rows ``start .. n - 1`` of them: the same predictions, places along and ends, bit for bit."""
    matcher = use(chained, tempo=0.0, posture="removed", relative=relative, clock=clock)
    matcher.fps = 30.0
    paths = data.draw(st.lists(st.sampled_from(chained.paths), min_size=1, max_size=6, unique=True))
    n = data.draw(st.integers(1, 20))
    start = data.draw(st.integers(0, n - 1))
    rng = np.random.default_rng(data.draw(st.integers(0, 2**16)))
    rest = chained.motor.rest[2:4]
    steps = rng.normal(0.0, data.draw(st.sampled_from([0.0, 0.005, 0.03])), (n, 2, 3))
    observed = rest + np.cumsum(steps, axis=0) + rng.normal(0.0, 0.05, (1, 2, 3))
    track = Track("wrists", 1.0, False, "hub", 0, dict.fromkeys(paths, 0.0), [], first=observed[0])
    paces = np.array([1.0])
    points, along, past = matcher._styled_predict_all(track, paths, observed, start, n, paces)
    assert points.shape == (len(paths), 1, n - start, 2, 3)
    for c, path in enumerate(paths):
        p, a, e = matcher._styled_predict(track, path, observed, start, n, paces)
        np.testing.assert_array_equal(points[c], p)
        np.testing.assert_array_equal(along[c], a)
        np.testing.assert_array_equal(past[c], e)


@settings(max_examples=25, **SETTINGS)
@given(chord=st.lists(st.floats(-0.3, 0.3), min_size=3, max_size=3), seconds=st.floats(0.4, 2.5),
       noise=st.floats(0.0, 0.01), seed=st.integers(0, 2**16), relative=st.booleans())
def test_posture_removed_without_tempo_is_the_same_batched_as_path_by_path(chained, monkeypatch, chord, seconds,
                                                                            noise, seed, relative):
    """``posture = "removed"`` and ``tempo = 0``: a followed demonstration's answers, errors frame by frame and fits
    the same with every candidate at once (one pace) as with the reference (path by path)."""
    path = stroke_path(chained.motor.rest[2], chord, seconds)
    path = path + np.random.default_rng(seed).normal(0.0, noise, path.shape)
    params = dict(posture="removed", tempo=0.0, relative=relative)
    batched = run(chained, path, True, monkeypatch, **params)
    alone = run(chained, path, False, monkeypatch, **params)
    assert batched == alone


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), c=st.integers(1, 6), s=st.integers(1, 15), m=st.integers(1, 4),
       k=st.integers(1, 5), frames=st.integers(1, 4), centred=st.booleans())
def test_every_candidates_sums_at_once_are_each_candidates_bit_for_bit(seed, c, s, m, k, frames, centred):
    """:func:`online_style.residuals_all` against :meth:`Fit.add` and :func:`residuals` candidate by candidate, over a
    few calls of ``m`` rows each (random data, NaNs among the predictions): the same sums, best paces and distances."""
    from plugins.lib import online_style

    rng = np.random.default_rng(seed)
    obs_a, obs_b = online_style.Observed.empty(k), online_style.Observed.empty(k)
    alone = [online_style.Fit.empty(s, k) for _ in range(c)]
    at_once = [f.copy() for f in alone]
    for _ in range(frames):
        o, p = rng.normal(size=(m, k, 3)), rng.normal(size=(c, s, m, k, 3))
        p[rng.random(p.shape[:-1]) < 0.05] = np.nan
        obs_a.add(o)
        obs_b.add(o)
        d, best = online_style.residuals_all(obs_b, at_once, o, p, centred)
        for i, fit in enumerate(alone):
            fit.add(o, p[i])
            di, bi = online_style.residuals(obs_a, fit, o[-1], p[i, :, -1], centred)
            assert bi == best[i]
            np.testing.assert_array_equal(di, d[i])
            for name in ("sp", "spp", "sop", "n"):
                np.testing.assert_array_equal(getattr(fit, name), getattr(at_once[i], name))
