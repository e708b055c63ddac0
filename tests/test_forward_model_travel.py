"""The forward model's travel (issue 18): where the body goes, predicted and compared like one more part.

Kopp & Graeser's motor commands move parts relative to the root (root-relative coordinates, B&B §5.1), so a step
to the left and a step to the right with the same leg swings are the same commands. ``forward-model``'s ``travel``
adds the root's displacement over ``travel`` seconds in the body's own frame: the motor command graph keeps where
the body went while each command was shown (``Edge.travel``), the forward model predicts it at the point of the
command it predicts the parts at, and compares it with the travel seen. These tests check that clips' edges carry
their travel, that travel tells apart movements whose root-relative poses are the same (and only travel does), that
a learned graph with travel is saved and loaded, and that the default (0, the paper) compares the parts alone.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import STICK_PARTS, write_stick_clip, write_stick_profile
from toolkit import ConfigError, Motion, create_plugin_manager
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile

PARTS = STICK_PARTS
STAND = np.array([[0.0, 1.0, 0.0], [0.0, 1.6, 0.1], [0.1, 0.5, 0.0], [-0.1, 0.5, 0.0], [0.3, 1.0, 0.0],
                  [0.1, 0.0, 0.0], [-0.1, 0.0, 0.0]])
SIDE = 0.6  # m/s: a side step's pace



def _side_steps(frames: int, vx: float, fps: float = 30.0) -> np.ndarray:
    """Side steps (world positions, heading 0: the body's frame is the world's): the feet lift and swing out and
    back once while the hand swings up; the root travels sideways at ``vx`` m/s (+x: the body's left). The
    root-relative poses do not depend on ``vx``."""
    k = np.arange(frames)
    phase = np.sin(np.pi * k / (frames - 1))
    pose = np.repeat(STAND[None], frames, axis=0).copy()
    pose[:, 5, 1] += 0.15 * phase  # the left foot lifts
    pose[:, 5, 0] += 0.2 * phase   # and swings out
    pose[:, 6, 0] -= 0.1 * phase
    pose[:, 4, 1] += 0.3 * phase   # the hand swings up
    pose[:, :, 0] += vx * (k / fps)[:, None]
    return pose


def _raise(frames: int = 30) -> np.ndarray:
    pose = np.repeat(STAND[None], frames, axis=0).copy()
    pose[:, 4, 1] += 0.5 * np.sin(np.linspace(0, np.pi, frames))
    pose[:, 4, 2] += 0.3 * np.sin(np.linspace(0, np.pi, frames))
    return pose


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    """A repertoire: ``left`` and ``right`` (the same side steps, the body travelling to its left and to its right)
    and ``raise`` (a gesture on the spot); and a profile."""
    root = tmp_path_factory.mktemp("fmtravel")
    write_stick_clip(root / "repertoire" / "left" / "a.bvh", _side_steps(40, SIDE))
    write_stick_clip(root / "repertoire" / "right" / "a.bvh", _side_steps(40, -SIDE))
    write_stick_clip(root / "repertoire" / "raise" / "a.bvh", _raise())
    write_stick_profile(root)
    return root


def _observer(clips, **matcher):
    pm = create_plugin_manager(autoload=False, trace=False)
    profile = load_profile(clips / "profile.toml")
    return profile, compose_observer(pm, profile, clips / "repertoire", matcher="forward-model",
                                     lengths_for_height=0, settings={"matcher": {"learn": False, **matcher}})


def _answers(clips, **matcher) -> dict[str, object]:
    profile, observer = _observer(clips, **matcher)
    watch = Observer(observer, profile.body, 30.0)
    out = {}
    for movement, vx in (("left", SIDE), ("right", -SIDE)):
        observer.motor.reset()
        out[movement] = watch.classify(Motion(_side_steps(44, vx), 30.0, PARTS)).match  # a little slower
    return out


def test_a_clips_edges_carry_where_the_body_went(clips):
    _, observer = _observer(clips)
    motor = observer.motor
    for movement, vx in (("left", SIDE), ("right", -SIDE), ("raise", 0.0)):
        (sequence,) = [n for n, label in motor.labels.items() if label == movement]
        for name in motor.sequences[sequence]:
            edge = motor.edge(name)
            assert edge.travel.shape == (len(edge.shown), 3)
            inner = edge.travel[2:-2] if len(edge.travel) > 6 else edge.travel  # the ends' one-sided differences
            assert np.allclose(inner, [vx, 0.0, 0.0], atol=0.05)


@pytest.mark.parametrize("dropout", ["absolute", "relative"])
def test_travel_tells_a_step_left_from_a_step_right_and_nothing_else_does(clips, dropout):
    """Their root-relative poses are the same, so their commands are: without travel both demonstrations get the
    same answer (or none); with travel each is itself, and the other movement's prediction is worse by the travel."""
    plain = _answers(clips, dropout=dropout)
    assert plain["left"].movement == plain["right"].movement or not (plain["left"].known and plain["right"].known)
    travelled = _answers(clips, dropout=dropout, travel=0.5)
    assert travelled["left"].movement == "left" and travelled["right"].movement == "right"


def test_travel_is_compared_as_one_more_part_of_the_error(clips):
    """With ``error = mean`` a movement whose travel is off by ``d`` m over the horizon is predicted ``d / (k + 1)``
    worse than with travel left out (k parts and the travel part, the parts' mean weighing k / (k + 1)); the
    movement that travels as the demonstration does is not worse. (The nodes of the two steps are shared, so a
    path may leave one step's edges for the other's: the first command of each is compared.)"""
    best = {}
    for travel in (0.0, 0.5):
        profile, observer = _observer(clips, dropout="relative", error="mean", travel=travel, ratio=100.0)
        Observer(observer, profile.body, 30.0).classify(Motion(_side_steps(44, SIDE), 30.0, PARTS))
        for frame, errors in observer.matcher.inspect()["trace"]:
            for path, error in errors.items():
                if len(path) == 1:
                    key = (travel, frame, observer.motor.label_of_path(path))
                    best[key] = min(best.get(key, np.inf), error)
    k = len(observer.motor.subsystems["body"])
    frames = [frame for frame in sorted({frame for _, frame, label in best if label == "right"} &
                                        {frame for _, frame, label in best if label == "left"})
              if frame >= 8]  # once the travel is seen: a quarter of a second (8 frames) after the onset
    assert frames
    for frame in frames:
        for label, expected in (("left", 0.0), ("right", 2 * SIDE * 0.5 / (k + 1))):
            gap = best[0.5, frame, label] - best[0.0, frame, label] * k / (k + 1)
            assert gap == pytest.approx(expected, abs=0.1 * SIDE * 0.5 / (k + 1))


def test_the_default_compares_the_parts_alone(clips):
    profile, observer = _observer(clips, dropout="relative")
    Observer(observer, profile.body, 30.0).classify(Motion(_side_steps(44, SIDE), 30.0, PARTS))
    track = observer.matcher.main
    assert track.travel_seen is None and observer.matcher._edge(track.initial[0]).travel is None


def test_a_graph_learned_with_travel_is_saved_and_loaded(clips):
    """Edges learned by watching keep their travel through get_state and set_state (as JSON would carry it)."""
    import json

    _, observer = _observer(clips)
    motor = observer.motor
    observed = _raise(24)[:, 1:]
    travel = np.tile([0.0, 0.0, 1.0], (len(observed), 1)) + np.linspace(0, 0.2, len(observed))[:, None]
    names = motor.learn_observed("body", "hub", observed, 30.0, travel=travel)
    state = json.loads(json.dumps(motor.get_state()))
    _, fresh = _observer(clips)
    fresh.motor.set_state(state)
    for name in names:
        assert np.allclose(fresh.motor.edge(name).travel, motor.edge(name).travel, atol=1e-6)
    first = fresh.motor.edge(names[0]).travel
    assert np.allclose(first, travel[: len(first)], atol=1e-6)  # the rows of the frames it was learned from
    bad = json.loads(json.dumps(state))
    edge = next(e for e in bad["body"]["edges"] if "travel" in e)
    edge["travel"] = edge["travel"][:-1]
    with pytest.raises(ConfigError, match="invalid travel"):
        fresh.motor.set_state(bad)


def test_an_edges_travel_must_match_its_demonstration(clips):
    _, observer = _observer(clips)
    motor = observer.motor
    observed = _raise(24)[:, 1:]
    with pytest.raises(ValueError, match="travel"):
        motor.learn("body", "hub", [], shown=observed, shown_fps=30.0, travel=np.zeros((3, 3)))


def test_the_travel_seen_is_the_mean_over_a_quarter_second_and_unknown_before(clips):
    """One or two frames' velocity is mostly observation noise: the travel is left out until the segment has lasted
    the window, then it is the root's mean velocity over it, in the body's frame (the body here faces +z)."""
    profile, observer = _observer(clips, dropout="relative", travel=0.5)
    watch = Observer(observer, profile.body, 30.0)
    steps = _side_steps(44, SIDE)
    watch.classify(Motion(steps[:8], 30.0, PARTS))
    assert observer.matcher.main.travel_seen is None
    noisy = steps + np.random.default_rng(0).normal(0.0, 0.003, steps.shape)  # 3 mm of observation noise
    watch.classify(Motion(noisy[:20], 30.0, PARTS))
    assert np.allclose(observer.matcher.main.travel_seen, [SIDE * 0.5, 0.0, 0.0], atol=0.02)


def test_a_movement_learned_by_watching_keeps_where_the_body_went(clips):
    """True imitation (K&G §4.3) with travel: what no edge predicts is learned with the travel seen meanwhile."""
    profile, observer = _observer(clips, travel=0.5, learn=True, threshold=0.001)  # nothing fits: learned
    before = set(observer.motor._edges)
    match = Observer(observer, profile.body, 30.0).classify(Motion(_side_steps(44, SIDE), 30.0, PARTS)).match
    learned = [observer.motor.edge(n) for n in match.details["learned"]]
    assert learned and not before & {e.name for e in learned}
    for edge in learned:
        assert edge.travel.shape == (len(edge.shown), 3)
        assert np.allclose(edge.travel[2:-2, 0], SIDE, atol=0.05) and np.allclose(edge.travel[:, [1, 2]], 0, atol=0.05)
