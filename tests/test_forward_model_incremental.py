"""The forward model's per-frame work is incremental (issue 22); these tests hold it to the direct formulas.

Each frame the forward model needs the observed path length of every part since the onset (:func:`_lengths`: a
three-frame mean, then the summed steps) and every candidate's prediction error (:meth:`ForwardModel._error`). It
keeps what it computed from the frames before (:class:`_Walk`, the rows of :class:`_Grown`) and predicts the
one-command candidates at once (:meth:`ForwardModel._errors`). Optimised and direct must agree to the last bit,
so an answer (a drop-out at a threshold, a commitment) can never differ: here on random data (hypothesis) and on
demonstrations fed frame by frame, parts hidden at first included.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.lib.guiding_stroke import GuidingStroke
from plugins.matchers.forward_model import Track, _lengths, _Walk
from tests.test_forward_model import ARMS  # the two-wrist character; its [matcher] table last
from toolkit import Motion, load_character
from toolkit.watching import ObservationLog


FPS = 30.0
coordinates = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)


@given(st.integers(1, 6), st.lists(st.integers(1, 5), min_size=1, max_size=60), st.data())
@settings(max_examples=150, deadline=None)
def test_the_running_path_length_is_the_whole_segments_to_the_last_bit(k, steps, data):
    """:class:`_Walk`, fed a working memory that grows by a few rows at a time, gives exactly :func:`_lengths` of
    the whole of it after every step (the filter's running sum and numpy's summation order reproduced)."""
    n = sum(steps)
    observed = data.draw(arrays(np.float64, (n, k, 3), elements=coordinates))
    walk, seen = _Walk(k), 0
    for step in steps:
        seen += step
        np.testing.assert_array_equal(walk.lengths(observed[:seen]), _lengths(observed[:seen]))


def test_a_running_path_length_refuses_a_memory_that_shrank():
    walk = _Walk(1)
    walk.lengths(np.zeros((5, 1, 3)))
    with pytest.raises(ValueError, match="shrank"):
        walk.lengths(np.zeros((4, 1, 3)))


def _arms(write, pm, *, strokes: int = 4, seed: int = 0, threshold: float = 10.0):
    """The two-wrist body with ``strokes`` random one-second commands from the hub (the right wrist held still in
    every other one)."""
    text = ARMS + f'threshold = {threshold}\n'
    character = load_character(write("arms.toml", text), pm)
    motor, rng = character.motor, np.random.default_rng(seed)
    left, right = motor.rest[2], motor.rest[3]
    names = []
    for i in range(strokes):  # the right wrist moves a little, or holds still (a stroke of no length)
        held = right + (rng.normal(0, 0.05, 3) if i % 2 else 0.0)
        names.append(motor.learn("wrists", "hub", [GuidingStroke(left, left + rng.normal(0, 0.2, 3), 1.0),
                                                   GuidingStroke(right, held, 1.0)]))
    return character, names


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(lengths=arrays(np.float64, 2, elements=st.floats(0.0, 1.0)),
       last=arrays(np.float64, (2, 3), elements=coordinates),
       first=arrays(np.float64, (2, 3), elements=coordinates), order=st.randoms(use_true_random=False))
def test_candidates_predicted_at_once_are_predicted_one_by_one(write, pm, lengths, last, first, order):
    """:meth:`ForwardModel._errors` (the one-command candidates stacked) gives each candidate exactly the error
    :meth:`ForwardModel._error` gives it alone, in the candidates' order, with anchors."""
    character, names = _arms(write, pm)
    matcher = character.matcher
    paths = [(name,) for name in names] + [(names[0], names[1])]
    order.shuffle(paths)
    track = Track("wrists", 1.0, False, "hub", 0, {p: 0.0 for p in paths}, sorted(names), first=first)
    got = matcher._errors(track, paths, lengths, last)
    assert list(got) == paths
    assert got == {path: matcher._error(track, path, lengths, last) for path in paths}


def _direct_errors(matcher, observed: np.ndarray, root_height: np.ndarray, idx, paths, track) -> dict:
    """The prediction errors the direct formulas give after the frames ``observed`` (whole segment each time)."""
    local = observed + root_height
    seen = local[track.onset:, idx]
    return {path: matcher._error(track, path, _lengths(seen), seen[-1]) for path in paths}


@pytest.mark.parametrize("hidden", [False, True])
def test_frame_by_frame_errors_are_the_whole_segments(write, pm, hidden):
    """Fed a demonstration frame by frame, every candidate's error in the trace is what the direct formulas give
    on the whole segment seen so far; with the head hidden for the first frames, too (its first sighting, while the
    wrists are followed, rewrites the rows before: working memory's revision, and what was kept is recomputed)."""
    character, names = _arms(write, pm, strokes=5, seed=3)
    matcher, motor = character.matcher, character.motor
    rest = motor.rest
    n = 40
    t = np.linspace(0.0, 1.0, n)[:, None]
    frames = np.repeat(rest[None], n, axis=0)
    frames[:, 2] = rest[2] + t * np.array([0.25, 0.1, -0.05]) + 0.002 * np.sin(40 * t)
    frames[:, 3] = rest[3] + t * np.array([0.0, 0.03, 0.0])
    visible = np.ones(frames.shape[:2], dtype=bool)
    if hidden:
        visible[:10, 1] = False
        frames[:10, 1] = np.nan
    motion = Motion(frames - rest[0], FPS, character.body.parts, visible)
    log = ObservationLog(motion.parts, FPS, capacity=1)
    memory = log.since(0)
    matcher.begin(memory)
    checked = 0
    for row in range(n):
        log.extend(motion.positions[row : row + 1], motion.visible[row : row + 1])
        memory.feed(row + 1)
        matcher.observe(memory)
        # the working memory it keeps in its motor frame is the one it would compute whole
        np.testing.assert_array_equal(matcher._local(), memory.positions + matcher._root_height)
        track = matcher.tracks.get("wrists")
        if track is None or not track.trace or track.trace[-1][0] != row:
            continue
        frame, errors = track.trace[-1]
        idx = motor.subsystems["wrists"]
        direct = _direct_errors(matcher, memory.positions, matcher._root_height, idx, list(errors), track)
        assert list(errors) == list(direct)
        np.testing.assert_array_equal(list(errors.values()), list(direct.values()), err_msg=f"frame {frame}")
        checked += 1
    assert checked >= 10  # the candidates were followed for a while, across the head's first sighting
    assert (memory.revision > 0) == hidden


def _direct_anchor(matcher, track: Track, name: str) -> np.ndarray:
    """Where each part joins command ``name``: the nearest point of the first half of its stroke to where it was
    seen at the onset (the formula, one command at a time, over the whole stroke)."""
    edge = matcher._edge(name)
    far = np.linalg.norm(edge.positions - track.first[:, None], axis=-1)
    far[edge.arcs > 0.5 * edge.arcs[:, -1:]] = np.inf
    return edge.arcs[np.arange(len(far)), np.argmin(far, axis=1)]


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(first=arrays(np.float64, (2, 3), elements=st.floats(-1.0, 2.0)), seed=st.integers(0, 3))
def test_anchors_placed_at_once_are_placed_one_by_one(write, pm, first, seed):
    """The anchors of every candidate of a track, placed at once (:meth:`ForwardModel._anchor`: the strokes' first
    halves stacked), are each command's own nearest first-half point."""
    character, names = _arms(write, pm, strokes=6, seed=seed)
    matcher = character.matcher
    rest = character.motor.rest
    track = Track("wrists", 1.0, False, "hub", 0, {(name,): 0.0 for name in names}, sorted(names),
                  first=rest[2:4] + first * 0.2)
    for name in reversed(names):  # the first asked places them all
        np.testing.assert_array_equal(matcher._anchor(track, name), _direct_anchor(matcher, track, name))
    assert set(track.anchors) == set(names)


@given(seed=st.integers(0, 10_000), c=st.integers(1, 6), k=st.integers(1, 5), h=st.integers(1, 40),
       hidden=st.booleans())
@settings(max_examples=60, deadline=None)
def test_anchor_distances_from_coordinate_planes_are_the_stacked_norms_bit_for_bit(seed, c, k, h, hidden):
    """The anchors' distances (:func:`_distances`, coordinate planes) equal ``np.linalg.norm`` of the stacked
    positions exactly, a part never seen (NaN) included."""
    from plugins.matchers.forward_model import _distances

    rng = np.random.default_rng(seed)
    positions = rng.normal(size=(c, k, h, 3)) * rng.uniform(0.01, 3.0)
    first = rng.normal(size=(k, 3))
    if hidden:
        first[rng.integers(k)] = np.nan
    want = np.linalg.norm(positions - first[:, None], axis=-1)
    got = _distances(*(np.ascontiguousarray(positions[..., i]) for i in range(3)), first)
    assert np.array_equal(got, want, equal_nan=True)
