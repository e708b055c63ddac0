"""A demonstration compared at each take's tempo (plugins.matchers.tempo): the costs with the motion rescaled, the
pace from the warping, and a slow performance that a held pose explained better than its own movement."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.matchers.comparison import Frames, Motion, Poses
from plugins.matchers.tempo import TEMPO, paced_distances, paces
from plugins.matchers.warping import Chains, relative_distances

RATE = 10.0


def _frames(rng, n: int, parts: int, dims: int, seen: float, carried: float) -> Frames:
    return Frames(rng.normal(size=(n, parts, dims)), rng.random((n, parts)) < seen, rng.normal(size=(n, 5)),
                  rng.random(n) < carried)


def _played(frames: Frames, speed: float, motion: slice) -> Frames:
    """``frames`` with their motion and travel multiplied by ``speed``, written out."""
    parts, carry = frames.parts.copy(), frames.carry.copy()
    parts[..., motion] *= speed
    carry[:, :3] *= speed
    return Frames(parts, frames.seen, carry, frames.carried)


@settings(max_examples=60, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from(["mean", "none"]), st.integers(1, 6), st.integers(1, 7),
       st.sampled_from([0.6, 1.1]), st.sampled_from([0.0, 0.5, 1.1]))
def test_the_paired_costs_are_the_comparisons_costs_of_the_demonstration_played_at_each_speed(
        seed, shape, n, m, seen, carried):
    rng = np.random.default_rng(seed)
    comparison = Motion(shape)
    dims, motion = (6, slice(3, 6)) if shape == "mean" else (3, slice(0, 3))
    a, b = _frames(rng, n, 4, dims, seen, carried), _frames(rng, m, 4, dims, seen, carried)
    paired = comparison.paired(a, b)
    np.testing.assert_allclose(paired.at(1.0), comparison.costs(a, b), atol=1e-12)
    speed = rng.uniform(1 / TEMPO, TEMPO, m)
    want = np.column_stack([comparison.costs(_played(a, s, motion), b.take([j]))[:, 0] for j, s in enumerate(speed)])
    np.testing.assert_allclose(paired.at(speed), want, atol=1e-12)
    still = comparison.still_at(a, speed[:2])
    for k, s in enumerate(speed[:2]):
        np.testing.assert_allclose(still[:, k], comparison.still(_played(a, s, motion)), atol=1e-12)


def test_positions_have_no_tempo():
    rng = np.random.default_rng(0)
    a, b = _frames(rng, 5, 3, 3, 1.1, 0.0), _frames(rng, 4, 3, 3, 1.1, 0.0)
    paired = Poses().paired(a, b)
    np.testing.assert_array_equal(paired.at(np.full(4, 3.0)), Poses().costs(a, b))


def test_the_pace_is_frames_advanced_per_step_between_samples_within_the_limit():
    np.testing.assert_allclose(paces(np.array([9.0, 3.0, 0.0, 90.0]), 10), [1.0, 1 / 3, 1 / TEMPO, TEMPO])
    np.testing.assert_array_equal(paces(np.array([0.0, 5.0]), 1), [1.0, 1.0])


def _waving(seconds: float, slower: float = 1.0, travel: float = 1.2, reach: float = 0.3) -> Frames:
    """A body walking forward at ``travel`` m/s while its hand waves at 1 Hz, ``slower`` times as slowly (the same
    places, each velocity divided by it), sampled at 10 Hz, in body sizes of 1."""
    t = np.arange(int(seconds * slower * RATE)) / RATE / slower
    poses = np.zeros((len(t), 3, 3))
    poses[:, 1] = [0.0, 0.6, 0.0]
    poses[:, 2] = np.column_stack([reach * np.sin(2 * np.pi * t), np.full(len(t), 0.3), np.zeros(len(t))])
    velocity = np.zeros_like(poses)
    velocity[:, 2, 0] = reach * 2 * np.pi * np.cos(2 * np.pi * t) / slower
    moving = np.zeros((len(t), 3))
    moving[:, 2] = travel / slower
    return Motion().frames(poses, np.ones(poses.shape[:2], dtype=bool), RATE, velocity=velocity, travel=moving,
                           heading=np.zeros(len(t)), size=1.0)


@pytest.mark.parametrize("slower", [2.0, 3.0, 4.0])
def test_a_performance_up_to_four_times_slower_than_its_take_is_compared_at_the_takes_tempo(slower):
    """Against a take of the wave and a take of standing still, a wave performed three times as slowly: frame by
    frame its velocities lie nearer standing still, which explains it better than the wave does (score above 1 at
    three times as slow); at the wave's tempo it is the wave, at the pace it was performed at."""
    take, still = _waving(3.0), _waving(3.0, travel=0.0, reach=0.0)
    nodes, chains = Frames.join([take, still]), Chains.of_lengths([len(take), len(still)], ["wave", "still"])
    demonstration = _waving(3.0, slower)
    plain = relative_distances(Motion(), demonstration, nodes, chains)
    paced = paced_distances(Motion(), demonstration, nodes, chains)
    assert paced.pace[0] == pytest.approx(1 / slower, rel=0.15)
    assert paced.scores[0] < 0.2 < 0.99 < paced.scores[1]
    assert paced.scores[0] < 0.5 * plain[0]
    if slower >= 3.0:
        assert plain[0] > plain[1]  # what the plain comparison answered: standing still


def test_at_its_own_tempo_a_take_is_itself_and_a_left_out_chain_is_infinitely_far():
    take, still = _waving(2.0), _waving(2.0, travel=0.0, reach=0.0)
    nodes, chains = Frames.join([take, still]), Chains.of_lengths([len(take), len(still)], ["wave", "still"])
    paced = paced_distances(Motion(), take, nodes, chains, skip=np.array([False, True]))
    assert paced.scores[0] == pytest.approx(0.0, abs=1e-6) and paced.pace[0] == pytest.approx(1.0)  # sqrt of rounding
    assert np.isinf(paced.scores[1]) and np.isinf(paced.distances[1]) and paced.pace[1] == 1.0
    assert paced.cost.shape == (len(take), len(nodes)) and (paced.cost[:, len(take):] == 0).all()


def test_the_jitter_is_taken_out_of_both_distances_squared():
    """plugins.matchers.tempo.less_jitter by hand: the demonstration's noise at each chain's pace (its motion's
    noise over the pace squared) and the chain's own, squared, out of the distance; the demonstration's alone out of
    its distance to standing still, which never falls below its noise."""
    from plugins.matchers.tempo import less_jitter

    def frames(noise):
        n = len(noise)
        return Frames(np.zeros((n, 1, 6)), np.ones((n, 1), dtype=bool), np.zeros((n, 5)), np.zeros(n, dtype=bool),
                      np.asarray(noise, dtype=float))

    samples = frames([[0.01, 0.04], [0.01, 0.04]])
    chains = frames([[0.01, 0.01], [0.01, 0.01], [0.0, 0.0]])  # chain 0: frames 0-1; chain 1: frame 2
    found, moving = less_jitter(np.array([0.5, 0.3]), np.array([1.0, 0.1]), samples, chains,
                                np.array([0, 2, 3]), np.array([1.0, 2.0]))
    own = np.array([0.01 + 0.04, 0.01 + 0.04 / 4])
    assert found == pytest.approx(np.sqrt([0.25 - own[0] - 0.02, 0.09 - own[1] - 0.0]))
    assert moving == pytest.approx(np.sqrt([1.0 - own[0], own[1]]))  # 0.1 moves less than its noise
