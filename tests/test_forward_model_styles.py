"""The forward model across styles (issue 18; K&G §4.1, §4.4, §6): the moving parts' error, the lead's clock and the
unit-free "unknown".

Hand-worked cases of each formula (:func:`moving_weights`, :func:`explained`, :func:`lead_clock`), hypothesis
properties of the invariances claimed for them, the matcher on the hand-built ``arms`` graph of
``tests/test_forward_model.py``, and a scenario on the project's generated data: Morris's demonstrations performed by
a larger body (every part 1.25 times as far from the root) or from another stance (every part moved by a few
centimetres), which the paper's settings do not recognise and the new ones do.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from plugins.matchers.forward_model import explained, lead_clock, moving_weights
from tests.test_forward_model import demonstration, stroke_path, arms  # noqa: F401 (arms: the fixture)
from tests.test_forward_model_relative import use
from toolkit.watching import feed

NEW = {"dropout": "relative", "error": "moving", "relative": True, "unexplained": 1.0}
"""The settings the scenario compares with the paper's (module docstring of ``plugins/matchers/forward_model.py``)."""


# -- the formulas on hand-worked numbers ----------------------------------------------------------------------


def test_moving_weights_are_each_parts_share_of_the_path_covered():
    np.testing.assert_allclose(moving_weights(np.array([0.0, 1.0, 3.0])), [0.0, 0.25, 0.75])
    np.testing.assert_allclose(moving_weights(np.zeros(4)), [0.25] * 4)  # nothing moved: the parts alike
    np.testing.assert_allclose(moving_weights(np.array([np.nan, 1.0])), [0.5, 0.5])  # not finite: alike


def test_explained_compares_the_error_with_a_share_of_the_demonstrations_extent():
    assert explained(0.05, 0.10, 0.5)  # half the extent: within 0.5
    assert not explained(0.06, 0.10, 0.5)
    assert not explained(0.11, 0.10, 1.0)  # worse than predicting that nothing moves
    assert explained(0.015, 0.001, 1.0, floor=0.02)  # an extent under the floor counts as the floor


def test_the_lead_clock_reads_every_part_at_the_time_the_lead_reaches_its_length():
    # a grid of three instants: the lead covers 0, 1, 2; another part 0, 0.5, 3; a third stays still
    arcs = np.array([[0.0, 1.0, 2.0], [0.0, 0.5, 3.0], [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(lead_clock(arcs, 0, 1.5), [1.5, 1.75, 0.0])  # halfway between instants 1 and 2
    np.testing.assert_allclose(lead_clock(arcs, 0, 0.5), [0.5, 0.25, 0.0])
    np.testing.assert_allclose(lead_clock(arcs, 0, 5.0), [2.0, 3.0, 0.0])  # past the end: the end
    np.testing.assert_allclose(lead_clock(arcs, 2, 1.0), [0.0, 0.0, 0.0])  # a still lead holds every part at the start
    # a lead that pauses (1 at instants 1 and 2): its length is reached at the first of them
    np.testing.assert_allclose(lead_clock(np.array([[0.0, 1.0, 1.0, 2.0], [0.0, 1.0, 2.0, 3.0]]), 0, 1.0), [1.0, 1.0])


# -- invariances ---------------------------------------------------------------------------------------------


@settings(max_examples=200, deadline=None)
@given(error=st.floats(0.0, 1.0), extent=st.floats(1e-3, 1.0), unexplained=st.floats(0.1, 3.0),
       scale=st.floats(0.01, 100.0))
def test_explained_has_no_unit(error, extent, unexplained, scale):
    """Scaling the prediction's error and the demonstration's extent together (another body size, another unit)
    leaves the answer as it was, unless the two are within rounding of the limit."""
    if abs(error - unexplained * extent) > 1e-9 * max(1.0, error):
        assert explained(error * scale, extent * scale, unexplained) == explained(error, extent, unexplained)


@settings(max_examples=200, deadline=None)
@given(lengths=st.lists(st.one_of(st.just(0.0), st.floats(1e-6, 10.0)), min_size=1, max_size=12),
       scale=st.floats(1e-3, 1e3))
def test_moving_weights_have_no_unit_and_sum_to_one(lengths, scale):
    """Path lengths of 0 or of a micrometre and more (below that a part has not moved, and a length of 5e-324 m
    halved is 0: a part that moved would become one that did not)."""
    lengths = np.array(lengths)
    weights = moving_weights(lengths)
    assert weights.sum() == pytest.approx(1.0) and (weights >= 0).all()
    np.testing.assert_allclose(moving_weights(lengths * scale), weights, atol=1e-12)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(dz=st.floats(-0.3, 0.3))
def test_with_relative_and_moving_a_demonstration_moved_elsewhere_is_predicted_alike(arms, dz):
    """``out`` performed with the whole body moved by ``dz`` along z (off both strokes' lines, so where each command
    is joined does not change): with ``relative`` and ``error = moving`` every candidate's error, frame by frame, is
    the one of the demonstration in place; the paper's positions are off by ``dz`` from the first frame."""
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0]))
    moved = demonstration(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0]))
    moved.positions[:, 1:] += [0.0, 0.0, dz]  # every part but the root: the root-relative pose moves
    traces = []
    for motion in (demo, moved):
        arms.motor.reset()
        matcher = use(arms, **{**NEW, "learn": False})
        list(feed(matcher, motion))
        traces.append(matcher.inspect()["trace"])
    assert [f for f, _ in traces[0]] == [f for f, _ in traces[1]]
    for (_, a), (_, b) in zip(*traces):
        assert a.keys() == b.keys()
        np.testing.assert_allclose([a[k] for k in a], [b[k] for k in a], atol=1e-9)


# -- the matcher ------------------------------------------------------------------------------------------------


def test_moving_weights_put_the_error_on_the_part_that_moves(arms):
    """Only the left wrist moves along ``out``; ``up``'s prediction of it is off by √2 L after a path L, the right
    wrist by nothing. The mean halves that; the moving parts' error keeps it whole."""
    demo = demonstration(arms, stroke_path(arms.motor.rest[2], [0.3, 0.0, 0.0]))
    results = {}
    for error in ("mean", "moving"):
        arms.motor.reset()
        matcher = use(arms, error=error, threshold=10.0, learn=False)  # nothing drops out: compare the errors
        list(feed(matcher, demo))
        results[error] = {f: e[(arms.up,)] for f, e in matcher.inspect()["trace"] if (arms.up,) in e}
    late = max(results["moving"])
    assert results["moving"][late] == pytest.approx(2 * results["mean"][late], rel=0.02)
    assert results["moving"][late] > 0.3  # about √2 x 0.3 m


def test_unexplained_answers_unknown_without_a_length(arms):
    """Inwards and down, 135 degrees from both edges: each prediction is about 1.85 times as far off as predicting
    that nothing moves, so with ``unexplained = 1`` neither explains the demonstration: unknown, whatever the ceiling.
    ``out`` itself is explained (its error is a small share of its extent) and committed early."""
    rest = arms.motor.rest[2]
    away = demonstration(arms, stroke_path(rest, [-0.25, -0.25, 0.0]))
    matcher = use(arms, **{**NEW, "ceiling": 10.0, "learn": False})
    assert all(a is None for a in feed(matcher, away))
    assert matcher.conclude(away).movement is None
    arms.motor.reset()
    shown = demonstration(arms, stroke_path(rest, [0.3, 0.0, 0.0]))
    commit = next(a for a in feed(use(arms, **{**NEW, "learn": False}), shown) if a is not None)
    assert commit.path == (arms.out,) and commit.decided_at < 0.5 * shown.n_frames
    # 0 keeps the ceiling's decision: the same demonstration under a ceiling of 10 m is the race's leader
    arms.motor.reset()
    matcher = use(arms, **{**NEW, "unexplained": 0.0, "ceiling": 10.0, "learn": False})
    list(feed(matcher, away))
    assert matcher.conclude(away).movement is not None


def test_the_lead_clock_predicts_badly_a_command_whose_parts_move_otherwise(arms):
    """``both`` moves the left wrist as ``out`` does and the right wrist 30 cm too. The demonstration moves only the
    left: with every part on its own clock, ``both``'s right wrist is predicted where it is seen (it has walked no
    path), so ``both`` predicts as well as ``out``; on the lead's clock it is predicted 30 cm away at the end."""
    from plugins.lib.guiding_stroke import GuidingStroke

    motor = arms.motor
    left, right = motor.rest[2], motor.rest[3]
    both = motor.learn("wrists", "hub", [GuidingStroke(left, left + [0.3, 0.0, 0.0], 1.0),
                                         GuidingStroke(right, right + [0.0, -0.3, 0.0], 1.0)])
    demo = demonstration(arms, stroke_path(left, [0.3, 0.0, 0.0]))
    last = {}
    for clock in ("parts", "lead"):
        motor.reset()
        matcher = use(arms, clock=clock, threshold=10.0, learn=False)
        list(feed(matcher, demo))
        last[clock] = matcher.inspect()["trace"][-1][1]
    assert last["parts"][(both,)] < 0.02
    assert last["lead"][(both,)] > 0.25 and last["lead"][(arms.out,)] < 0.02


# -- the scenario on generated data -----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    from plugins.bench.data import make_data
    from toolkit import create_plugin_manager
    from toolkit.observe import compose_observer
    from toolkit.recordings.profile import load_profile

    pm = create_plugin_manager(autoload=False, trace=False)
    data = make_data(pm, tmp_path_factory.mktemp("styles"), seed=5, streams=1, per_stream=2)
    profile = load_profile(data / "profile.toml")
    demos = [(folder.name, profile.read(sorted(folder.iterdir())[0], None))
             for folder in sorted((data / "demos").iterdir()) if folder.is_dir()]
    observers = {name: compose_observer(pm, profile, data / "repertoire", matcher="forward-model",
                                        settings={"matcher": dict(s)}) for name, s in (("paper", {}), ("new", NEW))}
    return profile, demos, observers


def styled(motion, *, scale: float = 1.0, offset=(0.0, 0.0, 0.0)):
    """``motion`` performed by another body: every part ``scale`` times as far from the root, then moved by
    ``offset`` (m), the root where it was."""
    from toolkit import Motion

    p = motion.positions.copy()
    root = p[:, :1].copy()
    p = root + (p - root) * scale + np.asarray(offset)
    p[:, :1] = root
    return Motion(p, motion.fps, motion.parts, visible=motion.visible)


def recognised(generated, which: str, **style) -> float:
    from toolkit.observe import Observer

    profile, demos, observers = generated
    character = observers[which]
    right = [Observer(character, profile.body, m.fps).classify(styled(m, **style)).movement == name
             for name, m in demos]
    return float(np.mean(right))


def test_a_larger_body_is_recognised_by_the_new_settings_and_not_by_the_papers(generated):
    """Morris's movements performed by a body 1.25 times as large: every prediction in positions is off by a quarter
    of the body from the first frames, so the paper's drop-out leaves nothing; displacements from the onset,
    weighted by the parts that move, with the candidates racing, find the movement."""
    paper, new = recognised(generated, "paper", scale=1.25), recognised(generated, "new", scale=1.25)
    assert paper <= 0.2 and new >= 0.75


def test_another_stance_is_recognised_more_often_and_the_plain_demonstrations_no_less(generated):
    offset = (0.0, -0.03, 0.02)  # 3 cm lower and 2 cm forward: another stance
    assert recognised(generated, "new", offset=offset) > recognised(generated, "paper", offset=offset)
    assert recognised(generated, "new") >= recognised(generated, "paper")


def test_with_relative_a_demonstration_seen_at_rest_begins_at_the_hub_not_where_the_last_movement_ended(arms):
    """After ``out`` the wrists' subsystem is in ``out``'s end node. A demonstration that begins at rest (the body
    went back without being followed) begins at the hub with ``relative`` too, as with positions: another stance is
    off one's own states by centimetres, the end of ``out`` by 30 cm. Seen at ``out``'s end, it begins there."""
    motor = arms.motor
    end = motor.edge(arms.out).target
    rest = motor.rest[2]
    for start, expected in ((rest + [0.0, 0.02, 0.0], "hub"), (rest + [0.3, 0.02, 0.0], end)):
        motor.reset()
        motor.move_to("wrists", end)
        matcher = use(arms, **{**NEW, "learn": False})
        list(feed(matcher, demonstration(arms, stroke_path(start, [0.0, 0.2, 0.0]))))
        assert matcher.inspect()["start_node"] == expected
