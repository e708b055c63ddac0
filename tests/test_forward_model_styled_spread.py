"""The forward model's spreads between takes in the demonstrator's own style (issue 18, fmstyled2; K&G §4.4, §6).

With ``posture`` or ``tempo`` on, :meth:`ForwardModel.take_errors` (and so :meth:`ForwardModel.spreads`, which the
``spread`` limit measures against) compares a take with another take's commands as the candidates are compared
while following: about each side's own mean over the frames seen and at the fitted pace. On the ``takes`` fixture of
``tests/test_forward_model_relative.py`` (two takes of ``reach``, the left wrist 30 cm to the side, the second also
4 cm up) and on takes made here: two takes that differ only by a held offset have no spread with the posture removed
(and a spread of the offset without); a take performed at half the pace has none with ``tempo``; the whole take at once
gives what following it frame by frame gives.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.test_forward_model import FPS, arms, stroke_path  # noqa: F401 (arms: the fixture)
from tests.test_forward_model_relative import takes, use  # noqa: F401 (takes: the fixture)
from plugins.lib import online_style
from plugins.lib.guiding_stroke import GuidingStroke
from plugins.matchers.forward_model import Track

E = {"dropout": "relative", "error": "moving", "relative": False, "learn": False}


def offset_takes(arms, offset, seconds=(1.0, 1.0)):
    """Two takes of ``reach``: the left wrist 30 cm to the side; the second held ``offset`` away throughout (both
    wrists) and taking ``seconds[1]`` seconds. Each learned as one edge from its own positions."""
    motor = arms.motor
    left, right = motor.rest[2], motor.rest[3]
    edges, observed = [], []
    for i, (shift, duration) in enumerate(zip((np.zeros(3), np.asarray(offset, float)), seconds)):
        edge = motor.learn("wrists", "hub", [GuidingStroke(left + shift, left + shift + [0.3, 0.0, 0.0], duration),
                                             GuidingStroke(right + shift, right + shift, duration)])
        motor.add_sequence([edge], name="reach" if not i else "reach#2", label="reach")
        o = np.repeat((motor.rest[[2, 3]] + shift)[None], int(round(duration * FPS)) + 1, axis=0)
        o[:, 0] = stroke_path(left + shift, [0.3, 0.0, 0.0], duration)
        edges.append(edge)
        observed.append(o)
    motor._takes = {"reach": [((e,), "wrists", o, FPS) for e, o in zip(edges, observed)]}
    return edges, observed


def test_two_takes_differing_by_a_held_offset_have_no_spread_with_the_posture_removed(arms):
    (a, b), (obs_a, obs_b) = offset_takes(arms, [0.0, -0.06, 0.04])
    plain = use(arms, **E, spread=2.0).spreads()["reach"]
    assert plain == pytest.approx(np.hypot(0.06, 0.04), rel=0.05)  # the offset, frame after frame
    matcher = use(arms, **E, spread=2.0, posture="removed")
    # within a millimetre (the path-length clock reads the walked path of positions averaged over three frames)
    assert matcher.spreads()["reach"] < 1e-3
    assert matcher.take_errors("wrists", obs_b, (a,)).max() < 2e-3
    assert matcher._limit((a,)) == pytest.approx(2.0 * matcher.spreads()["reach"])


def test_a_take_at_half_the_pace_has_no_spread_with_tempo_and_the_posture_removed(arms):
    """The second take is the first performed over two seconds: on the path-length clock (§4.4) it is already the
    same; with ``tempo`` the pace fitted to it is a half, and its error vanishes too."""
    (a, b), (obs_a, obs_b) = offset_takes(arms, [0.0, 0.0, 0.0], seconds=(1.0, 2.0))
    matcher = use(arms, **E, spread=2.0, tempo=2.0, posture="removed")
    assert matcher.take_errors("wrists", obs_b, (a,), FPS).max() < 2e-3
    assert matcher.take_errors("wrists", obs_a, (b,), FPS).max() < 2e-3
    # predicted at the take's own pace (1), it would be twice as far along: far off
    use(arms, tempo=1.0)
    assert matcher.take_errors("wrists", obs_b, (a,), FPS).max() > 0.05


@pytest.mark.parametrize("styled", [{"posture": "removed"}, {"tempo": 2.0}, {"tempo": 2.0, "posture": "removed"}])
@pytest.mark.parametrize("error", ["max", "mean"])
def test_the_whole_take_at_once_is_what_following_it_frame_by_frame_gives(takes, styled, error):
    """Each frame's error from :meth:`_styled_errors` fed the take a row at a time (the fits' running sums) against
    :meth:`take_errors` (cumulative sums): the same, for the other take's commands and for its own."""
    matcher = use(takes, **{**E, "error": error, **styled})
    matcher.fps = FPS
    (first, _, observed, _), (second, *_) = takes.motor.takes()["reach"]
    observed = observed + np.random.default_rng(0).normal(0.0, 0.001, observed.shape)  # not a perfect line
    for path in (second, first):
        fast = matcher.take_errors("wrists", observed, path, FPS)
        track = Track("wrists", 1.0, False, "hub", 0, {path: 0.0}, [], first=observed[0])
        slow = []
        for t in range(1, len(observed)):
            lengths = np.zeros(observed.shape[1])  # the combination (max or mean) does not read them
            slow.append(matcher._styled_errors(track, [path], observed[: t + 1], lengths)[path])
            track.candidates = {path: 0.0}
        # on the pace's clock exactly; on the path-length clock (posture alone) within a few millimetres: following
        # averages the last frames over fewer than three (:func:`_lengths`), the whole take over three throughout
        np.testing.assert_allclose(fast, slow, atol=1e-9 if "tempo" in styled else 3e-3)
    assert max(fast.max(), max(slow)) > 0.0


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(1, 12), s=st.integers(1, 5), centred=st.booleans())
def test_cumulative_distances_are_the_running_sums_frame_by_frame(seed, n, s, centred):
    """:func:`online_style.distances_all` against :class:`Observed`/:class:`Fit`/:func:`residuals` row by row."""
    rng = np.random.default_rng(seed)
    o, p = rng.normal(size=(n, 3, 3)), rng.normal(size=(s, n, 3, 3))
    d, best = online_style.distances_all(o, p, centred)
    obs, fit = online_style.Observed.empty(3), online_style.Fit.empty(s, 3)
    for i in range(n):
        obs.add(o[i:i + 1])
        fit.add(o[i:i + 1], p[:, i:i + 1])
        di, bi = online_style.residuals(obs, fit, o[i], p[:, i], centred)
        rss = online_style.fitted(obs, fit, centred)
        assert rss[best[i]] == pytest.approx(rss[bi], abs=1e-9)  # the same least residual (ties: either)
        if best[i] == bi:
            np.testing.assert_allclose(d[i], di, atol=1e-9)


@pytest.mark.parametrize("styled", [{"tempo": 2.0, "posture": "removed"}, {"tempo": 2.0, "relative": True},
                                    {"posture": "removed"}, {}])
def test_the_spreads_kept_between_takes_are_each_take_computed_alone_bit_for_bit(arms, styled):
    """:meth:`ForwardModel.spreads` keeps, between the takes of a movement, each path's predictions at the paces over
    the longest take (sliced for a shorter one), each take's path lengths and weights, and stacks every take's commands
    once: three takes of different lengths (1, 1.6 and 0.7 s, the third moved) give the same errors, take by take and
    path by path, as :meth:`ForwardModel.take_errors` computed alone, and the spread their median of minima."""
    motor = arms.motor
    (a, b), (obs_a, obs_b) = offset_takes(arms, [0.0, -0.05, 0.02], seconds=(1.0, 1.6))
    left, right = motor.rest[2] + [0.01, 0.03, 0.0], motor.rest[3] + [0.01, 0.03, 0.0]
    c = motor.learn("wrists", "hub", [GuidingStroke(left, left + [0.25, 0.05, 0.0], 0.7),
                                      GuidingStroke(right, right, 0.7)])
    obs_c = np.repeat(np.stack([left, right])[None], 22, axis=0)
    obs_c[:, 0] = stroke_path(left, [0.25, 0.05, 0.0], 0.7)
    obs_c = obs_c + np.random.default_rng(3).normal(0.0, 0.002, obs_c.shape)
    examples = [((a,), "wrists", obs_a, FPS), ((b,), "wrists", obs_b, FPS), ((c,), "wrists", obs_c, FPS)]
    motor._takes = {"reach": examples}
    matcher = use(arms, **{**E, "spread": 2.0, **styled})
    matcher._time_tables = {}
    kept = {"longest": max(len(o) for _, _, o, _ in examples)}
    minima = []
    for i, (_, subsystem, observed, fps) in enumerate(examples):
        means = []
        for j, (edges, *_) in enumerate(examples):
            if j != i:
                alone = matcher.take_errors(subsystem, observed, edges, fps)
                with_kept = matcher.take_errors(subsystem, observed, edges, fps, kept=kept)
                np.testing.assert_array_equal(with_kept, alone)
                means.append(float(np.mean(alone)))
        minima.append(min(means))
    if "tempo" in styled:
        assert any(key[0] == "points" for key in kept if isinstance(key, tuple))  # predictions were kept
    matcher._spreads = None
    assert matcher.spreads()["reach"] == float(np.median(minima))


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(1, 12), more=st.integers(0, 8), s=st.integers(1, 5),
       centred=st.booleans())
def test_the_sums_of_a_longer_prediction_give_the_distances_of_its_first_rows_bit_for_bit(seed, n, more, s, centred):
    """:func:`online_style.distances_all` with :func:`online_style.prediction_sums` of a prediction ``more`` rows longer
    than the observation (NaNs among them) against the prediction cut to the observation's rows."""
    rng = np.random.default_rng(seed)
    o, p = rng.normal(size=(n, 3, 3)), rng.normal(size=(s, n + more, 3, 3))
    p[rng.random(p.shape[:-1]) < 0.05] = np.nan
    d, best = online_style.distances_all(o, p[:, :n], centred)
    dk, bk = online_style.distances_all(o, None, centred, online_style.prediction_sums(p))
    np.testing.assert_array_equal(d, dk)
    np.testing.assert_array_equal(best, bk)
