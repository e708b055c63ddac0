"""The forward model's answer at the end of a demonstration (plugins.matchers.forward_model.answer): the followed
scores alone (``comparison = "motion"``), or mixed with the takes' strokes over the whole demonstration
(``"motion+strokes"``, K&G 2006 §4.1, §4.3, §4.4).

On generated hand gestures (two takes of each movement; other people and styles as demos) the strokes tell waves
from raises that the followed motion alone does not; with one take of each movement they weigh nothing and every
answer is the motion's. The takes' motions are the positions the inverse model was given, and a take restored from a
saved state is played by its commands, with the strokes it was learned from.
"""

from __future__ import annotations

import numpy as np
import pytest

from plugins.bench.data import make_data
from plugins.bench.gestures import MOVEMENTS
from plugins.matchers.decision import Calibration
from plugins.matchers.forward_model.answer import FollowedAndStrokes, FollowedScores
from plugins.matchers.stroke_warping import strokes_still
from plugins.matchers.strokes_evidence import TakeStrokes
from toolkit import create_plugin_manager
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile

STROKES = {"matcher": {"comparison": "motion+strokes"}}
MOTION = {"matcher": {"comparison": "motion"}}


def following(character):
    return character.matcher.match.__self__


def answers(pm, folder, profile, demos, settings):
    character = compose_observer(pm, profile, folder / "repertoire", matcher="forward-model", settings=settings)
    return character, [Observer(character, profile.body, m.fps).classify(m).match for _, m in demos]


@pytest.fixture(scope="module")
def mixed(gestures):
    folder, profile, demos = gestures
    return answers(create_plugin_manager(autoload=False, trace=False), folder, profile, demos, STROKES)


def test_the_strokes_tell_waves_from_raises_that_the_followed_motion_does_not(pm, gestures, mixed):
    """The strokes weigh in (the takes show they separate the movements), and the wave/raise confusions of the
    followed motion alone fall by half or more."""
    folder, profile, demos = gestures
    character, with_strokes = mixed
    assert following(character).answer.weights[1] > 0.2
    _, alone = answers(pm, folder, profile, demos, MOTION)
    truth = [label for label, _ in demos]

    def confused(matches):
        return sum(m.movement is not None and m.movement != t and m.movement.split("_")[1] == t.split("_")[1]
                   for m, t in zip(matches, truth))

    assert confused(with_strokes) <= confused(alone) / 2
    assert np.mean([m.movement == t for m, t in zip(with_strokes, truth)]) > \
        np.mean([m.movement == t for m, t in zip(alone, truth)])
    assert set(MOVEMENTS) == set(truth)


def test_the_answer_at_the_end_has_a_calibration_of_its_own_and_commitments_keep_theirs(gestures, mixed):
    """The answer at the end is decided on the takes scored alike (the mixed rows); a commitment made while the
    demonstration came in was held to the followed motion's threshold, and stands only as the answer at the end."""
    character, matches = mixed
    f = following(character)
    assert isinstance(f.answer, FollowedAndStrokes)
    movements = f.prediction.chains.movements
    assert f.answer.decision.calibration == Calibration.of_rows(f.answer.mix.rows, movements)
    assert f.answer.decision.threshold() != f.decision.threshold()
    online, end = f.decision.threshold(), f.answer.decision.threshold()
    told = [m for m in matches if m.decided_at is not None]
    assert told and all(m.threshold == pytest.approx(online) for m in told)
    assert all(m.threshold == pytest.approx(end) for m in matches if m.decided_at is None and m.score is not None)


def test_with_one_take_of_each_movement_the_answers_are_the_followed_ones(pm, tmp_path):
    """Max's movements, one take each: the strokes weigh nothing (no clip is cut into strokes), and every answer,
    its score and its threshold, is the followed motion's."""
    data = make_data(pm, tmp_path, seed=6, streams=0, per_stream=4)
    profile = load_profile(data / "profile.toml")
    demos = [(clip.parent.name, profile.read(clip)) for clip in sorted((data / "demos").glob("*/*.bvh"))[::3]]
    mixed_character, mixed = answers(pm, data, profile, demos, STROKES)
    _, alone = answers(pm, data, profile, demos, MOTION)
    answer = following(mixed_character).answer
    assert answer.weights.tolist() == [1.0, 0.0] and answer.mix.strokes.templates == []
    assert [(m.movement, m.score, m.threshold) for m in mixed] == [(m.movement, m.score, m.threshold) for m in alone]


def test_the_followed_motion_alone_is_decided_by_the_decision_that_commits(pm, gestures):
    folder, profile, _ = gestures
    character = compose_observer(pm, profile, folder / "repertoire", matcher="forward-model", settings=MOTION)
    f = following(character)
    assert isinstance(f.answer, FollowedScores) and f.answer.decision is f.decision


def test_the_takes_motions_are_the_positions_the_inverse_model_was_given(pm, gestures):
    folder, profile, _ = gestures
    motor = compose_observer(pm, profile, folder / "repertoire", matcher="forward-model", settings=STROKES).motor
    played = motor.take_motions()
    for movement, takes in motor.takes().items():
        assert len(played[movement]) == len(takes) == 2
        for (edges, subsystem, observed, fps), motion in zip(takes, played[movement]):
            idx = motor.subsystems[subsystem]
            assert motion.fps == fps and np.array_equal(motion.positions[:, idx], observed)


def test_a_take_restored_from_a_saved_state_is_played_by_its_commands_with_its_strokes(pm, gestures):
    """A take learned by watching keeps its edges only when saved: loaded again, it is its commands played, and its
    strokes are the ones it was learned from, up to what the commands smooth away."""
    folder, profile, demos = gestures
    settings = {"matcher": {"comparison": "motion+strokes", "learn": True}}
    learner = compose_observer(pm, profile, folder / "repertoire" / "wave_left", matcher="forward-model",
                               settings=settings)
    raise_right = next(m for label, m in demos if label == "raise_right")
    assert Observer(learner, profile.body, raise_right.fps).classify(raise_right).movement == "learned-1"
    (observed,) = learner.motor.take_motions()["learned-1"]
    fresh = compose_observer(pm, profile, folder / "repertoire" / "wave_left", matcher="forward-model",
                             settings=settings)
    fresh.motor.set_state(learner.motor.get_state())
    (edges, subsystem, kept, _), = fresh.motor.takes()["learned-1"]
    (restored,) = fresh.motor.take_motions(fps=30.0)["learned-1"]
    assert kept is None and restored.fps == 30.0
    assert np.allclose(restored.positions, np.concatenate(fresh.motor.play_take(edges, subsystem, 30.0)))
    strokes = TakeStrokes(fresh.body)
    strokes.rebuild([observed])
    series = strokes.series(restored)
    assert strokes.scores(series, strokes_still(series))[0] < 0.25
