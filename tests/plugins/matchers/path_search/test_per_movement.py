"""Path search's exact search (plugins.matchers.path_search.per_movement): every movement's own best path.

The warping is pinned to its definition (every path enumerated through small cost matrices of plain chains; a
reference written again for cyclic ones); the matcher then finds, on the stick figure, a movement the
k-best beam loses, and performances four times slower and faster than its own.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from plugins.matchers.path_search.per_movement import posegraph_chains
from plugins.lib.compiled import kernel
from plugins.matchers.warping import _warp, _warp_path
from tests.plugins.matchers.path_search.stick import FPS, STICK, observed
from toolkit import Motion, load_character

PER_MOVEMENT = """
[matcher]
plugin = "path-search"
search = "per-movement"
"""


def enumerated(cost: np.ndarray) -> float:
    """By enumeration, for a plain chain: every path from any column of row 0 to any column of the last row with
    steps (i-1, j-1), (i-1, j), (i, j-1); for each end column the path of least summed cost, then the least of those
    sums over their paths' lengths (the warping chooses by sum and divides at the end)."""
    n, m = cost.shape
    least: dict[int, tuple[float, int]] = {}

    def walk(i, j, total, length):
        if i == n - 1 and (j not in least or total < least[j][0]):
            least[j] = (total, length)
        if i + 1 < n:
            walk(i + 1, j, total + cost[i + 1, j], length + 1)
            if j + 1 < m:
                walk(i + 1, j + 1, total + cost[i + 1, j + 1], length + 1)
        if i > 0 and j + 1 < m:  # the same sample on along the chain (not from the first row: a path starts anywhere)
            walk(i, j + 1, total + cost[i, j + 1], length + 1)

    for j in range(m):
        walk(0, j, cost[0, j], 1)
    return min(total / length for total, length in least.values())


def cyclic_reference(cost: np.ndarray) -> float:
    """For a cyclic chain, the same as a plain chain laid out twice over (a path may go round once within a sample
    row and come back to the first node from the last), by dynamic programming row by row: each cell the least sum
    of its three predecessors, the column after the last being the first."""
    n, m = cost.shape
    total = np.full((n, m), np.inf)
    length = np.zeros((n, m))
    total[0], length[0] = cost[0], 1
    for i in range(1, n):
        for sweep in range(2):  # the row settles in two sweeps round the cycle
            for j in range(m):
                p = (j - 1) % m
                options = [(total[i - 1, j], length[i - 1, j])]
                if m > 1:
                    options += [(total[i - 1, p], length[i - 1, p]), (total[i, p], length[i, p])]
                s, ln = min(options, key=lambda o: o[0])
                if s + cost[i, j] < total[i, j]:
                    total[i, j], length[i, j] = s + cost[i, j], ln + 1
    return float((total[-1] / length[-1]).min())


@settings(max_examples=200)
@given(st.integers(1, 6).flatmap(lambda n: st.tuples(
    arrays(np.float64, (n, 5), elements=st.floats(0.0, 3.0)), st.lists(st.integers(1, 3), min_size=1, max_size=3),
    st.booleans())))
def test_each_chains_distance_is_its_least_mean_cost_path(case):
    """Random costs over chains of 1-3 nodes, plain or cyclic: each chain's distance is the enumeration's (plain) or
    the reference's (cyclic)."""
    cost, sizes, cyclic = case
    sizes = sizes[: cost.shape[1]] or [1]
    width = sum(sizes)
    cost = np.tile(cost, (1, 3))[:, :width]
    cost = np.ascontiguousarray(cost + 1e-7 * np.sqrt(np.arange(2, cost.size + 2)).reshape(cost.shape))  # no ties
    starts = np.concatenate([[0], np.cumsum(sizes)]).astype(np.intp)
    cyc = np.array([cyclic] * len(sizes))
    best = np.empty(len(sizes))
    end = np.empty(len(sizes), dtype=np.intp)
    _warp(cost, starts, cyc, best, end, np.empty(len(sizes)))
    for c in range(len(sizes)):
        block = cost[:, starts[c] : starts[c + 1]]
        want = cyclic_reference(block) if cyclic else enumerated(block)
        assert best[c] == pytest.approx(want, abs=1e-12)


@settings(max_examples=100)
@given(arrays(np.float64, st.tuples(st.integers(1, 7), st.integers(1, 6)), elements=st.floats(0.0, 3.0)),
       st.booleans())
def test_the_compiled_warping_is_the_reference_and_its_path_ends_where_the_best_does(cost, cyclic):
    """The compiled kernels give the reference's numbers; the path kept aligns every sample with a node of the
    chain, and a plain chain's nodes never go back."""
    cost = np.ascontiguousarray(cost)
    starts = np.array([0, cost.shape[1]], dtype=np.intp)
    got, want = np.empty(1), np.empty(1)
    end_got, end_want = np.empty(1, dtype=np.intp), np.empty(1, dtype=np.intp)
    adv_got, adv_want = np.empty(1), np.empty(1)
    kernel(_warp)(cost, starts, np.array([cyclic]), got, end_got, adv_got)
    _warp(cost, starts, np.array([cyclic]), want, end_want, adv_want)
    assert got[0] == want[0] and end_got[0] == end_want[0] and adv_got[0] == adv_want[0]
    out, ref = np.empty(len(cost), dtype=np.intp), np.empty(len(cost), dtype=np.intp)
    kernel(_warp_path)(cost, cyclic, out)
    _warp_path(cost, cyclic, ref)
    assert out.tolist() == ref.tolist()
    assert ((0 <= out) & (out < cost.shape[1])).all()
    assert out[-1] == end_want[0]
    if not cyclic:
        assert (np.diff(out) >= 0).all()
    # the frames the path advanced over (the pace's numerator): its steps along the chain, a loop's included
    assert adv_want[0] == (np.diff(out) % cost.shape[1]).sum()


@pytest.fixture
def stick(write, pm):
    return load_character(write("stick.toml", STICK.replace('[matcher]\nplugin = "path-search"\n', PER_MOVEMENT)), pm)


def test_the_chains_are_the_takes_without_hubs(stick):
    chains = posegraph_chains(stick.motor)
    assert chains.movements == ("raise", "reach")
    assert [len(chains.chain(c)) for c in range(2)] == [9, 9]
    assert not chains.cyclic.any()
    names = stick.motor.nodes
    assert [names[i] for i in chains.chain(0)] == stick.motor.paths["raise"][1:-1]


def test_a_movement_whose_middle_frame_lies_elsewhere_is_still_found(stick):
    """The glitched raise that the k-best beam with k = 1 spends half on the reach (test_kbest.py): every movement
    keeps its own best path, and the raise's is nearest."""
    motion = observed(stick, "raise")
    positions = motion.positions.copy()
    mid = motion.n_frames // 2
    hand = stick.body.index("hand")
    positions[mid - 1 : mid + 2, hand] = stick.motor.key_poses["front"][hand] - stick.motor.key_poses["front"][0]
    match = stick.matcher.match(Motion(positions, FPS, motion.parts, motion.visible))
    assert match.movement == "raise"
    assert {stick.motor.movement_of(n) for n in match.path} == {"raise"}


@pytest.mark.parametrize("speed", [0.25, 0.5, 2.0, 4.0])
def test_a_performance_four_times_slower_or_faster_than_ones_own_is_found(stick, speed):
    """Slower: the samples stay on nodes; faster: one sample passes several nodes. Either way the raise is nearest,
    much nearer than the reach, with no limit on either to set."""
    stick.matcher.params = {**stick.matcher.params, "candidates": 1}
    match = stick.matcher.match(observed(stick, "raise", speed=speed))
    assert match.movement == "raise"
    (first, near), (second, far) = match.candidates
    assert first == "raise" and second == "reach" and near < 0.25 * far


def test_an_unknown_answer_still_ranks_the_candidates(stick):
    """What ``likeme observe`` explains an "unknown" with: the movements ranked by the score the decision read, the
    nearest first, as a known answer ranks them."""
    from plugins.matchers.decision import Distance

    stick.matcher.params = {**stick.matcher.params, "candidates": 1}
    known = stick.matcher.match(observed(stick, "raise"))
    stick.matcher.decision = Distance(1e-12)  # nothing is near enough
    match = stick.matcher.match(observed(stick, "raise"))
    assert match.movement is None and match.nearest == "raise"
    assert [name for name, _ in match.candidates] == [name for name, _ in known.candidates] == ["raise", "reach"]


def test_the_paths_nodes_follow_the_movement_in_order(stick):
    match = stick.matcher.match(observed(stick, "reach", speed=0.5))
    path = match.path
    order = {n: i for i, n in enumerate(stick.motor.paths["reach"])}
    steps = [order[n] for n in path]
    assert steps == sorted(steps)
    assert len(set(steps)) >= 7  # it walks the movement, not one pose


def test_distances_are_eq_1_per_aligned_pair(stick):
    """1 cm off at the hand all along: every aligned pair costs eq. 1 = 0.01 / 5 at least (the best path can only
    be farther, where its samples fall between nodes)."""
    match = stick.matcher.match(observed(stick, "reach", offset=(0.01, 0.0, 0.0)))
    assert match.movement == "reach"
    assert match.details["mean_distance"] >= 0.01 / 5 - 1e-12
    assert match.details["mean_distance"] < 0.01 / 5 + 0.01
