"""The warping advanced sample by sample with each take at its own pace so far (plugins.matchers.pacing): the
kernel against the reference written out, the same numbers whatever the samples come in, and a performance three
times slower than its take followed at the take's tempo."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.matchers.comparison import Frames, Motion
from plugins.matchers.pacing import PRIOR, PacedWarping, followed_scores
from plugins.matchers.decision import relative_scores
from plugins.matchers.warping import Chains, chain_stills, relative_distances
from tests.plugins.matchers.reference import followed_score
from tests.plugins.matchers.test_tempo import RATE, _frames, _waving


@settings(max_examples=40, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 9), st.lists(st.integers(1, 6), min_size=1, max_size=3),
       st.sampled_from([0.6, 1.1]), st.sampled_from([0.0, 0.7, 1.1]), st.booleans(), st.sampled_from([0.0, 2.0, 5.0]))
def test_each_chain_is_followed_at_its_pace_as_the_reference_writes_it_out(seed, n, lengths, seen, carried, loops,
                                                                         prior):
    """Random frames (parts unseen, carries unknown), chains some of which loop: after the last sample each chain's
    score is the reference's (each sample played at the pace the chain's best path has gone so far, warped step by
    step), for priors of none, two and five samples."""
    rng = np.random.default_rng(seed)
    samples = _frames(rng, n, 4, 6, seen, carried)
    samples = samples.take(samples.seen.any(axis=1))  # a sample with nothing seen is not given to the warping
    if not len(samples):
        return
    nodes = _frames(rng, sum(lengths), 4, 6, 1.1, carried)
    chains = Chains.of_lengths(lengths, [f"m{k}" for k in range(len(lengths))],
                               cyclic=[loops and k % 2 == 0 for k in range(len(lengths))])
    warping = PacedWarping(Motion(), nodes, chains, rate=prior / PRIOR)
    followed = warping.advance(samples)
    got = followed.distance[-1] / followed.moved[-1]
    want = [followed_score(Motion(), samples, nodes, chains, k, prior) for k in range(len(chains))]
    np.testing.assert_allclose(got, want, rtol=1e-6)  # the sums over a frame's features in single precision


@settings(max_examples=25, deadline=None)
@given(st.integers(0, 2**32 - 1), st.lists(st.integers(1, 4), min_size=1, max_size=5))
def test_the_numbers_after_each_sample_do_not_depend_on_how_the_samples_came_in(seed, blocks):
    """The samples given one block after another (sizes drawn) or all at once: bit for bit the same distances,
    distances to standing still and ends after every sample, and the same paces (a forward model fed rows one by
    one or at once answers the same)."""
    rng = np.random.default_rng(seed)
    samples = _frames(rng, sum(blocks), 5, 6, 1.1, 1.1)
    nodes = _frames(rng, 12, 5, 6, 1.1, 1.1)
    chains = Chains.of_lengths([5, 7], ["a", "b"], cyclic=[False, True])
    whole = PacedWarping(Motion(), nodes, chains, RATE)
    at_once = whole.advance(samples)
    parts = PacedWarping(Motion(), nodes, chains, RATE)
    pieces, start = [], 0
    for size in blocks:
        pieces.append(parts.advance(samples.take(slice(start, start + size))))
        start += size
    for name in ("distance", "moved", "ends"):
        np.testing.assert_array_equal(np.concatenate([getattr(p, name) for p in pieces]), getattr(at_once, name))
    np.testing.assert_array_equal(parts.pace, whole.pace)


@pytest.mark.parametrize("slower", [2.0, 3.0])
def test_a_performance_slower_than_its_take_is_followed_at_the_takes_tempo(slower):
    """A wave performed two or three times as slowly as its take, followed sample by sample: the wave's pace
    settles near 1 / slower, and the wave explains it far better than standing still does, where the warping at
    the demonstrator's own tempo leaves it nearer standing still at three times as slow."""
    take, still = _waving(3.0), _waving(3.0, travel=0.0, reach=0.0)
    nodes, chains = Frames.join([take, still]), Chains.of_lengths([len(take), len(still)], ["wave", "still"])
    demonstration = _waving(3.0, slower)
    warping = PacedWarping(Motion(), nodes, chains, RATE)
    followed = warping.advance(demonstration)
    scores = followed.distance[-1] / followed.moved[-1]
    assert warping.pace[0] == pytest.approx(1 / slower, rel=0.2)
    assert scores[0] < 0.3 < 0.99 < scores[1]
    plain = relative_distances(Motion(), demonstration, nodes, chains)
    assert scores[0] < 0.5 * plain[0]
    takes = chain_stills(Motion(), nodes, chains.starts)  # the calibration's scores: relative to the larger motion
    np.testing.assert_allclose(followed_scores(Motion(), demonstration, nodes, chains, rate=RATE),
                               relative_scores(followed.distance[-1], followed.moved[-1], takes))


def test_a_chain_left_out_is_infinitely_far_and_positions_cannot_be_paced():
    take, still = _waving(2.0), _waving(2.0, travel=0.0, reach=0.0)
    nodes, chains = Frames.join([take, still]), Chains.of_lengths([len(take), len(still)], ["wave", "still"])
    scores = followed_scores(Motion(), take, nodes, chains, np.array([False, True]), rate=RATE)
    assert scores[0] == pytest.approx(0.0, abs=1e-4) and np.isinf(scores[1])  # single precision's rounding, rooted
    from plugins.matchers.comparison import Poses

    with pytest.raises(ValueError, match="scales with tempo"):
        PacedWarping(Poses(), nodes, chains, RATE)
