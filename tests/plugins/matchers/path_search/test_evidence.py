"""What the per-movement search scores takes by (plugins.matchers.path_search.evidence): the motion comparison
alone, or with the takes' strokes, each evidence weighed by how well the repertoire's takes show it separates the
movements.

The weights and the calibration are pinned to their formulas on hand-written scores; on generated hand gestures
(two takes of each movement, other people and styles as demos) the strokes tell waves from raises that the motion
alone does not; with one take of each movement the strokes weigh nothing and the answers are the motion's.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.bench.gestures import MOVEMENTS
from plugins.matchers.decision import Calibration
from plugins.matchers.strokes_evidence import MOST_SEPARATION, evidence_weights
from tests.plugins.matchers.hands import HANDS, LOW_RAISE, holding, waving
from toolkit import ConfigError, load_character
from toolkit.observe import Observer, compose_observer

STROKES = {"matcher": {"comparison": "motion+strokes"}}


def _rows(own: float, other: float, takes: int = 2, movements: int = 2) -> tuple[np.ndarray, list[str]]:
    """Scores of ``takes`` takes of each of ``movements`` movements against each other: ``own`` between two takes
    of one movement, ``other`` between movements, ``inf`` on the diagonal."""
    labels = [f"m{i}" for i in range(movements) for _ in range(takes)]
    same = np.equal.outer(labels, labels)
    rows = np.where(same, own, other).astype(float)
    np.fill_diagonal(rows, np.inf)
    return rows, labels


def test_each_evidence_weighs_its_separation_over_its_spacing():
    """Motion: own 0.5, other 0.6; strokes: own 0.1, other 0.8: weights in the ratio log(1.2) / 0.6 to
    log(8) / 0.8, summing to 1."""
    motion, labels = _rows(0.5, 0.6)
    strokes, _ = _rows(0.1, 0.8)
    expected = np.array([np.log(1.2) / 0.6, np.log(8.0) / 0.8])
    assert evidence_weights([motion, strokes], labels) == pytest.approx(expected / expected.sum())


@pytest.mark.parametrize(("own", "other", "expected"), [
    (0.9, 0.6, [1.0, 0.0]),     # the strokes' takes lie as far apart as movements: they weigh nothing
    (0.0, 0.8, None),           # two copies of one clip: the most separation counts, not an infinite one
])
def test_an_evidence_that_separates_nothing_weighs_nothing_and_copies_do_not_weigh_everything(own, other, expected):
    motion, labels = _rows(0.3, 0.6)
    strokes, _ = _rows(own, other)
    weights = evidence_weights([motion, strokes], labels)
    if expected is None:
        expected = np.array([np.log(2.0) / 0.6, MOST_SEPARATION / 0.8])
        expected = expected / expected.sum()
    assert weights == pytest.approx(expected)


@pytest.mark.parametrize("case", ["one take of each", "one movement", "nothing separates"])
def test_where_the_takes_show_no_separation_the_motion_decides_alone(case):
    rows = {"one take of each": _rows(0.2, 0.6, takes=1), "one movement": _rows(0.2, 0.6, movements=1),
            "nothing separates": _rows(0.7, 0.6)}[case]
    assert evidence_weights([rows[0], rows[0]], rows[1]).tolist() == [1.0, 0.0]


@settings(max_examples=100, deadline=None)
@given(st.lists(st.sampled_from("abc"), min_size=1, max_size=7).flatmap(lambda labels: st.tuples(
    st.just(labels), arrays(np.float64, (len(labels), len(labels)), elements=st.floats(0.0, 2.0)))))
def test_the_calibration_of_rows_is_each_takes_nearest_own_and_other(case):
    """Each take's row, itself left out: own is the least of its movement's other takes, other the least of every
    other movement's takes; takes with neither give nothing."""
    labels, rows = case
    rows = rows.copy()
    np.fill_diagonal(rows, 5.0)  # never read
    got = Calibration.of_rows(rows, labels)
    own = [min(rows[c, d] for d in range(len(labels)) if d != c and labels[d] == labels[c]) for c in range(len(labels))
           if labels.count(labels[c]) > 1]
    other = [min(rows[c, d] for d in range(len(labels)) if labels[d] != labels[c]) for c in range(len(labels))
             if len(set(labels)) > 1]
    assert got == Calibration.of(own, other)


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
