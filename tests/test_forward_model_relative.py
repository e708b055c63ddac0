"""The forward model's relative drop-out and its spread between takes (issue 18; K&G §4.4, Fig. 3).

The same hand-built graph as ``tests/test_forward_model.py``: one subsystem, both wrists; ``out`` moves the left
wrist 30 cm to the side, ``up`` 30 cm up, each a straight guiding stroke of one second. A demonstration along ``out``
after a path of length ``L`` is ``L·√2`` from ``up``'s prediction and about 0 from ``out``'s.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.ndimage import uniform_filter1d

from tests.test_forward_model import FPS, arms, demonstration, stroke_path  # noqa: F401 (arms: the fixture)
from plugins.lib.guiding_stroke import GuidingStroke
from toolkit.watching import feed


def use(character, **params):
    character.matcher.params = {**character.matcher.params, **params}
    character.matcher._spreads = None
    return character.matcher


# -- the rule on hand-worked numbers ------------------------------------------------------------------------


def test_a_candidate_one_and_a_half_times_the_best_drops_under_ratio_1_25_and_survives_under_2(arms):
    errors = {("a",): 0.04, ("b",): 0.06}  # b is 1.5 times a; both above min_move (0.02), under ceiling (0.15)
    assert use(arms, dropout="relative", ratio=1.25)._survivors(errors) == {("a",): 0.04}
    assert use(arms, dropout="relative", ratio=2.0)._survivors(errors) == errors
    # the ceiling drops a candidate whatever the others do, and both when both are above it: unknown
    assert use(arms, dropout="relative", ratio=2.0, ceiling=0.05)._survivors(errors) == {("a",): 0.04}
    assert use(arms, dropout="relative", ratio=2.0, ceiling=0.03)._survivors(errors) == {}


def test_the_absolute_dropout_is_the_papers_threshold_whatever_the_others_do(arms):
    errors = {("a",): 0.001, ("b",): 0.045, ("c",): 0.055}
    assert arms.matcher.params["dropout"] == "absolute"  # the default: the paper
    assert use(arms, ratio=1.0)._survivors(errors) == {("a",): 0.001, ("b",): 0.045}  # ratio is not used
    assert use(arms, threshold=0.06)._survivors(errors) == errors


def test_errors_under_min_move_count_as_min_move(arms):
    """The best predicts within 1 mm: bar = 1.5 x max(0.001, 0.02) = 0.03, not 1.5 x 0.001."""
    errors = {("a",): 0.001, ("b",): 0.029, ("c",): 0.031}
    assert use(arms, dropout="relative", ratio=1.5, min_move=0.02)._survivors(errors) == {("a",): 0.001, ("b",): 0.029}
    assert use(arms, dropout="relative", ratio=1.5, min_move=0.04)._survivors(errors) == errors  # bar 0.06


@settings(max_examples=200, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])  # use() sets
# every parameter the rule reads on each example
@given(errors=st.lists(st.floats(0.0, 0.5), min_size=1, max_size=8), ratio=st.floats(1.0, 4.0),
       ceiling=st.floats(0.0, 0.5))
def test_relative_survivors_are_the_best_and_those_within_ratio_of_it(arms, errors, ratio, ceiling):
    matcher = use(arms, dropout="relative", ratio=ratio, ceiling=ceiling)
    table = {(f"e{i}",): e for i, e in enumerate(errors)}
    alive = matcher._survivors(table)
    under = {p: e for p, e in table.items() if e <= ceiling}
    assert set(alive) <= set(under)
    if under:
        best = min(under.values())
        assert best in alive.values()  # the best under the ceiling never drops out
        bar = ratio * max(best, matcher.params["min_move"])
        assert alive == {p: e for p, e in under.items() if e <= bar}
    else:
        assert alive == {}
    wider = use(arms, dropout="relative", ratio=ratio + 0.5, ceiling=ceiling)._survivors(table)
    assert set(alive) <= set(wider)  # a larger ratio keeps at least as many


# -- on a demonstration ----------------------------------------------------------------------------------------


def test_relative_dropout_drops_up_once_it_is_ratio_times_out_and_commits_to_out(arms):
    matcher = use(arms, dropout="relative", ratio=1.5)
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0]))
    answers = list(feed(matcher, demo))
    trace = matcher.inspect()["trace"]
    bars = {frame: 1.5 * max(min(errors.values()), matcher.params["min_move"]) for frame, errors in trace}
    up = [(frame, errors[(arms.up,)]) for frame, errors in trace if (arms.up,) in errors]
    assert up[-1][1] > bars[up[-1][0]] and all(error <= bars[frame] for frame, error in up[:-1])
    assert up[-1][1] < matcher.params["ceiling"]  # dropped by the race, not by the ceiling
    commit = next(a for a in answers if a is not None)
    assert commit.path == (arms.out,) and commit.decided_at < 0.5 * demo.n_frames
    # the paper's threshold keeps up alive longer: relative commits no later
    paper = use(arms, dropout="absolute")
    arms.motor.reset()
    assert next(a for a in feed(paper, demo) if a is not None).decided_at >= commit.decided_at


def test_a_movement_not_in_the_repertoire_is_still_unknown(arms):
    """Inwards and down, 135 degrees from both edges: their errors grow alike, so the race keeps both, and both
    pass the ceiling: nothing is committed and, without learning, the answer is unknown."""
    matcher = use(arms, dropout="relative", ratio=1.5, learn=False)
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [-0.25, -0.25, 0.0]))
    assert all(a is None for a in feed(matcher, demo))
    answer = matcher.conclude(demo)
    assert answer.movement is None
    last = {}
    for frame, errors in matcher.inspect()["trace"]:
        last.update(errors)
    assert min(last.values()) > matcher.params["ceiling"]


# -- spread between takes ---------------------------------------------------------------------------------------


@pytest.fixture
def takes(arms):
    """Two takes of ``reach``: the left wrist 30 cm to the side, and 30 cm to the side and 4 cm up (7.6 degrees
    apart); each learned as one edge, labelled ``reach`` as clips are, with its own trajectory as the take."""
    motor = arms.motor
    left, right = motor.rest[2], motor.rest[3]
    hold = GuidingStroke(right, right, 1.0)
    paths, edges = [], []
    for chord in ([0.3, 0.0, 0.0], [0.3, 0.04, 0.0]):
        edge = motor.learn("wrists", "hub", [GuidingStroke(left, left + chord, 1.0), hold])
        motor.add_sequence([edge], name="reach" if not edges else "reach#2", label="reach")
        observed = np.repeat(motor.rest[[2, 3]][None], int(FPS) + 1, axis=0)
        observed[:, 0] = stroke_path(left, chord)
        paths.append(observed)
        edges.append(edge)
    motor._takes = {"reach": [((e,), "wrists", o, FPS) for e, o in zip(edges, paths)]}
    arms.reach = edges
    return arms


def test_a_takes_error_under_the_other_takes_commands_is_its_distance_from_their_prediction(takes):
    """At path length L the other take predicts L along a direction 7.6 degrees off: 2 L sin(3.8°) ≈ 0.132 L."""
    matcher = takes.matcher
    (first, _, observed, _), (second, *_) = takes.motor.takes()["reach"]
    errors = matcher.take_errors("wrists", observed, second)
    walked = np.linalg.norm(observed[1:, 0] - observed[0, 0], axis=1)
    angle = np.arctan2(0.04, 0.3)
    far = walked > 0.02
    np.testing.assert_allclose(errors[far], 2 * np.sin(angle / 2) * walked[far], rtol=0.1)
    assert matcher.take_errors("wrists", observed, first).max() < 0.01  # its own commands predict it


def test_a_takes_errors_are_the_forward_models_own_frame_by_frame_along_a_path_of_several_edges(takes):
    """take_errors predicts every frame at once; frame by frame, _error (what following does) gives the same, also
    when the path runs on from one edge into the next (``reach`` then ``up``'s way back is not needed: out then up)."""
    from plugins.matchers.forward_model import Track

    motor, matcher = takes.motor, takes.matcher
    left, right = motor.rest[2], motor.rest[3]
    hold = GuidingStroke(right, right, 1.0)
    node = motor.edge(takes.out).target
    onward = motor.learn("wrists", node, [GuidingStroke(left + [0.3, 0.0, 0.0], left + [0.3, 0.2, 0.0], 1.0), hold])
    observed = np.repeat(motor.rest[[2, 3]][None], 2 * int(FPS) + 1, axis=0)
    observed[:, 0] = np.concatenate([stroke_path(left, [0.25, 0.05, 0.0]), stroke_path(left + [0.25, 0.05, 0.0],
                                                                                         [0.0, 0.2, 0.0])[1:]])
    for error in ("max", "mean"):
        use(takes, error=error)
        fast = matcher.take_errors("wrists", observed, (takes.out, onward))
        track = Track("wrists", 1.0, False, "hub", 0, {}, [], first=observed[0])
        smooth = uniform_filter1d(observed, size=3, axis=0, mode="nearest")
        walked = np.concatenate([np.zeros((1, 2)), np.cumsum(np.linalg.norm(np.diff(smooth, axis=0), axis=-1), axis=0)])
        slow = [matcher._error(track, (takes.out, onward), walked[t], observed[t]) for t in range(1, len(observed))]
        np.testing.assert_allclose(fast, slow, atol=1e-3)
        assert fast.max() > 0.05  # not trivially zero


def test_the_spread_is_the_median_of_each_takes_mean_error_and_sets_the_movements_limit(takes):
    matcher = use(takes, spread=2.0)
    (a, _, obs_a, _), (b, _, obs_b, _) = takes.motor.takes()["reach"]
    expected = float(np.median([matcher.take_errors("wrists", obs_a, b).mean(),
                                matcher.take_errors("wrists", obs_b, a).mean()]))
    assert matcher.spreads() == {"reach": pytest.approx(expected)}
    assert 0.01 < expected < 0.04  # a few centimetres: 0.132 x the mean path length walked (about 0.15 m)
    assert matcher._limit(a) == pytest.approx(2.0 * expected)  # a movement of several takes: its spread
    assert matcher._limit((takes.up,)) == matcher.params["threshold"]  # one take (unlabelled): the threshold
    assert use(takes, spread=2.0, dropout="relative")._limit((takes.up,)) == matcher.params["ceiling"]
    assert use(takes, spread=0.0, dropout="absolute")._limit(a) == matcher.params["threshold"]  # 0: the paper's


def test_the_race_compares_mean_errors_since_the_onset_and_an_extended_path_inherits_them(arms):
    """a errs 0.05 then 0.05, b 0.02 then 0.09: on the second frame b is 1.8 times a (dropped under ratio 1.25),
    but its mean, 0.055, is 1.1 times a's 0.05 (kept). A path extended from a carries a's sums on."""
    from plugins.matchers.forward_model import Track

    frames = [{("a",): 0.05, ("b",): 0.02}, {("a",): 0.05, ("b",): 0.09}]
    matcher = use(arms, dropout="relative", ratio=1.25, race=True)
    track = Track("wrists", 1.0, False, "hub", 0, {}, [])
    for errors in frames:
        evidence = matcher._evidence(track, errors)
        alive = matcher._survivors(errors, evidence)
    assert evidence == {("a",): pytest.approx(0.05), ("b",): pytest.approx(0.055)}
    assert set(alive) == {("a",), ("b",)}
    plain = use(arms, dropout="relative", ratio=1.25, race=False)
    assert set(plain._survivors(frames[1], plain._evidence(Track("wrists", 1.0, False, "hub", 0, {}, []),
                                                          frames[1]))) == {("a",)}
    extended = use(arms, dropout="relative", ratio=1.25, race=True)._evidence(track, {("a", "c"): 0.08})
    assert extended == {("a", "c"): pytest.approx((0.05 + 0.05 + 0.08) / 3)}


def test_at_the_end_the_leader_of_the_race_is_the_answer_when_no_candidate_prevailed_alone(arms):
    """``aside`` is ``out`` turned 3 degrees: along ``out`` it errs at most 2 x 0.3 x sin(1.5°) ≈ 1.6 cm, under
    min_move x ratio (3 cm), so both stay alive to the end and nothing is committed early. The paper's drop-out then
    answers unknown (without learning); the relative one answers the better predictor, ``out``."""
    motor = arms.motor
    left, right = motor.rest[2], motor.rest[3]
    turn = np.radians(3.0)
    aside = motor.learn("wrists", "hub", [GuidingStroke(left, left + 0.3 * np.array([np.cos(turn), np.sin(turn), 0.0]),
                                                        1.0), GuidingStroke(right, right, 1.0)])
    demo = demonstration(arms, stroke_path(left, [0.3, 0.0, 0.0]))
    matcher = use(arms, dropout="absolute", learn=False)
    assert all(a is None for a in feed(matcher, demo)) and matcher.conclude(demo).movement is None
    motor.reset()
    matcher = use(arms, dropout="relative", ratio=1.5, learn=False)
    assert all(a is None for a in feed(matcher, demo))
    assert set(matcher.inspect()["candidates"]) == {(arms.out,), (aside,)}
    answer = matcher.conclude(demo)
    assert answer.movement == arms.out and answer.decided_at is None


def test_a_candidate_worse_than_predicting_no_movement_drops_out_with_stillness(arms):
    errors = {("a",): 0.03, ("b",): 0.05}  # still: 0.02, min_move 0.02: up to 0.04 explains something
    assert use(arms, dropout="relative", ratio=2.0, stillness=True)._survivors(errors, None, 0.02) == {("a",): 0.03}
    assert use(arms, dropout="relative", ratio=2.0, stillness=False)._survivors(errors) == errors


def test_with_stillness_a_movement_no_edge_fits_is_unknown_as_soon_as_every_edge_is_worse_than_standing_still(arms):
    """Inwards and down, 135 degrees from both edges: after a path L each prediction is 2 L sin(67.5°) ≈ 1.85 L off,
    standing still L: both drop once 0.85 L > min_move (2 cm), L ≈ 2.4 cm, long before the ceiling (15 cm, L ≈ 8 cm)."""
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [-0.25, -0.25, 0.0]))
    moved = np.linalg.norm(demo.positions[:, 2] - demo.positions[0, 2], axis=1)
    dropped = {}
    for stillness in (True, False):
        arms.motor.reset()
        matcher = use(arms, dropout="relative", ratio=1.5, learn=False, stillness=stillness)
        assert all(a is None for a in feed(matcher, demo))
        assert matcher.conclude(demo).movement is None
        dropped[stillness] = moved[matcher.inspect()["trace"][-1][0]]  # the frame both were last predicted
    assert 0.02 < dropped[True] < 0.04
    assert dropped[False] > 0.07
