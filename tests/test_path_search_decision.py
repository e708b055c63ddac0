"""Path search's decision with the styled comparison (issue 18): ``spread_quantile`` (which of a movement's take
distances is its spread) and ``still_spread`` (the spreads measured as ``posture = "still"`` compares a match).

The repertoire is Morris's generated clips of a few movements, two takes each (speeds 0.8 and 1.25, with observation
noise); the demonstrations are his third takes (speed 1.0), performed from another stance and larger, of the same
movements or of one left out.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.toolkit.test_relative_lengths import generated  # noqa: F401  (the generated recordings, a module fixture)
from toolkit import create_plugin_manager
from toolkit.observe import Observer
from toolkit.observe import compose_observer
from toolkit.profile import load_profile

MOVEMENTS = ("wave", "reach", "clap", "bow", "knock")
LEFT_OUT = "knock"
DECISION = {"posture": "still", "amplitude": 2.0, "still_spread": True, "spread_quantile": 1.0, "spread": 1.0}
"""The styled comparison with each movement accepted as far as its own farthest take lies from the others."""


@pytest.fixture(scope="module")
def takes(generated, tmp_path_factory):
    """A repertoire folder of links to Morris's takes at speeds 0.8 and 1.25 of each of :data:`MOVEMENTS` but
    :data:`LEFT_OUT`."""
    folder = tmp_path_factory.mktemp("takes")
    for movement in MOVEMENTS:
        if movement == LEFT_OUT:
            continue
        (folder / movement).mkdir()
        for clip in sorted((generated / "demos" / movement).glob("*.bvh")):
            if clip.stem.endswith("_1.0"):
                continue
            (folder / movement / clip.name).symlink_to(clip)
    return folder


def observer(generated, takes, **matcher):
    pm = create_plugin_manager(autoload=False, trace=False)
    character = compose_observer(pm, load_profile(generated / "profile.toml"), takes,
                                 settings={"matcher": matcher})
    character.matcher._refresh()
    return character


def test_the_spread_is_the_chosen_quantile_of_the_take_distances(generated, takes):
    """Two takes: the median is halfway between their distances, the quantile 1 the larger, 0.75 three quarters of
    the way (numpy's linear interpolation between the sorted distances)."""
    spreads = {q: observer(generated, takes, spread=1.0, spread_quantile=q).matcher for q in (0.5, 0.75, 1.0)}
    distances = spreads[0.5].take_distances
    assert set(distances) == set(MOVEMENTS) - {LEFT_OUT}
    for movement, d in distances.items():
        low, high = sorted(d)
        assert len(d) == 2 and 0 < low <= high
        assert spreads[0.5].spreads[movement] == pytest.approx((low + high) / 2)
        assert spreads[0.75].spreads[movement] == pytest.approx(low + 0.75 * (high - low))
        assert spreads[1.0].spreads[movement] == pytest.approx(high)
        assert spreads[1.0].take_distances[movement] == d  # the quantile chooses; the distances are the same
        assert spreads[1.0].threshold(movement) == pytest.approx(high)  # spread = 1: the farthest take itself


def test_still_spread_changes_nothing_unless_the_posture_is_still(generated, takes):
    kept = observer(generated, takes, spread=2.0).matcher
    assert observer(generated, takes, spread=2.0, still_spread=True).matcher.take_distances == kept.take_distances


def test_with_still_spread_the_spreads_shrink_as_the_matches_distances_do(generated, takes):
    """``posture = "still"`` compares a demonstration without its stance, so its distances are smaller than with
    the posture kept; spreads measured as built (posture kept) are larger than the matches they judge, and those
    measured as compared are not."""
    built = observer(generated, takes, spread=1.0, posture="still").matcher
    compared = observer(generated, takes, spread=1.0, posture="still", still_spread=True).matcher
    for movement in built.spreads:
        assert compared.spreads[movement] <= built.spreads[movement] + 1e-12


@settings(max_examples=5, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(offset=st.tuples(*[st.floats(-0.2, 0.2)] * 3))
def test_a_stance_held_through_one_take_leaves_that_takes_distance_unchanged(generated, takes, offset):
    """Invariance: a part held still through a take (its stillness 1) has its whole posture removed from the take
    and, by the same share, from every other take, so holding it anywhere else (``offset``) does not change the
    take's distance to the rest of the graph. Measured as built (posture kept) it does."""
    def distance(still_spread: bool, shift) -> float:
        character = observer(generated, takes, spread=1.0, posture="still", still_spread=still_spread)
        motor, matcher = character.motor, character.matcher
        rows = np.array([motor.nodes.index(n) for n in motor.takes()["wave"][0]])
        head = character.body.index("head")
        poses = motor.node_root_relative.copy()
        poses[rows, head] = poses[rows, head].mean(axis=0) + np.asarray(shift)  # held still, then moved
        motor.node_root_relative = poses
        matcher._cache_version = -1
        matcher._refresh()
        return matcher.take_distances["wave"][0]

    assert distance(True, offset) == pytest.approx(distance(True, (0.0, 0.0, 0.0)), abs=1e-9)
    if np.linalg.norm(offset) > 0.05:
        assert distance(False, offset) != pytest.approx(distance(False, (0.0, 0.0, 0.0)), abs=1e-6)


def styled(motion, stance: np.ndarray, scale: float):
    """``motion`` (world positions) performed from another stance (``stance`` added to each part about the root)
    and ``scale`` times as large about each part's mean position."""
    from toolkit import Motion

    mean = np.nanmean(motion.positions, axis=0)
    return Motion(mean + (motion.positions - mean) * scale + stance, motion.fps, motion.parts, motion.visible)


WIDE = {"left_knee": (0.04, 0.0, 0.0), "right_knee": (-0.04, 0.0, 0.0), "left_foot": (0.06, 0.0, 0.0),
        "right_foot": (-0.06, 0.0, 0.0)}
"""Another stance: knees 4 cm and feet 6 cm further out (the parts that take no part in these movements)."""


def test_a_styled_known_movement_is_accepted_and_a_movement_left_out_is_unknown(generated, takes):
    """Scenario: Morris's third take of each movement, performed from a wide-legged stance (:data:`WIDE`) and 1.2 times
    as large. With the styled comparison and each movement's farthest take as its limit,
    every known movement is recognised and his knock, left out of the repertoire, is unknown. The paper's comparison
    with the same limit rejects the styled known movements too."""
    profile = load_profile(generated / "profile.toml")
    character = observer(generated, takes, **DECISION)
    paper = observer(generated, takes, spread=1.0, spread_quantile=1.0)  # the posture kept, as performed
    stance = np.zeros((len(profile.body.parts), 3))
    for part, offset in WIDE.items():
        stance[profile.body.parts.index(part)] = offset
    answers, kept = {}, {}
    for movement in MOVEMENTS:
        motion = styled(profile.read(next((generated / "demos" / movement).glob("*_1.0.bvh"))), stance, 1.2)
        answers[movement] = Observer(character, profile.body, motion.fps).classify(motion).movement
        kept[movement] = Observer(paper, profile.body, motion.fps).classify(motion).movement
    assert answers == {m: (None if m == LEFT_OUT else m) for m in MOVEMENTS}
    assert all(m is None for m in kept.values())


def test_with_still_spread_a_takes_distance_is_the_take_compared_as_a_demonstration(generated, takes):
    """By hand: the take loses its own stillness's share of each part's take posture (plugins.lib.style), every node
    loses the same share of its take's posture, and the take's distance is eq. 3 per sample along the best path that
    avoids its own nodes."""
    from plugins.lib.pose_distance import path_distance
    from plugins.lib.style import stillness

    character = observer(generated, takes, spread=1.0, posture="still", still_spread=True)
    motor, matcher = character.motor, character.matcher
    body = character.body.n_parts
    rows = np.array([matcher.node_names.index(n) for n in motor.takes()["clap"][1]])
    kept, posture = matcher._nodes_kept, matcher._take_posture
    share = stillness(kept[rows, :body], np.ones((len(rows), body), bool), posture[rows[0]])
    assert share.min() == pytest.approx(0.0) and share.max() <= 1.0  # the most moving part keeps its posture
    nodes = kept.copy()
    nodes[:, :body] -= share[None, :, None] * posture
    exclude = np.zeros(len(nodes), bool)
    exclude[rows] = True
    matcher.nodes_compared = nodes
    path, _, evidence = matcher.search(nodes[rows], np.ones(nodes[rows].shape[:2], bool), None, exclude)
    matcher.nodes_compared = kept
    by_hand = path_distance(nodes[rows], nodes[path], np.ones(nodes[rows].shape[:2], bool)) / evidence
    assert matcher.take_distances["clap"][1] == pytest.approx(by_hand, rel=1e-12)
