"""The forward model's posture removed in proportion to each part's stillness (issue 18, fmstill): ``posture =
"still"`` of ``forward-model``, path search's ``still`` estimated online (:func:`plugins.lib.online_style.stillness`).

The formula: the stillness from running sums is :func:`plugins.lib.style.stillness` over the frames seen, whatever
chunks they came in; the residual sum of squares and the last frame's distances are those computed directly from the
frames with each part's mean times its stillness removed from both sides; the whole take at once
(:func:`online_style.distances_all`) is what following it frame by frame gives, and every candidate at once
(:func:`online_style.residuals_all`) what each alone gives. The behaviour, on numbers and on the hand-built ``arms``
graph of ``tests/test_forward_model.py`` (``out``: the left wrist 30 cm along x in one second, the right wrist held):
a still part held elsewhere through the movement cancels, as with the posture removed; a moving part held elsewhere
(the whole movement made from another place) still counts, as with the posture kept.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib import style
from plugins.lib.online_style import Fit, Observed, distances_all, fitted, residuals, residuals_all, stillness
from tests.test_forward_model import FPS, arms, stroke_path  # noqa: F401 (arms: the fixture)
from tests.test_forward_model_relative import use
from toolkit import Motion
from toolkit.watching import feed


def chunks(draw_sizes: list[int], n: int) -> list[tuple[int, int]]:
    """Rows 0 .. n - 1 cut into consecutive chunks of the given sizes (the last takes the rest)."""
    out, at = [], 0
    for size in draw_sizes:
        if at >= n:
            break
        out.append((at, min(n, at + size)))
        at += size
    if at < n:
        out.append((at, n))
    return out


def moving(rng: np.random.Generator, n: int, k: int) -> np.ndarray:
    """Frames (n, k, 3): each part about its own place, moving by its own amount (one part not at all)."""
    amount = rng.uniform(0.0, 1.0, k)
    amount[rng.integers(k)] = 0.0
    return rng.normal(0.0, 2.0, (1, k, 3)) + rng.normal(size=(n, k, 3)) * amount[None, :, None]


# -- the formula --------------------------------------------------------------------------------------------------


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(1, 30), k=st.integers(1, 6),
       sizes=st.lists(st.integers(1, 5), max_size=10))
def test_the_running_stillness_is_path_searchs_over_the_frames_seen(seed, n, k, sizes):
    rng = np.random.default_rng(seed)
    o = moving(rng, n, k)
    obs = Observed.empty(k)
    for a, b in chunks(sizes, n):
        obs.add(o[a:b])
        np.testing.assert_allclose(stillness(obs), style.stillness(o[:b], np.ones((b, k), bool)), atol=1e-9)


def test_stillness_before_anything_moved_is_one_and_a_still_part_is_exactly_one():
    obs = Observed.empty(3)
    np.testing.assert_array_equal(stillness(obs), [1.0, 1.0, 1.0])
    still = np.array([[0.1, 0.2, 0.3], [1.0, -2.0, 0.5], [7.0, 7.0, 7.0]])
    for _ in range(4):
        obs.add(still[None])
    np.testing.assert_array_equal(stillness(obs), [1.0, 1.0, 1.0])  # nothing moves (not even by rounding)
    for x in (0.0, 0.3, 0.1):
        obs.add((still + [[x, 0, 0], [0, 0, 0], [0, 0, 0]])[None])
    w = stillness(obs)
    assert w[0] == 0.0 and w[1] == 1.0 and w[2] == 1.0  # the part that moves most, and the parts that do not


def direct(o: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """From the frames themselves: per pace (S,) the residual sum of squares of ``o`` (n, k, 3) against ``p``
    (S, n, k, 3) with each part's mean times its stillness over ``o`` removed from both sides, and each pace's
    distances at the last frame (S, k)."""
    w = style.stillness(o, np.ones(o.shape[:2], bool))[:, None]
    oc = o - w * o.mean(axis=0)
    pc = p - w * p.mean(axis=1, keepdims=True)
    r = oc[None] - pc
    return (r * r).sum(axis=(1, 2, 3)), np.linalg.norm(r[:, -1], axis=-1)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(1, 20), k=st.integers(1, 5), s=st.integers(1, 4))
def test_the_residuals_from_running_sums_are_those_of_the_frames_with_the_still_parts_means_removed(seed, n, k, s):
    rng = np.random.default_rng(seed)
    o, p = moving(rng, n, k), rng.normal(size=(s, n, k, 3))
    obs, fit = Observed.empty(k), Fit.empty(s, k)
    obs.add(o)
    fit.add(o, p)
    rss, last = direct(o, p)
    np.testing.assert_allclose(fitted(obs, fit, "still"), rss, rtol=1e-9, atol=1e-9)
    d, best = residuals(obs, fit, o[-1], p[:, -1], "still")
    assert rss[best] == pytest.approx(rss.min(), abs=1e-9)
    np.testing.assert_allclose(d, last[best], atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), c=st.integers(1, 5), s=st.integers(1, 5), m=st.integers(1, 3),
       frames=st.integers(1, 4))
def test_every_candidate_at_once_is_each_alone_with_the_still_parts_means_removed(seed, c, s, m, frames):
    rng = np.random.default_rng(seed)
    k = 4
    obs_a, obs_b = Observed.empty(k), Observed.empty(k)
    alone = [Fit.empty(s, k) for _ in range(c)]
    at_once = [f.copy() for f in alone]
    o_all = moving(rng, m * frames, k)
    for t in range(frames):
        o, p = o_all[t * m:(t + 1) * m], rng.normal(size=(c, s, m, k, 3))
        obs_a.add(o)
        obs_b.add(o)
        d, best = residuals_all(obs_b, at_once, o, p, "still")
        for i, fit in enumerate(alone):
            fit.add(o, p[i])
            di, bi = residuals(obs_a, fit, o[-1], p[i, :, -1], "still")
            rss = fitted(obs_a, fit, "still")
            assert rss[best[i]] == pytest.approx(rss[bi], abs=1e-9)
            if bi == best[i]:
                np.testing.assert_allclose(d[i], di, atol=1e-9)


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**31 - 1), n=st.integers(1, 15), s=st.integers(1, 4))
def test_the_whole_take_at_once_is_the_running_sums_frame_by_frame_with_stillness(seed, n, s):
    rng = np.random.default_rng(seed)
    o, p = moving(rng, n, 3), rng.normal(size=(s, n, 3, 3))
    d, best = distances_all(o, p, "still")
    obs, fit = Observed.empty(3), Fit.empty(s, 3)
    for i in range(n):
        obs.add(o[i:i + 1])
        fit.add(o[i:i + 1], p[:, i:i + 1])
        di, bi = residuals(obs, fit, o[i], p[:, i], "still")
        rss = fitted(obs, fit, "still")
        assert rss[best[i]] == pytest.approx(rss[bi], abs=1e-9)
        if best[i] == bi:
            np.testing.assert_allclose(d[i], di, atol=1e-9)


# -- the behaviour, on numbers --------------------------------------------------------------------------------------


def two_parts(offset_still: float, offset_moving: float) -> tuple[np.ndarray, np.ndarray]:
    """A prediction (1, n, 2, 3): part 0 moves along x, part 1 holds still; the observation is the same movement
    with the still part held ``offset_still`` higher and the moving part's whole movement ``offset_moving`` higher."""
    t = np.linspace(0.0, 1.0, 25)
    p = np.zeros((25, 2, 3))
    p[:, 0, 0] = 0.3 * t
    p[:, 1] = [0.5, 0.0, 0.0]
    o = p + np.array([[0.0, offset_moving, 0.0], [0.0, offset_still, 0.0]])
    return o, p[None]


def last_distances(o: np.ndarray, p: np.ndarray, centred) -> np.ndarray:
    obs, fit = Observed.empty(o.shape[1]), Fit.empty(1, o.shape[1])
    obs.add(o)
    fit.add(o, p)
    return residuals(obs, fit, o[-1], p[:, -1], centred)[0]


def test_a_still_part_held_elsewhere_cancels_and_a_moving_part_held_elsewhere_counts():
    o, p = two_parts(0.08, 0.0)
    np.testing.assert_allclose(last_distances(o, p, "still"), [0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(last_distances(o, p, False), [0.0, 0.08], atol=1e-12)
    o, p = two_parts(0.0, 0.08)
    np.testing.assert_allclose(last_distances(o, p, "still"), [0.08, 0.0], atol=1e-12)  # where it moves counts
    np.testing.assert_allclose(last_distances(o, p, True), [0.0, 0.0], atol=1e-12)  # removed: it cancels


# -- the behaviour, in the forward model ----------------------------------------------------------------------------


def follow(arms, left: np.ndarray, right_offset, **params):
    """The left wrist along ``left`` (n, 3), the right wrist held at rest plus ``right_offset`` throughout, followed
    to its end by the forward model comparing positions (``relative`` off), the largest part's error: the answers
    and the matcher."""
    rest = arms.motor.rest
    frames = np.repeat(rest[None], len(left), axis=0)
    frames[:, 2] = left
    frames[:, 3] = rest[3] + np.asarray(right_offset, dtype=float)
    demo = Motion(frames - rest[0], FPS, arms.body.parts)
    arms.motor.reset()
    matcher = use(arms, **{"dropout": "relative", "error": "max", "relative": False, "learn": False,
                           "posture": "kept", "tempo": 0.0, **params})
    answers = [a for a in feed(matcher, demo) if a is not None]
    matcher.conclude(demo)
    return answers, matcher


@pytest.mark.parametrize("tempo", [0.0, 2.0])
def test_the_right_wrist_held_lower_through_out_cancels_with_stillness(arms, tempo):
    """``out`` with the right wrist, which ``out`` keeps still, held 8 cm lower: with the posture kept the imitation
    deviates; removed in proportion to stillness, ``out`` is followed to its end as with the posture removed."""
    path = stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0])
    _, matcher = follow(arms, path, [0.0, -0.08, 0.0], tempo=tempo)
    assert matcher.inspect()["deviated"]
    for posture in ("still", "removed"):
        answers, matcher = follow(arms, path, [0.0, -0.08, 0.0], posture=posture, tempo=tempo)
        assert [a.path for a in answers] == [(arms.out,)] and not matcher.inspect()["deviated"]
        assert matcher.tracks["wrists"].styled[(arms.out,)].extra["error"] < 0.01


@pytest.mark.parametrize("tempo", [0.0, 2.0])
def test_out_made_8_cm_lower_counts_with_stillness_and_not_with_the_posture_removed(arms, tempo):
    """``out``'s whole movement made 8 cm lower (the left wrist, the part that moves, held elsewhere through it):
    with the posture removed it cancels and ``out`` is followed; in proportion to stillness the moving part keeps
    its place, so ``out`` predicts it 8 cm off and its imitation deviates, as with the posture kept."""
    path = stroke_path(arms.motor.rest[2] + [0.0, -0.08, 0.0], [0.3, 0.0, 0.0])
    answers, matcher = follow(arms, path, [0.0, 0.0, 0.0], posture="removed", tempo=tempo)
    assert [a.path for a in answers] == [(arms.out,)] and not matcher.inspect()["deviated"]
    for posture in ("still", "kept"):
        _, matcher = follow(arms, path, [0.0, 0.0, 0.0], posture=posture, tempo=tempo)
        assert matcher.inspect()["deviated"]


def test_standing_still_with_stillness_is_held_at_the_onset_for_the_moving_parts(arms):
    """``unexplained`` compares with predicting that nothing moves, in the same way: with ``"still"`` the moving
    part is predicted at its onset place (its whole displacement counts), the still one about its mean (its held
    offset cancels). ``out`` is explained and committed to early; a movement 135 degrees from both edges is not."""
    rest = arms.motor.rest[2]
    params = {"posture": "still", "unexplained": 1.0, "ceiling": 10.0, "relative": True, "error": "moving"}
    answers, _ = follow(arms, stroke_path(rest, [0.3, 0.0, 0.0]), [0.0, -0.08, 0.0], **params)
    assert [a.path for a in answers] == [(arms.out,)] and answers[0].decided_at <= 0.5 * 31
    answers, matcher = follow(arms, stroke_path(rest, [-0.25, -0.25, 0.0]), [0.0, -0.08, 0.0], **params)
    assert not answers
    track = matcher.tracks["wrists"]
    total, frames = track.extent
    assert frames > 0 and total / frames > 0.05  # the left wrist's displacement from its onset place counts


def test_the_spread_between_two_takes_differing_by_a_still_parts_place_is_none_with_stillness(arms):
    """:meth:`ForwardModel.take_errors` with ``"still"``: a take with the right wrist held 8 cm lower under ``out``'s
    commands has no error (the still part's offset cancels); the take made 8 cm lower, its error is the offset."""
    matcher = use(arms, dropout="relative", error="max", relative=False, posture="still", tempo=0.0)
    matcher.fps = FPS
    rest = arms.motor.rest
    left = stroke_path(rest[2], [0.3, 0.0, 0.0])
    take = np.stack([left, np.repeat(rest[3][None] + [0.0, -0.08, 0.0], len(left), axis=0)], axis=1)
    assert matcher.take_errors("wrists", take, (arms.out,), FPS).max() < 5e-3
    lower = take.copy()
    lower[:, 0] += [0.0, -0.08, 0.0]
    lower[:, 1] = rest[3]
    errors = matcher.take_errors("wrists", lower, (arms.out,), FPS)
    assert errors[5:].min() > 0.06
