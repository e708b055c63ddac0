"""What the per-movement search scores takes by (plugins.matchers.path_search.evidence): the motion comparison
alone, or with the takes' strokes, each evidence weighed by how well the repertoire's takes show it separates the
movements.

On generated hand gestures (two takes of each movement, other people and styles as demos) the strokes tell waves
from raises that the motion alone does not; with one take of each movement the strokes weigh nothing and the answers
are the motion's (the weights' formula: ``tests/plugins/matchers/test_strokes_evidence.py``).
"""

from __future__ import annotations

import numpy as np
import pytest

from plugins.bench.gestures import MOVEMENTS
from tests.plugins.matchers.hands import HANDS, LOW_RAISE, holding, waving
from toolkit import ConfigError, load_character
from toolkit.observe import Observer, compose_observer

STROKES = {"matcher": {"comparison": "motion+strokes"}}


def _answers(pm, folder, profile, demos, settings=None):
    observer = compose_observer(pm, profile, folder / "repertoire", settings=settings)
    return observer, [Observer(observer, profile.body, m.fps).classify(m).movement for _, m in demos]


def test_the_strokes_tell_waves_from_raises_that_the_motion_does_not(pm, gestures):
    """Two takes of each of the six gestures, the demos another performer and six other styles of the first: the
    strokes weigh in (the takes show they separate the movements), and the wave/raise confusions of the motion
    alone fall by half or more."""
    folder, profile, demos = gestures
    observer, mixed = _answers(pm, folder, profile, demos, STROKES)
    assert observer.matcher.evidence.weights[1] > 0.2
    _, alone = _answers(pm, folder, profile, demos, {"matcher": {"comparison": "motion"}})
    truth = [label for label, _ in demos]

    def confused(answers):
        return sum(a is not None and a != t and a.split("_")[1] == t.split("_")[1] for a, t in zip(answers, truth))

    assert confused(mixed) <= confused(alone) / 2
    assert np.mean(np.equal(mixed, truth)) > np.mean(np.equal(alone, truth))
    assert set(MOVEMENTS) == set(truth)


def test_with_one_take_of_each_movement_the_answers_are_the_motions(write, pm):
    """Key-pose movements, one take each: the strokes weigh nothing, every score is the motion comparison's."""
    known = LOW_RAISE + holding("reach", "held", reach=0.3) + waving("long_wave", 7)
    table = '\n[matcher]\nplugin = "path-search"\nsearch = "per-movement"\ndecision = "calibrated"\n'
    alone = load_character(write("alone.toml", HANDS + known + table + 'comparison = "motion"\n'), pm)
    mixed = load_character(write("mixed.toml", HANDS + known + table + 'comparison = "motion+strokes"\n'), pm)
    assert mixed.matcher.evidence.weights.tolist() == [1.0, 0.0]
    for movement in ("wave", "low_raise", "long_wave"):
        motion = alone.motor.perform(movement, fps=30.0).root_relative(alone.body.root)
        a, b = alone.matcher.match(motion), mixed.matcher.match(motion)
        assert (a.movement, a.score, a.threshold) == (b.movement, b.score, b.threshold)


def test_the_takes_strokes_come_from_the_clips_the_posegraph_was_built_from(pm, gestures):
    """Each take of a clip repertoire is its clip, in the order of the takes; a key-pose movement's one take is its
    nodes played."""
    folder, profile, _ = gestures
    motor = compose_observer(pm, profile, folder / "repertoire", settings=STROKES).motor
    played = motor.take_motions()
    for movement in MOVEMENTS:
        clips = [clip.motion for clip in motor.clips.clips if clip.movement == movement]
        assert len(played[movement]) == len(motor.takes()[movement]) == len(clips) == 2
        assert all(a is b for a, b in zip(played[movement], clips))


def test_a_key_pose_movement_is_played_for_its_strokes(write, pm):
    motor = load_character(write("hands.toml", HANDS), pm).motor
    (wave,) = motor.take_motions(fps=30.0)["wave"]
    nodes = len(motor.takes()["wave"][0])
    assert wave.fps == 30.0 and abs(wave.n_frames - (nodes - 1) / motor.node_rate * 30.0) <= 1


def test_strokes_need_the_per_movement_search_and_the_calibrated_decision(write, pm):
    table = '\n[matcher]\nplugin = "path-search"\ncomparison = "motion+strokes"\n'
    with pytest.raises(ConfigError, match="search = 'k-best' compares poses"):
        load_character(write("k.toml", HANDS + table + 'decision = "calibrated"\n'), pm)
    with pytest.raises(ConfigError, match="decision = 'distance'"):
        load_character(write("d.toml", HANDS + table + 'search = "per-movement"\n'), pm)
