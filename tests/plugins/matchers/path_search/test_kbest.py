"""Path search's k-best beam (Buchsbaum & Blumberg 2005, §5.2) on a posegraph small enough to work out by hand
(the stick figure of :mod:`tests.plugins.matchers.path_search.stick`)."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.matchers.path_search import kbest
from tests.plugins.matchers.path_search.stick import FPS, STICK, observed
from toolkit import Motion, load_character


@pytest.fixture
def stick(write, pm):
    return load_character(write("stick.toml", STICK), pm)


def test_the_graph_is_two_paths_of_nine_nodes_through_one_hub(stick):
    motor = stick.motor
    assert motor.graph.number_of_nodes() == 1 + 2 * 9
    assert [motor.movement_of(n) for n in motor.paths["raise"]] == [None] + ["raise"] * 9 + [None]


def test_its_own_movement_is_found_on_its_own_path_at_distance_zero(stick):
    match = stick.matcher.match(observed(stick, "raise"))
    assert match.movement == "raise"
    assert match.details["mean_distance"] == pytest.approx(0.0, abs=1e-9)
    assert set(match.path) <= set(stick.motor.paths["raise"])
    assert match.details["votes"] == {"raise": sum(stick.motor.movement_of(n) == "raise" for n in match.path)}


def test_the_mean_distance_is_eq_1_per_sample_averaged_over_the_visible_parts(stick):
    """1 cm off at the hand, across the hand's path (no node is nearer): eq. 1 is 0.01 / 5 parts at every sample, and
    0.01 / 4 when the head is hidden (the mean is over the visible parts)."""
    match = stick.matcher.match(observed(stick, "reach", offset=(0.01, 0.0, 0.0)))
    assert match.movement == "reach" and match.details["mean_distance"] == pytest.approx(0.01 / 5)
    match = stick.matcher.match(observed(stick, "reach", offset=(0.01, 0.0, 0.0), hidden="head"))
    assert match.movement == "reach" and match.details["mean_distance"] == pytest.approx(0.01 / 4)
    assert match.confidence == pytest.approx(np.exp(-(0.01 / 4) / stick.matcher.params["distance"]["scale"]))


def test_farther_than_max_distance_is_unknown_not_the_nearest(stick):
    """The hand 20 cm out to the side all along: 0.2 / 5 = 0.04 m per sample, past max_distance (0.03 m)."""
    match = stick.matcher.match(observed(stick, "raise", offset=(0.2, 0.0, 0.0)))
    assert match.movement is None and match.details["reason"] == "too far from every path"
    assert match.details["nearest"] == "raise" and match.details["mean_distance"] == pytest.approx(0.04)


def test_a_path_may_skip_nodes_so_a_faster_movement_still_aligns(stick):
    """Twice as fast: each observed sample is two nodes along. With max_skip = 2 the path keeps up exactly; with
    max_skip = 1 it falls behind and every sample costs distance."""
    fast = observed(stick, "raise", speed=2.0)
    match = stick.matcher.match(fast)
    assert match.movement == "raise" and match.details["mean_distance"] == pytest.approx(0.0, abs=1e-9)
    stick.matcher.params = {**stick.matcher.params, "beam": {"k": 8, "max_skip": 1}}
    stick.matcher._version = -1  # the reach tables are rebuilt for the new max_skip
    slow = stick.matcher.match(fast)
    assert slow.details["mean_distance"] > 0.01


def test_hub_poses_do_not_vote(stick):
    stand = observed(stick, "raise").slice(0, 1)  # one frame: standing
    match = stick.matcher.match(stand)
    assert match.movement is None and match.details["reason"] == "only hub poses"


def test_k_best_from_the_middle_frame_loses_a_movement_whose_middle_is_elsewhere(stick):
    """A raise whose middle frame is glitched to the reach's forward pose: with k = 1 the only start is on the reach,
    and the beam spends half the movement there before it can get back into the raise (the per-movement search
    finds the raise: tests/plugins/matchers/path_search/test_per_movement.py)."""
    motion = observed(stick, "raise")
    positions = motion.positions.copy()
    mid = motion.n_frames // 2
    hand = stick.body.index("hand")
    positions[mid - 1 : mid + 2, hand] = stick.motor.key_poses["front"][hand] - stick.motor.key_poses["front"][0]
    glitched = Motion(positions, FPS, motion.parts, motion.visible)
    stick.matcher.params = {**stick.matcher.params, "beam": {"k": 1, "max_skip": 2},
                            "distance": {"max_distance": 10.0, "scale": 0.02}}
    stick.matcher._version = -1  # the beam is rebuilt for the new k
    narrow = stick.matcher.match(glitched)
    assert narrow.details["votes"]["reach"] >= narrow.details["votes"].get("raise", 0)  # half the path on the reach


def reference_reach(graph, nodes, index, max_skip, *, forward):
    """Each node's reach by a plain bounded breadth-first search, as compressed rows."""
    step = graph.successors if forward else graph.predecessors
    out = []
    for node in nodes:
        frontier, found = {node}, {node}
        for _ in range(max_skip):
            frontier = {m for f in frontier for m in step(f)}
            found |= frontier
        out.append(np.array(sorted(index[m] for m in found), dtype=np.intp))
    indptr = np.concatenate([[0], np.cumsum([len(r) for r in out])]).astype(np.intp)
    return indptr, np.concatenate(out) if out else np.zeros(0, dtype=np.intp)


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 30).flatmap(lambda n: st.tuples(
    st.just(n), st.lists(st.tuples(st.integers(0, max(n - 1, 0)), st.integers(0, max(n - 1, 0))), max_size=3 * n),
    st.permutations(range(n)), st.integers(1, 5), st.booleans(), st.integers(0, 3), st.integers(0, 6))))
def test_the_reach_factored_through_wide_nodes_is_the_same_reach(case):
    """Random directed graphs (cycles, self-loops, hubs), nodes in any order: every long node's local nodes and the
    rings of the wide nodes it reaches first make up exactly its reach (a plain breadth-first search's); the other
    nodes have their whole reach listed."""
    ps = kbest
    n, edges, order, max_skip, forward, wide, long_row = case
    graph = nx.DiGraph()
    graph.add_nodes_from(f"n{i}" for i in range(n))
    graph.add_edges_from((f"n{a}", f"n{b}") for a, b in edges)
    nodes = [f"n{i}" for i in order]
    index = {node: i for i, node in enumerate(nodes)}
    saved = ps.WIDE, ps.LONG_ROW
    ps.WIDE, ps.LONG_ROW = wide, long_row  # few successors make a node wide: many wide nodes, chains of them
    try:
        fan = ps._fan(graph, nodes, index, max_skip, forward=forward)
    finally:
        ps.WIDE, ps.LONG_ROW = saved
    indptr, want = reference_reach(graph, nodes, index, max_skip, forward=forward)
    ring_ptr, ring_nodes = fan.rings
    full_ptr, full = fan.full
    for i in range(n):
        if not fan.long[i]:  # listed whole, sorted
            assert full[full_ptr[i]:full_ptr[i + 1]].tolist() == want[indptr[i]:indptr[i + 1]].tolist()
            assert fan.local[0][i] == fan.local[0][i + 1] and fan.wide[0][i] == fan.wide[0][i + 1]
            continue
        assert full_ptr[i] == full_ptr[i + 1]  # a long row is never built whole
        got = set(fan.local[1][fan.local[0][i]:fan.local[0][i + 1]].tolist())
        for at in range(fan.wide[0][i], fan.wide[0][i + 1]):
            w, d = fan.wide[1][at], fan.wide[2][at]
            for r in range(max_skip - d + 1):
                row = w * (max_skip + 1) + r
                got |= set(ring_nodes[ring_ptr[row]:ring_ptr[row + 1]].tolist())
        assert got == set(want[indptr[i]:indptr[i + 1]].tolist())


@pytest.mark.parametrize("settings", [["matcher.beam.k=3"], ["matcher.beam.max_skip=3"]])
def test_a_beam_step_through_hubs_keeps_the_same_paths_as_listing_every_pair(tmp_path, settings):
    """Generated repertoires of many movements sharing a hub (likeme bench scaling's): every demo gets the same path,
    movement and confidence whether the reach is factored through the hub or listed pair by pair."""
    ps = kbest
    from plugins.bench.memory import _data
    from plugins.bench.scaling import _demos, generated_clips
    from plugins.lib.clip_repertoire import clip_repertoire
    from toolkit.manager import create_plugin_manager
    from toolkit.observe import Observer, compose_observer
    from toolkit.config.settings import parse_settings
    from toolkit.recordings.profile import load_profile

    pm = create_plugin_manager()
    profile = load_profile(_data(pm, tmp_path / "data") / "profile.toml")
    motions, labels = generated_clips(pm, 40, seed=3)
    repertoire = clip_repertoire(motions, labels, profile)
    answers = {}
    for long_row in (0, 10**9):  # 0: every row through the hub factored; 10**9: every pair listed, as before
        saved, ps.LONG_ROW = ps.LONG_ROW, long_row
        try:
            character = compose_observer(pm, profile, repertoire, matcher="", settings=parse_settings(
                ["matcher.comparison=poses", "matcher.search=k-best", "matcher.decision=distance", *settings]))
            observer = Observer(character, profile.body, 30.0)
            answers[long_row] = [observer.classify(motion).match for _, motion in _demos(pm, 30.0)]
            table = character.matcher.searcher.kbest.succ
        finally:
            ps.LONG_ROW = saved
        assert (len(table.wide[1]) > 0) == (long_row == 0)  # the hub (40 movements) is wide
    assert len(answers[0]) >= 5
    for a, b in zip(answers[0], answers[10**9]):
        assert (a.movement, a.path, a.confidence) == (b.movement, b.path, b.confidence)
