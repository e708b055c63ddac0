"""Path search's ``consistency`` (issue 18): with several takes of a movement, each part's weight in eq. 1 for the
movement's nodes follows how consistent the part is between the takes.

A hand-made repertoire of the stick figure (tests/conftest.py): ``raise`` (the hand up) and ``out`` (the hand up
and out to the side), three takes each, in each of which the feet stand another way (what one performer does
besides the movement), and ``nod`` (the head), one take.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import STICK_PARTS, write_stick_clip, write_stick_profile
from toolkit import Motion, create_plugin_manager
from toolkit.observe import Observer, compose_observer
from toolkit.profile import load_profile

STAND = np.array([[0.0, 1.0, 0.0], [0.0, 1.6, 0.1], [0.1, 0.5, 0.0], [-0.1, 0.5, 0.0], [0.3, 1.0, 0.0],
                  [0.1, 0.0, 0.0], [-0.1, 0.0, 0.0]])
HAND, FEET, HEAD = 4, [5, 6], 1
HANDS = {"raise": (0.0, 0.4, 0.0), "out": (0.6, 0.4, 0.0)}
"""Where each movement takes the hand from standing, at its height: the consistent part."""
SWINGS = {"raise": ((0.3, 0, 0), (0, 0, 0.3), (-0.3, 0, 0)), "out": ((0, 0, -0.3), (0.3, 0, 0), (0, 0.15, 0.3))}
"""Where the feet stand in each take (a different way each time): the part that varies between takes."""
FRAMES = 40


def clip(hand, feet, frames: int = FRAMES, scale: float = 1.0) -> np.ndarray:
    """World positions (frames, 7, 3): the hand goes from its standing place to ``hand`` (an offset) and back, along
    half a sine, while the feet stand ``feet`` (an offset) from their standing place throughout; everything
    ``scale`` times as large about the origin."""
    s = np.sin(np.linspace(0.0, np.pi, frames))[:, None]
    pose = np.repeat(STAND[None], frames, axis=0).copy()
    pose[:, HAND] += s * np.asarray(hand, dtype=float)
    for f in FEET:
        pose[:, f] += np.asarray(feet, dtype=float)
    return pose * scale


def repertoire(root, scale: float = 1.0):
    for movement, swings in SWINGS.items():
        for take, feet in enumerate(swings):
            write_stick_clip(root / "repertoire" / movement / f"{take}.bvh", clip(HANDS[movement], feet, scale=scale))
    nod = np.repeat(STAND[None], FRAMES, axis=0).copy() * scale
    nod[:, HEAD, 2] += 0.2 * scale * np.sin(np.linspace(0.0, np.pi, FRAMES))
    write_stick_clip(root / "repertoire" / "nod" / "0.bvh", nod)
    write_stick_profile(root)
    return root


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    return repertoire(tmp_path_factory.mktemp("consistency"))


def observer(root, lengths_for_height: float | str | None = 0, **matcher):
    pm = create_plugin_manager(autoload=False, trace=False)
    profile = load_profile(root / "profile.toml")
    character = compose_observer(pm, profile, root / "repertoire", lengths_for_height=lengths_for_height,
                                 settings={"matcher": {"max_distance": 10.0, **matcher}})
    return profile, character


def nodes_of(matcher, movement: str) -> np.ndarray:
    return np.flatnonzero(matcher.labels == movement)


@pytest.mark.parametrize("c", [1.0, 2.0])
def test_a_part_that_varies_between_takes_weighs_less_by_the_formula(made, c):
    """Every part but the feet is the same in every take (variation 0) and both feet vary alike (``v``), so over
    the P compared parts the mean variation is ``2v / P`` and a part that does not vary weighs
    ``(v + c 2v/P) / (c 2v/P) = 1 + P / (2c)`` times a foot, whatever ``v`` is; the weights have mean 1 over the
    parts."""
    _, character = observer(made, consistency=c)
    weights = character.matcher.part_weights
    parts = weights.shape[1]
    for movement in SWINGS:
        w = weights[nodes_of(character.matcher, movement)]
        assert np.allclose(w.mean(axis=1), 1.0)
        assert np.allclose(w[:, FEET], w[:, [5]])
        still = [p for p in range(parts) if p not in FEET]
        assert np.allclose(w[:, still], w[:, [HAND]])
        assert np.allclose(w[:, HAND] / w[:, 5], 1.0 + parts / (2.0 * c), rtol=1e-6)


def test_one_take_and_the_hubs_weigh_every_part_alike_and_off_is_no_weights(made):
    _, character = observer(made, consistency=1.0)
    matcher = character.matcher
    assert np.all(matcher.part_weights[nodes_of(matcher, "nod")] == 1.0)
    assert np.all(matcher.part_weights[matcher.labels == ""] == 1.0)
    assert (matcher.labels == "").any()
    assert observer(made)[1].matcher.part_weights is None


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(scale=st.floats(0.2, 5.0))
def test_the_weights_do_not_change_when_every_take_and_the_demonstration_are_scaled(tmp_path_factory, scale):
    """Every take and the demonstration ``scale`` times as large (the lengths of the posegraph and the matcher
    scaled with the body's height): each movement's weights the same, the same answer, and its mean distance
    ``scale`` times as large."""
    plain = repertoire(tmp_path_factory.mktemp("plain"))
    scaled = repertoire(tmp_path_factory.mktemp("scaled"), scale)
    answers = []
    for root, s in ((plain, 1.0), (scaled, scale)):
        profile, character = observer(root, lengths_for_height="", consistency=1.0)
        demo = Motion(clip(HANDS["raise"], (0, 0, -0.3), scale=s), 30.0, STICK_PARTS)
        matcher = character.matcher
        rows = {m: matcher.part_weights[nodes_of(matcher, m)] for m in (*SWINGS, "nod")}
        assert all(np.allclose(r, r[0]) for r in rows.values())  # one row per movement
        match = Observer(character, profile.body, 30.0).classify(demo).match
        answers.append(({m: r[0] for m, r in rows.items()}, match))
    (w1, m1), (w2, m2) = answers
    for movement in w1:
        assert np.allclose(w1[movement], w2[movement], rtol=1e-6)
    assert m1.movement == m2.movement == "raise"
    assert m2.details["mean_distance"] == pytest.approx(scale * m1.details["mean_distance"], rel=1e-4, abs=1e-9)


def test_spreads_are_measured_with_the_weights_matches_use(made):
    """With ``consistency`` a take's distance to the others is eq. 1 weighted as matches weigh the parts: the feet,
    which alone differ between takes, weigh less, so the spreads shrink."""
    plain = observer(made, spread=1.0)[1].matcher
    weighted = observer(made, spread=1.0, consistency=1.0)[1].matcher
    for movement in SWINGS:
        assert 0 < weighted.spreads[movement] < plain.spreads[movement]


def test_a_movement_told_by_its_consistent_part_is_recognised_with_consistency_and_not_without(made):
    """Scenario: the hand goes up (``raise``) while the feet stand back, as they did in one take of ``out`` and
    in no take of ``raise``. Eq. 1 over every part alike answers ``out`` (the feet are two parts, the hand one);
    with consistency the feet, which vary between every movement's takes, count less than the hand, which does not,
    and the answer is ``raise``."""
    demo = Motion(clip(HANDS["raise"], SWINGS["out"][0]), 30.0, STICK_PARTS)
    answers = {}
    for c in (0.0, 1.0):
        profile, character = observer(made, consistency=c)
        answers[c] = Observer(character, profile.body, 30.0).classify(demo).match.movement
    assert answers == {0.0: "out", 1.0: "raise"}
