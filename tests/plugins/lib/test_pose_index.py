"""The spatial index of the posegraph's poses (plugins/lib/pose_index.py) gives exactly the exhaustive scan's k
nearest poses by eq. 1, in the scan's order, and path search answers the same with it on and off."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib import pose_index
from plugins.lib.pose_distance import pose_distance
from plugins.lib.pose_index import PoseIndex, nearest_by_scan
from toolkit import Motion, load_character


def scan(poses, query, visible, k):
    """The scan as path search wrote it: eq. 1 to every pose, a stable argsort, the first k."""
    d = pose_distance(poses, query, visible)
    order = np.argsort(d, kind="stable")[:k]
    return order, d[order]


@st.composite
def cases(draw):
    n = draw(st.integers(1, 3000))
    parts = draw(st.integers(1, 8))
    seed = draw(st.integers(0, 2**32 - 1))
    rng = np.random.default_rng(seed)
    if draw(st.booleans()):  # poses on a grid of few values: many exact ties in eq. 1
        poses = rng.integers(-2, 3, size=(n, parts, 3)).astype(float) * 0.1
    else:  # poses near a few smooth "movements", as a posegraph's are
        centres = rng.normal(0, 0.3, size=(draw(st.integers(1, 20)), parts, 3))
        poses = centres[rng.integers(len(centres), size=n)] + rng.normal(0, 0.01, size=(n, parts, 3))
    if draw(st.booleans()):  # exact duplicates of some poses
        poses[rng.integers(n, size=n // 3)] = poses[rng.integers(n, size=n // 3)]
    visible = rng.random(parts) < draw(st.sampled_from([1.0, 0.7, 0.3]))
    query = poses[rng.integers(n)] + rng.normal(0, draw(st.sampled_from([0.0, 0.005, 0.1])), size=(parts, 3))
    k = draw(st.integers(1, 40))
    return poses, query, visible, k


@settings(max_examples=150, deadline=None)
@given(cases(), st.sampled_from([1, 4, 64]), st.sampled_from([0.25, 1.0]))
def test_the_index_returns_exactly_the_scans_k_nearest_in_the_scans_order(case, first_batch, max_share):
    poses, query, visible, k = case
    saved = pose_index.FIRST_BATCH, pose_index.MAX_SHARE
    pose_index.FIRST_BATCH, pose_index.MAX_SHARE = first_batch, max_share  # 1.0: the tree answers however many
    try:  # candidates (poses on a grid, far queries)
        got = PoseIndex(poses).nearest(query, visible, k)
    finally:
        pose_index.FIRST_BATCH, pose_index.MAX_SHARE = saved
    want = scan(poses, query, visible, k)
    np.testing.assert_array_equal(got[0], want[0])
    np.testing.assert_array_equal(got[1], want[1])
    np.testing.assert_array_equal(nearest_by_scan(poses, query, visible, k)[0], want[0])


@settings(max_examples=100, deadline=None)
@given(st.integers(0, 2**32 - 1), st.integers(1, 12), st.sampled_from([1.0, 0.6, 0.2]))
def test_the_features_distance_is_a_lower_bound_of_eq_1(seed, parts, share):
    """|f(a) - f(b)| <= eq. 1(a, b) for every feature, between any two poses, not only the indexed ones."""
    rng = np.random.default_rng(seed)
    visible = rng.random(parts) < share
    visible[rng.integers(parts)] = True
    scale = rng.uniform(0.01, 1.0, size=(1, parts, 3))  # parts that move much and parts that barely move
    poses = rng.normal(0, 1, size=(300, parts, 3)) * scale
    if parts > 1:
        poses[:, 0] = 0.0  # a root that never moves: its share of every direction is zero
    index = PoseIndex(poses).tree(visible)
    blocks = np.linalg.norm(index.weights.reshape(len(index.weights), -1, 3), axis=2)
    assert np.all(blocks <= (1 + 1e-12) / visible.sum())  # each part's direction has at most unit length / S
    a, b = rng.normal(0, 1, size=(2, 200, parts, 3)) * scale
    fa = a[:, visible].reshape(200, -1) @ index.weights.T
    fb = b[:, visible].reshape(200, -1) @ index.weights.T
    assert np.all(np.abs(fa - fb).max(axis=1) <= pose_distance(a, b, visible) * (1 + 1e-12))


def test_poses_of_movements_are_answered_by_the_tree_and_a_far_query_by_the_scan():
    rng = np.random.default_rng(4)
    phase = np.linspace(0, 2 * np.pi, 60)
    base = rng.normal(0, 0.3, size=(6, 1, 11, 3))  # six movements of 11 parts, 60 poses each
    swing = rng.normal(0, 0.2, size=(6, 1, 11, 3))
    clips = base + swing * np.sin(phase)[None, :, None, None]
    takes = [clips[rng.integers(6)] * rng.uniform(0.9, 1.1) + rng.normal(0, 0.002, size=(60, 11, 3))
             for _ in range(150)]
    poses = np.concatenate(takes)  # 9,000 poses
    poses[:, 0] = 0.0  # root-relative
    index = PoseIndex(poses)
    for q in range(40):
        query = poses[rng.integers(len(poses))] + rng.normal(0, 0.003, size=(11, 3))
        visible = rng.random(11) > (0.0 if q < 30 else 0.2)
        for k in (1, 8, 40):
            got = index.nearest(query, visible, k)
            want = scan(poses, query, visible, k)
            np.testing.assert_array_equal(got[0], want[0])
            np.testing.assert_array_equal(got[1], want[1])
    assert index.scanned == 0  # every answer came from a tree
    far = np.full((11, 3), 5.0)  # as far from every pose as from each other: most poses are candidates
    got = index.nearest(far, None, 8)
    assert index.scanned == 1
    np.testing.assert_array_equal(got[0], scan(poses, far, np.ones(11, dtype=bool), 8)[0])


def test_ties_come_in_index_order_as_the_stable_argsort_gives_them():
    rng = np.random.default_rng(1)
    poses = rng.normal(0, 1, size=(2000, 5, 3))
    twin = rng.normal(0, 1, size=(5, 3))
    at = np.array([1999, 7, 1500, 300, 12, 1000])  # the same pose at six places, nearest the query
    poses[at] = twin
    index = PoseIndex(poses)
    pose_index.FIRST_BATCH, saved = 4, pose_index.FIRST_BATCH
    try:
        got, dist = index.nearest(twin + 0.001, None, 4)
    finally:
        pose_index.FIRST_BATCH = saved
    np.testing.assert_array_equal(got, [7, 12, 300, 1000])  # the four lowest of the six tied, ascending
    assert len(set(dist.tolist())) == 1


def test_one_tree_per_visibility_pattern_at_most_max_trees_kept():
    rng = np.random.default_rng(2)
    poses = rng.normal(0, 1, size=(500, 6, 3))
    index = PoseIndex(poses)
    patterns = [np.arange(6) != i for i in range(6)]
    for visible in patterns:
        index.nearest(poses[0], visible, 3)
    assert len(index._trees) == pose_index.MAX_TREES
    assert index.tree(patterns[-1]).tree.m == pose_index.FEATURES  # features of the five visible parts
    assert index.tree(patterns[-1]) is index.tree(patterns[-1])  # cached


def test_poses_that_are_not_finite_are_scanned_not_put_in_a_tree():
    rng = np.random.default_rng(3)
    poses = rng.normal(0, 1, size=(300, 4, 3))
    poses[10, 2] = np.nan
    index = PoseIndex(poses)
    got = index.nearest(poses[5], np.ones(4, dtype=bool), 5)
    want = scan(poses, poses[5], np.ones(4, dtype=bool), 5)
    np.testing.assert_array_equal(got[0], want[0])
    assert not index._trees


@pytest.fixture(scope="module")
def max_and_morris():
    from toolkit.manager import create_plugin_manager

    pm = create_plugin_manager()
    return load_character("max", pm), load_character("morris", pm)


def demonstrations(observer, demonstrator, seed):
    """Morris performing each of Max's movements he knows too, at three speeds, with 3 mm of noise and a part
    hidden now and then (the demos of ``likeme bench make-data``, plugins/bench/data.py)."""
    rng = np.random.default_rng(seed)
    shared = sorted(set(observer.motor.movements()) & set(demonstrator.motor.movements()))
    for movement in shared:
        for speed in (0.8, 1.0, 1.25):
            motion = demonstrator.motor.perform(movement, fps=30.0, speed=speed)
            motion = motion.onto(observer.body.parts).root_relative(observer.body.root)
            positions = motion.positions + rng.normal(0, 0.003, motion.positions.shape)
            visible = motion.visible & (rng.random(motion.visible.shape) > 0.1)
            yield Motion(positions, motion.fps, motion.parts, visible)


def test_path_search_answers_the_same_with_the_index_forced_on_and_off(max_and_morris, monkeypatch):
    observer, demonstrator = max_and_morris
    matcher = observer.matcher
    monkeypatch.setattr(pose_index, "FIRST_BATCH", 8)  # small batches: the tree answers, it does not fall back
    motions = list(demonstrations(observer, demonstrator, 0))
    assert len(motions) >= 10
    answers = {}
    for forced, threshold in (("on", 0), ("off", 10**9)):
        monkeypatch.setattr(matcher, "index_min_nodes", threshold)
        matcher._version = -1  # the beam is built again with the new size
        answers[forced] = [matcher.match(m) for m in motions]
        beam = matcher.searcher.kbest
        if forced == "on":
            assert beam._index is not None and beam._index._trees  # the trees answered
    assert beam._index is None  # off: never built
    for on, off in zip(answers["on"], answers["off"]):
        assert (on.movement, on.path, on.confidence) == (off.movement, off.path, off.confidence)


def test_the_benchmark_checks_every_answer_of_the_index_against_the_scan():
    from plugins.bench.posegraph_index import run
    from toolkit.manager import create_plugin_manager

    row = run(3000, parts=None, k=8, queries=20, noise=0.002, seed=0, pm=create_plugin_manager())
    assert row["agree"] == "20/20"
    assert row["nodes"] == 3000 and row["parts"] == 11 and row["index_ms"] > 0 and row["scan_ms"] > 0
    assert 0 < row["index_cpu_ms"] < 1e3
    wide = run(500, parts=14, k=3, queries=5, noise=0.0, seed=1, pm=create_plugin_manager())
    assert wide["agree"] == "5/5" and wide["parts"] == 14
