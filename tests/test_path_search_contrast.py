"""Path search attending to what tells one's own movements apart (issue 18, distinct18): ``contrast`` (each
movement's nodes weigh the parts on which it differs from the other movements) and ``rivals`` (the best candidates
compared again, pair by pair, on the parts that tell each pair apart), on the stick of ``test_path_search`` with a
third movement worked out by hand: ``kickwave`` kicks the left knee 0.6 m forward while the hand rises half as high
as in ``raise`` (0.3 m)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tests.test_path_search import FPS, STICK, observed
from toolkit import Motion, load_character

KICKWAVE = """
[motor.poses.kw]
base = "stand"
lk = [0.1, 0.5, 0.6]
hand = [0.3, 1.3, 0.0]

[motor.movements.kickwave]
keys = [{ pose = "stand", at = 0.0 }, { pose = "kw", at = 0.5 }, { pose = "stand", at = 1.0 }]

"""
LUNGE = KICKWAVE.replace("lk = [0.1, 0.5, 0.6]", "lk = [0.1, 0.5, 0.3]").replace("hand = [0.3, 1.3, 0.0]",
                                                                                  "hand = [0.45, 1.6, 0.0]")
"""The kickwave of the rivals' test: the knee only 0.3 m forward, the hand as high as the raise's but 0.15 m to the
side. So the raise and the kickwave differ twice as much at the knee as at the hand, and each is the other's nearest
movement (0.45 m summed at the top, against 0.6 m from the hub)."""
ROOT, HEAD, LK, RK, HAND = range(5)


def stick_with(write, pm, three: bool | str = True, **matcher):
    extra = "".join(f"{k} = {json.dumps(v)}\n" for k, v in matcher.items())
    third = LUNGE if three == "lunge" else KICKWAVE
    text = STICK.replace("[matcher]", third + "[matcher]") if three else STICK
    return load_character(write("stick.toml", text + extra), pm)


def rows(stick, movement: str) -> list[int]:
    return [stick.motor.nodes.index(n) for n in stick.motor.takes()[movement][0]]


def test_a_part_that_lies_alike_in_every_movement_gets_the_floor_weight(write, pm):
    """Raise and reach differ only at the hand: the root, head and knees (the same in both, and at the hub) weigh
    the floor (1 - contrast) / 5 = 0.1 in every movement's nodes, the hand the rest; hubs weigh every part alike."""
    stick = stick_with(write, pm, three=False, contrast=0.5)
    matcher = stick.matcher
    for movement in ("raise", "reach"):
        assert matcher.contrasts[movement][:4] == pytest.approx(np.zeros(4), abs=1e-12)
        assert matcher.contrasts[movement][HAND] > 0.1
        w = matcher.node_weights[rows(stick, movement)]
        assert w == pytest.approx(np.tile([0.1, 0.1, 0.1, 0.1, 0.6], (len(w), 1)))
    hub = stick.motor.nodes.index(stick.motor.paths["raise"][0])
    assert matcher.node_weights[hub] == pytest.approx(np.full(5, 0.2))


def test_each_movement_weighs_the_parts_it_differs_on_from_its_nearest_other_movement(write, pm):
    """Without its own nodes a raise is nearest the hub (hand only, 0.6 m at the top; the kickwave is as far at the
    hand and 0.6 m at the knee as well), so its weights go to the hand; the kickwave is 0.6 m from the hub at the knee
    and 0.3 m at the hand (less along the raise, whose hand passes 0.3 m on its way), so its knee weighs most, its
    hand more than the floor, and the parts no movement moves the floor."""
    stick = stick_with(write, pm, contrast=0.5)
    matcher = stick.matcher
    raise_w = matcher.node_weights[rows(stick, "raise")][0]
    assert raise_w == pytest.approx([0.1, 0.1, 0.1, 0.1, 0.6])
    kick = matcher.contrasts["kickwave"]
    assert kick[[ROOT, HEAD, RK]] == pytest.approx(np.zeros(3), abs=1e-12)
    assert kick[LK] > kick[HAND] > 0.0
    expect = 0.1 + 0.5 * kick / kick.sum()
    assert matcher.node_weights[rows(stick, "kickwave")][0] == pytest.approx(expect)
    assert expect[LK] > expect[HAND] > 0.1


def raise_with_a_kick(stick) -> Motion:
    """A raise performed with the left knee going 0.5 m forward as the hand rises (a style): at the top 0.5 m from
    the raise at the knee; 0.3 m from the kickwave at the hand and 0.1 m at the knee."""
    motion = observed(stick, "raise")
    positions = motion.positions.copy()
    positions[:, LK, 2] += positions[:, HAND, 1] / 0.6 * 0.5
    return Motion(positions, FPS, motion.parts, motion.visible)


def test_a_raise_differing_from_its_own_nodes_only_where_no_movement_is_told_apart_by_it_is_a_raise(write, pm):
    """Eq. 1's plain mean takes the styled raise for the kickwave (0.4 m against 0.5 m summed over the parts at the
    top); with ``contrast = 0.5`` the raise's nodes weigh the knee at the floor, the kickwave's weigh it most, and the
    raise is recognised."""
    plain = stick_with(write, pm, max_distance=10.0)
    assert plain.matcher.match(raise_with_a_kick(plain)).movement == "kickwave"
    contrast = stick_with(write, pm, max_distance=10.0, contrast=0.5)
    match = contrast.matcher.match(raise_with_a_kick(contrast))
    assert match.movement == "raise"
    # and the movements performed as the stick does them are still themselves, at distance 0
    for movement in ("raise", "reach", "kickwave"):
        own = contrast.matcher.match(observed(contrast, movement))
        assert own.movement == movement and own.details["mean_distance"] == pytest.approx(0.0, abs=1e-9)


def kickwave_from_a_raise(stick) -> Motion:
    """The rivals' kickwave performed with the hand straight up as in the raise and the knee only 0.2 m forward: at
    the top 0.2 m from the raise at the knee; 0.1 m from the kickwave at the knee and 0.15 m at the hand."""
    motion = observed(stick, "kickwave")
    positions = motion.positions.copy()
    positions[:, LK, 2] *= 2 / 3
    positions[:, HAND, 0] = 0.3
    return Motion(positions, FPS, motion.parts, motion.visible)


def test_rivals_compared_on_what_tells_the_two_apart_find_the_kickwave(write, pm):
    """The raise is nearest by eq. 1's plain mean (0.2 against 0.25 summed over the parts at the top); the kickwave
    is the runner-up. The two differ twice as much at the knee as at the hand, so compared on those parts alone (the
    knee weighing about 2/3, the hand 1/3; the parts where they agree not at all) the kickwave is nearer
    (0.1 x 2/3 + 0.15 / 3 < 0.2 x 2/3) and wins the pair."""
    plain = stick_with(write, pm, "lunge", max_distance=10.0, candidates=1)
    match = plain.matcher.match(kickwave_from_a_raise(plain))
    assert match.movement == "raise" and match.candidates[1][0] == "kickwave"
    rivals = stick_with(write, pm, "lunge", max_distance=10.0, rivals=2)
    match = rivals.matcher.match(kickwave_from_a_raise(rivals))
    assert match.movement == "kickwave" and match.details["rivals"] == {"raise": 0, "kickwave": 1}
    pair = rivals.matcher.pair_contrast("raise", "kickwave")
    assert pair[[ROOT, HEAD, RK]] == pytest.approx(np.zeros(3), abs=1e-12)
    assert pair[LK] > 1.5 * pair[HAND] > 0.0  # less than twice: the best path stays on a node now and then
    assert rivals.matcher.pair_contrast("kickwave", "raise") is pair
    assert all(n in rivals.motor.paths["kickwave"] for n in match.path if not rivals.motor.graph.nodes[n]["hub"])
    for movement in ("raise", "reach", "kickwave"):
        assert rivals.matcher.match(observed(rivals, movement)).movement == movement


def test_by_default_every_node_weighs_every_part_alike(write, pm):
    """The paper: no weights, no pair compared again."""
    stick = stick_with(write, pm)
    assert stick.matcher.node_weights is None and stick.matcher.contrasts == {}
    match = stick.matcher.match(raise_with_a_kick(stick))
    assert "rivals" not in match.details
