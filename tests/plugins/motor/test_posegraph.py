"""The posegraph motor system (B&B §4.1): nodes, movements as paths, hubs, contiguous poses."""

from __future__ import annotations

import networkx as nx
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.conftest import CHARACTERS
from toolkit import create_plugin_manager, load_character


@pytest.fixture(scope="module")
def max_():
    return load_character(CHARACTERS / "max.toml", create_plugin_manager(autoload=False))


def test_movements_are_paths_from_the_hub_back_to_the_hub(max_):
    g, motor = max_.motor.graph, max_.motor
    assert len(motor.movements()) >= 30
    for name, path in motor.paths.items():
        assert path[0] == path[-1] == "stand"
        assert nx.is_path(g, path)
        assert all(motor.movement_of(n) == name for n in path[1:-1])
    # transitions between movements pass through the hub: the only node with edges into several movements
    for node in g.nodes:
        successors = {motor.movement_of(s) for s in g.successors(node)} - {None}
        if len(successors) > 1:
            assert g.nodes[node]["hub"]


def test_node_poses_are_one_contiguous_array_indexed_by_the_graph(max_):
    motor = max_.motor
    assert motor.node_poses.flags["C_CONTIGUOUS"]
    assert motor.node_poses.shape == (motor.graph.number_of_nodes(), len(max_.body.parts), 3)
    np.testing.assert_allclose(motor.node_poses[motor.node_index("stand")], motor.rest_pose())
    root = max_.body.root_index
    np.testing.assert_allclose(motor.node_root_relative[:, root], 0.0)


def test_node_rate_sets_the_resolution(max_):
    motor = max_.motor
    jump_nodes = len(motor.paths["jump"]) - 2
    duration = motor.perform("jump").duration
    assert abs(jump_nodes - duration * motor.params["node_rate"]) <= 2


@settings(max_examples=10, deadline=None)
@given(name=st.sampled_from(["jump", "wave", "sit", "cover_face"]), fps=st.sampled_from([24.0, 30.0, 60.0]))
def test_playing_a_movement_path_stays_close_to_the_authored_movement(max_, name, fps):
    motor = max_.motor
    authored = motor.perform(name, fps=fps)
    path = motor.play_path(motor.paths[name], fps=fps)
    n = min(authored.n_frames, path.n_frames)
    assert abs(authored.n_frames - path.n_frames) <= fps / motor.params["node_rate"] + 1
    assert np.abs(authored.positions[:n] - path.positions[:n]).max() < 0.05


def test_play_path_refuses_a_path_that_is_not_in_the_graph(max_):
    with pytest.raises(ValueError, match="no edge"):
        max_.motor.play_path(["stand", "jump/3"])


def test_learned_movement_is_a_new_path_through_new_nodes():
    character = load_character(CHARACTERS / "max.toml", create_plugin_manager(autoload=False))
    motor = character.motor
    before = motor.graph.number_of_nodes()
    poses = motor.node_root_relative[[motor.node_index(n) for n in motor.paths["wave"]]]
    visible = np.ones(poses.shape[:2], bool)
    visible[3, 5] = False  # a hidden hand is filled from the nearest known pose
    path = motor.learn("new-wave", poses, visible)
    assert path[0] == path[-1] == "stand" and len(path) == len(poses)
    assert motor.graph.number_of_nodes() == before + len(poses) - 2
    assert "new-wave" in motor.movements() and motor.describe()["learned"] == ["new-wave"]
    assert motor.perform("new-wave", fps=30).n_frames > 10
    with pytest.raises(Exception, match="already exists"):
        motor.learn("new-wave", poses)


@settings(max_examples=30, deadline=None)
@given(n=st.integers(2, 60), block=st.integers(1, 2000), seed=st.integers(0, 2**16))
def test_find_hubs_block_by_block_is_the_all_pairs_answer(n, block, seed):
    """The clip ends' eq. 1 distances are taken a block of rows at a time (bounded memory for large repertoires):
    the same hubs, bit for bit, as one call over every pair."""
    from unittest import mock

    from plugins.lib import clip_repertoire

    rng = np.random.default_rng(seed)
    ends = rng.normal(scale=0.05, size=(n, 4, 3))
    ends[rng.random(n) < 0.5] *= 0.1  # a crowd of ends near the rest, as real clips have
    whole = clip_repertoire.find_hubs(ends, 0.06, 0.2)  # the default block holds every pair of these few ends
    with mock.patch.object(clip_repertoire, "PAIR_BLOCK", block):
        np.testing.assert_array_equal(clip_repertoire.find_hubs(ends, 0.06, 0.2), whole)


@settings(max_examples=10, deadline=None)
@given(seed=st.integers(0, 2**16), n=st.integers(1, 12), takes=st.integers(1, 3))
def test_loading_learned_movements_at_once_makes_the_graph_learning_them_one_by_one_makes(seed, n, takes):
    """A state file's movements enter the graph together (one build: loading is linear in the state's size); the
    graph, its node arrays and every movement's mean and spread are those of learning the movements one at a time."""
    pm = create_plugin_manager(autoload=False)
    one_by_one = load_character(CHARACTERS / "max.toml", pm).motor
    rng = np.random.default_rng(seed)
    base = one_by_one.node_root_relative[[one_by_one.node_index(x) for x in one_by_one.paths["wave"]]]
    for i in range(n):
        demos = [base[: rng.integers(4, len(base) + 1)] + rng.normal(scale=0.01, size=base.shape)[:1]
                 for _ in range(takes)]
        for demo in demos:
            demo[[0, -1]] = base[0]
        one_by_one.learn_takes(f"learned-{i}", demos, announce=False)
    state = one_by_one.get_state()
    loaded = load_character(CHARACTERS / "max.toml", pm).motor
    loaded.set_state(state)
    assert loaded.nodes == one_by_one.nodes
    assert sorted(loaded.graph.edges) == sorted(one_by_one.graph.edges)
    assert np.allclose(loaded.node_poses, one_by_one.node_poses, atol=2e-6)  # a state holds 6 decimals
    assert np.allclose(loaded.node_motion, one_by_one.node_motion, atol=1e-3)
    assert loaded.get_state() == state
    for name, entry in one_by_one.learned.items():
        assert loaded.learned[name]["spread"] == pytest.approx(entry["spread"], abs=1e-5)


def test_a_take_that_is_the_mean_has_no_spread_and_the_c_warping_path_is_the_python_one():
    from dtaidistance import dtw_ndim

    from plugins.motor.posegraph import mean_path

    rng = np.random.default_rng(3)
    take = rng.normal(size=(9, 4, 3))
    assert mean_path([take], take.copy())[1] == 0.0
    other = take[::-1][:7] + rng.normal(scale=0.1, size=(7, 4, 3))
    a, b = take.reshape(9, -1), np.ascontiguousarray(other.reshape(7, -1))
    assert dtw_ndim.warping_path(a, b, use_c=True) == dtw_ndim.warping_path(a, b, use_c=False)


def _random_character(rng: np.random.Generator, n: int) -> str:
    """A character extending Max with ``n`` random key-pose movements: 2 to 5 keys, some sharing their key times
    (played together) and some not, poses that move the root (travel) and the hands, a random node rate."""
    lines = ['[character]\nname = "Random"\nextends = ' + repr(str(CHARACTERS / "max.toml")).replace("'", '"'),
             f"[motor]\nnode_rate = {rng.choice([1.0, 7.5, 10.0, 24.0])}"]
    timings = [[0.0, 0.5, 1.0], [0.0, 0.4], [0.0, 0.3, 0.7, 1.3], [0.0, 0.05, 0.1]]
    for i in range(n):
        lines.append(f'[motor.poses.p{i}]\nbase = "stand"\nshift = {rng.normal(scale=0.03, size=3).round(4).tolist()}\n'
                     f"right_hand = {rng.normal([-0.1, 0.4, 0.1], 0.05).round(4).tolist()}")
        times = timings[rng.integers(len(timings))] if rng.random() < 0.7 else np.cumsum(
            np.r_[0.0, rng.uniform(0.05, 0.8, size=rng.integers(1, 5))]).round(3).tolist()
        poses = ["stand", *(f"p{rng.integers(i + 1)}" for _ in times[2:]), f"p{i}"][: len(times) - 1] + ["stand"]
        keys = ", ".join(f'{{ pose = "{p}", at = {t} }}' for p, t in zip(poses, times))
        lines.append(f"[motor.movements.m{i}]\nkeys = [{keys}]")
    return "\n\n".join(lines) + "\n"


@pytest.mark.parametrize(("seed", "n", "together"), [*((s, None, 3) for s in range(6)), (6, 600, None)])
def test_movements_played_together_give_the_nodes_each_gives_alone(tmp_path, seed, n, together):
    """The key-pose movements are played and differentiated in batches of one key timing
    (:meth:`Posegraph._played`): every node's pose, travel and motion is, bit for bit, what playing that movement
    alone gives (its nodes at ``node_rate``; at 30 frames/s the root's travel and the parts' motion, taken at the
    nodes' times). Batches of 3, so that most movements share a call with others and some timings need two; and
    600 movements in the default batches (on one BLAS thread, as the build runs them)."""
    from unittest import mock

    from plugins.lib.travel import body_velocity
    from plugins.lib.velocity import derivative
    from plugins.motor import posegraph
    from plugins.motor.key_poses import play

    rng = np.random.default_rng(seed)
    path = tmp_path / "random.toml"
    path.write_text(_random_character(rng, n or int(rng.integers(8, 25))))
    with mock.patch.object(posegraph, "_TOGETHER", together or posegraph._TOGETHER):
        motor = load_character(path, create_plugin_manager(autoload=False)).motor
    rate, root, parts = motor.params["node_rate"], motor.body.root_index, motor.body.parts
    for name, movement in motor.repertoire.items():
        sampled = play(motor.key_poses, movement, parts, fps=rate).positions
        fine = play(motor.key_poses, movement, parts, fps=30.0).positions
        at = np.minimum(np.round(np.arange(len(sampled)) * 30.0 / rate).astype(int), len(fine) - 1)
        travel = np.nan_to_num(body_velocity(fine, fine, np.ones(fine.shape[:2], dtype=bool), root, 30.0)[at])
        motion = derivative(fine - fine[:, root : root + 1], 30.0)[at]
        nodes = [motor.node_index(node) for node in motor.paths[name][1:-1]]
        assert len(nodes) == len(sampled) - 2
        np.testing.assert_array_equal(motor.node_poses[nodes], sampled[1:-1])
        np.testing.assert_array_equal(motor.node_travel[nodes], travel[1:-1])
        np.testing.assert_array_equal(motor.node_motion[nodes], motion[1:-1])
    assert motor.node_travel.any() and motor.node_motion.any()  # the roots travel, the parts move
