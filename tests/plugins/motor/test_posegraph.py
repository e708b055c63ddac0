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
