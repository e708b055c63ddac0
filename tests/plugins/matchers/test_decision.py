"""The decisions matchers share (plugins.matchers.decision), and path search's calibration on its repertoire."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from plugins.matchers.decision import Calibrated, Calibration, Distance, Stillness, relative_scores
from toolkit import load_character
from toolkit.observe import Observer, compose_observer
from toolkit.recordings.profile import load_profile
from tests.plugins.matchers.path_search.stick import STICK, observed
from tests.plugins.matchers.reference import left_out_scores

scores = st.lists(st.floats(0.0, 5.0), max_size=30)


def test_distance_is_the_papers_limit_and_zero_is_none():
    decision = Distance(0.03)
    assert decision.threshold() == 0.03
    assert decision.decide("wave", 0.029).movement == "wave"
    verdict = decision.decide("wave", 0.031)
    assert verdict.movement is None and verdict.nearest == "wave" and verdict.score == 0.031
    assert Distance(0.0).threshold() == np.inf and Distance(0.0).decide("wave", 1e9).movement == "wave"
    assert decision.decide(None, 0.0).movement is None  # nothing came near


@given(scores, scores, st.floats(0.0, 1.0))
def test_the_calibrated_threshold_is_the_gaps_far_side_else_the_own_else_the_others_quantile_at_most_one(own, other,
                                                                                                         rate):
    decision = Calibrated(rate)
    decision.calibrate(Calibration.of(own, other))
    if own and other and np.quantile(own, 1.0 - rate) <= np.quantile(other, rate):
        assert decision.threshold() == min(np.quantile(other, rate), 1.0)
    elif own:
        assert decision.threshold() == min(np.quantile(own, 1.0 - rate), 1.0)
    else:
        assert decision.threshold() == (min(np.quantile(other, 1.0 - rate), 1.0) if other else 1.0)


def test_a_gap_between_own_takes_and_other_movements_puts_unknown_at_its_far_side():
    """Two takes of each movement, each pair nearer each other than any other movement comes: at most 5% of
    movements like the repertoire's own are taken for known (and at most 5% of the own takes rejected)."""
    decision = Calibrated(0.05)
    decision.calibrate(Calibration.of([0.17, 0.19, 0.24, 0.25, 0.36], [0.66, 0.69, 0.70, 0.73, 0.76]))
    assert decision.threshold() == pytest.approx(np.quantile([0.66, 0.69, 0.70, 0.73, 0.76], 0.05))
    assert decision.decide("walk", 0.6, 1.0).movement == "walk"  # a styled walk between the two
    assert decision.decide("walk", 0.7, 1.0).movement is None  # as far as the repertoire's other movements lie
    decision.calibrate(Calibration.of([0.17, 0.70], [0.66, 0.69, 0.70, 0.73, 0.76]))  # overlap: no gap
    assert decision.threshold() == pytest.approx(np.quantile([0.17, 0.70], 0.95))  # the own takes'


def test_without_a_gap_the_own_takes_set_unknown_not_the_farthest_other_movement():
    """Takes by two people that lie as far apart as some movements do (no gap): all but 5% of a known movement's
    performances are taken for it as far as its takes show (the own scores' 95th percentile, split-conformal); a new
    movement beyond that is unknown although another movement of the repertoire lies as far from its neighbours."""
    own, other = [0.30, 0.35, 0.42, 0.48, 0.55, 0.60], [0.40, 0.52, 0.70, 0.85, 0.95, 0.98]
    decision = Calibrated(0.05)
    decision.calibrate(Calibration.of(own, other))
    assert decision.threshold() == pytest.approx(np.quantile(own, 0.95))
    assert decision.decide("walk", 0.58, 1.0).movement == "walk"  # a performance as far as the two people's
    assert decision.decide("walk", 0.80, 1.0).movement is None  # a new movement: once accepted below 0.98
    assert decision.threshold() < np.quantile(other, 0.95)


def test_the_calibrated_score_is_the_share_left_unexplained():
    """The distance to the nearest movement over the distance to standing still: unit-free, so the same
    demonstration measured in other units (both distances scaled) gets the same verdict."""
    decision = Calibrated(0.5)
    decision.calibrate(Calibration.of([0.2, 0.25, 0.3], [0.6, 0.7, 0.8]))
    assert decision.threshold() == pytest.approx(0.7)
    for unit in (1.0, 100.0):
        assert decision.decide("wave", 0.5 * unit, 1.0 * unit).movement == "wave"
        assert decision.decide("wave", 0.75 * unit, 1.0 * unit).movement is None
    assert decision.decide("wave", 0.0, 0.0).movement == "wave"  # nothing to explain, nothing left unexplained
    assert decision.decide("wave", 0.1, 0.0).movement is None


@given(st.lists(st.tuples(*(st.floats(low, 5.0, allow_subnormal=False) for low in (0.0, 0.01, 0.0))), min_size=1,
                max_size=8))
def test_relative_scores_rank_as_the_share_of_the_demonstrations_motion_over_the_larger_of_the_nearest_pair(rows):
    """Each chain's (distance, the demonstration's motion at its pace, the take's motion): the scores rank as
    distance over the demonstration's motion, and the nearest's is its distance over the larger of the pair's
    motions (a half-size performance leaves the same share of the take unexplained as the take would of it)."""
    distances, moving, takes = (np.array(column) for column in zip(*rows))
    got = relative_scores(distances, moving, takes)
    ratio = distances / moving
    k = int(np.argmin(ratio))
    assert got[k] == pytest.approx(distances[k] / max(moving[k], takes[k]))
    np.testing.assert_allclose(got, ratio / max(1.0, takes[k] / moving[k]))
    assert int(np.argmin(got)) == k
    half = relative_scores(np.array([0.5]), np.array([0.5]), np.array([1.0]))  # half the take's motion, half missing
    assert half[0] == pytest.approx(0.5) and relative_scores(np.array([0.5]), np.array([1.0]), np.array([0.5]))[0] \
        == pytest.approx(0.5)
    assert relative_scores(np.array([0.0, 1.0]), np.array([0.0, 0.0]), np.array([1.0, 1.0])).tolist() == [np.inf] * 2


def test_calibration_keeps_finite_scores_only():
    assert Calibration.of([0.1, np.inf, np.nan], [np.inf, 0.5]) == Calibration((0.1,), (0.5,))


THIRD = """
[motor.poses.knee]
base = "stand"
lk = [0.1, 0.8, 0.3]

[motor.movements.kick]
keys = [{ pose = "stand", at = 0.0 }, { pose = "knee", at = 0.5 }, { pose = "stand", at = 1.0 }]
"""

REAL_PEOPLE = """
[matcher]
plugin = "path-search"
comparison = "motion"
search = "per-movement"
decision = "calibrated"
"""


@pytest.fixture
def stick(write, pm):
    text = STICK.replace("[matcher]", THIRD + "\n[matcher]", 1)
    text = text.replace('[matcher]\nplugin = "path-search"\n', REAL_PEOPLE)
    return load_character(write("stick.toml", text), pm)


def test_with_one_take_of_each_movement_path_search_calibrates_by_leaving_each_movement_out(stick):
    """One take each: no take to leave out of its own movement; each movement left out in turn gives how near a
    movement the repertoire does not hold comes: its take's distance to the nearest other movement over its
    distance to standing still, each at the other movement's tempo. The threshold is their 95th percentile
    (known_rejected = 0.05), at most 1."""
    matcher = stick.matcher
    calibration = matcher.decision.calibration
    assert calibration.own == ()
    search = matcher.searcher
    want = left_out_scores(matcher.comparison, search.takes, search.nodes, search.chains, paced=True)
    assert calibration.other == pytest.approx(want)
    assert matcher.decision.threshold() == pytest.approx(min(np.quantile(want, 0.95), 1.0))


def test_a_known_movement_performed_otherwise_is_taken_for_it_and_a_new_one_is_unknown(stick):
    """Against the stick's raise, reach and kick (one take each): its raise performed slower and with the hand held
    higher is a raise; a movement it does not know (the hand swung out to the side and back, twice) is unknown,
    with the raise or the reach as the nearest and the score above the threshold."""
    styled = observed(stick, "raise", speed=0.6, offset=(0.0, 0.1, 0.0))
    match = stick.matcher.match(styled)
    assert match.movement == "raise" and match.score <= match.threshold
    new = observed(stick, "raise")
    positions = new.positions.copy()
    t = np.linspace(0.0, 1.0, new.n_frames)
    hand = stick.body.index("hand")
    positions[:, hand] = positions[0, hand] + np.stack([0.4 * np.sin(2 * np.pi * 2 * t), 0 * t, 0 * t], axis=1)
    unknown = stick.matcher.match(type(new)(positions, new.fps, new.parts, new.visible))
    assert unknown.movement is None and unknown.reason == "too far from every path"
    assert unknown.score > unknown.threshold and unknown.nearest in ("raise", "reach", "kick")


def test_a_wave_with_half_the_takes_motion_leaves_half_of_it_unexplained():
    """A wave with half the take's reach and travel (a style that moves less): over its own motion alone the wave
    explained it hardly better than standing still (score above 0.9); over the larger of the pair's
    motions half of the take is left unexplained, as a wave twice the take's size leaves half of itself."""
    from plugins.matchers.comparison import Frames, Motion
    from plugins.matchers.tempo import paced_distances
    from plugins.matchers.warping import Chains
    from tests.plugins.matchers.test_tempo import _waving

    take, still = _waving(3.0), _waving(3.0, travel=0.0, reach=0.0)
    nodes, chains = Frames.join([take, still]), Chains.of_lengths([len(take), len(still)], ["wave", "still"])
    half, double = _waving(3.0, travel=0.6, reach=0.15), _waving(3.0, travel=2.4, reach=0.6)
    small, large = (paced_distances(Motion(), d, nodes, chains) for d in (half, double))
    assert small.scores[0] == pytest.approx(0.5, abs=0.05) and large.scores[0] == pytest.approx(0.5, abs=0.05)
    assert small.distances[0] / np.mean(Motion().still(half)) > 0.9  # over its own motion: near standing still
    assert small.scores[0] < small.scores[1] and large.scores[0] < large.scores[1]  # the wave, not standing still


@pytest.fixture(scope="module")
def generated(tmp_path_factory):
    """The project's generated recordings: Max's movements (one take each), Morris's versions of them."""
    from plugins.bench.data import make_data
    from toolkit import create_plugin_manager

    pm = create_plugin_manager(autoload=False, trace=False)
    return pm, make_data(pm, tmp_path_factory.mktemp("generated"), seed=3, streams=1, per_stream=2)


def test_with_two_takes_the_own_takes_count_too(generated, tmp_path):
    """A repertoire of two takes of each movement (Max's take and a Morris take): each take left out of its own
    movement gives an own score, and the threshold is at least their 95th percentile."""
    pm, folder = generated
    profile = load_profile(folder / "profile.toml")
    repertoire = tmp_path / "two"
    for movement in sorted(p.name for p in (folder / "repertoire").iterdir()):
        (repertoire / movement).mkdir(parents=True)
        (repertoire / movement / "max.bvh").symlink_to(folder / "repertoire" / movement / "max.bvh")
        morris = sorted((folder / "demos" / movement).glob("*.bvh"))[0]
        (repertoire / movement / "morris.bvh").symlink_to(morris)
    character = compose_observer(pm, profile, repertoire)
    decision = character.matcher.decision
    movements = len(list(repertoire.iterdir()))
    assert len(decision.calibration.own) == 2 * movements and len(decision.calibration.other) == 2 * movements
    assert decision.threshold() >= np.quantile(decision.calibration.own, 0.95)
    observer = Observer(character, profile.body, 30.0)
    demos = sorted((folder / "demos").glob("*/*.bvh"))
    right = [observer.classify(profile.read(p, None)).movement == p.parent.name for p in demos]
    assert np.mean(right) >= 0.9


def test_stillness_holds_half_way_to_the_least_moving_movement():
    """A movement that does not move at all holds still; a demonstration is it when it moves at most half as much
    as the least moving other movement (no moving one can then come nearer than standing still)."""
    s = Stillness.of({"stand": 0.0, "nod": 0.3, "wave": 0.9, "sway": 1e-12})
    assert s.still == {"stand", "sway"} and s.limit == pytest.approx(0.15)
    assert s.holds("stand", 0.15) and not s.holds("stand", 0.151) and not s.holds("nod", 0.0)
    assert not Stillness.of({"nod": 0.3, "wave": 0.9}).holds("nod", 0.0)
    assert Stillness.of({"stand": 0.0}).holds("stand", 5.0)  # nothing moving to be nearer
    assert not Stillness().holds(None, 0.0)
