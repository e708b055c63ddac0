"""A new movement learned from repeated demonstrations (Buchsbaum & Blumberg 2005, §7.3): mean path, spread, takes."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.motor.posegraph import mean_path
from tests.conftest import CHARACTERS
from toolkit import ConfigError, create_plugin_manager, load_character, load_scenario


@pytest.fixture(scope="module")
def pm():
    return create_plugin_manager(autoload=False)


def _path(n: int = 20, parts: int = 4) -> np.ndarray:
    """A smooth path of ``n`` poses of ``parts`` parts (n, parts, 3)."""
    t = np.linspace(0.0, 1.0, n)[:, None]
    k = np.arange(1, parts + 1)[None, :]
    return np.stack([0.2 * np.sin(2 * np.pi * t * k / 2), 0.1 * np.cos(np.pi * t * k), 0.05 * t * k], axis=-1)


def _take(path: np.ndarray, n: int, noise: float, rng: np.random.Generator) -> np.ndarray:
    """``path`` played at another speed (``n`` poses, resampled) and seen with noise."""
    old = np.linspace(0.0, 1.0, len(path))
    new = np.linspace(0.0, 1.0, n)
    flat = path.reshape(len(path), -1)
    out = np.stack([np.interp(new, old, flat[:, j]) for j in range(flat.shape[1])], axis=1).reshape(n, *path.shape[1:])
    return out + rng.normal(0.0, noise, out.shape)


def test_the_mean_of_takes_seen_with_noise_is_nearer_the_movement_than_a_take():
    """DTW barycentre averaging: takes at other speeds, each seen with noise, average out to a path nearer the
    movement than any one of them; the spread is about the noise."""
    rng = np.random.default_rng(0)
    truth = _path()
    takes = [_take(truth, n, 0.01, rng) for n in (18, 20, 23, 21, 19)]
    mean, spread = mean_path(takes)

    fine = _take(truth, 2000, 0.0, rng)  # the movement, densely

    def error(p):  # mean distance from each of its poses to the movement
        return float(np.mean(np.min(np.linalg.norm(p[:, None] - fine[None], axis=-1).mean(axis=-1), axis=1)))

    assert error(mean) < 0.75 * min(error(t) for t in takes)
    assert 0.005 < spread < 0.03  # about the noise (1 cm per coordinate: ~1.6 cm per part)
    one, zero = mean_path(takes[:1])
    np.testing.assert_array_equal(one, takes[0]) and zero == 0.0


@settings(max_examples=15, deadline=None)
@given(st.integers(2, 5), st.integers(0, 10_000))
def test_the_mean_takes_the_length_of_the_take_nearest_the_others(k, seed):
    rng = np.random.default_rng(seed)
    takes = [_take(_path(), int(n), 0.005, rng) for n in rng.integers(12, 30, k)]
    mean, spread = mean_path(takes)
    assert len(mean) in {len(t) for t in takes} and mean.shape[1:] == takes[0].shape[1:]
    assert np.isfinite(mean).all() and spread >= 0.0


def _windmill_takes(pm, n: int, seed: int = 0):
    """``n`` takes of Morris's windmill as Max's path search samples them (root-relative, at the node rate)."""
    from plugins.bench.learning import _movement_keys, take

    morris = load_character(CHARACTERS / "morris.toml", pm)
    max_ = load_character(CHARACTERS / "max.toml", pm)
    rng = np.random.default_rng(seed)
    keys, times = _movement_keys(morris, "windmill")
    motions = [take(keys, times, morris, rng, noise=0.005, jitter=0.01) for _ in range(n)]
    return max_, [max_.matcher.samples(m.onto(max_.body.parts))[1] for m in motions]


def test_learned_from_several_takes_the_movement_is_one_mean_path_and_its_takes(pm):
    max_, samples = _windmill_takes(pm, 3)
    motor = max_.motor
    before = set(motor.movements())
    path = motor.learn_takes("windmill", [s[0] for s in samples], [s[1] for s in samples], announce=False)
    assert set(motor.movements()) - before == {"windmill"}  # learned once
    assert motor.paths["windmill"] == path and path[0] == path[-1] == "stand"
    takes = [name for name in motor.paths if name.startswith("windmill/take-")]
    assert len(takes) == 3 and all(motor.paths_label[t] == "windmill" for t in takes)
    assert all(motor.movement_of(node) == "windmill" for t in takes for node in motor.paths[t][1:-1])
    entry = motor.learned["windmill"]
    assert len(entry["takes"]) == 3 and entry["spread"] > 0
    np.testing.assert_allclose(motor.node_root_relative[[motor.node_index(n) for n in path[1:-1]]], entry["mean"],
                               atol=1e-9)  # the path is the mean, root-relative
    assert motor.perform("windmill").n_frames > 1  # performed along the mean path
    # a fourth take joins only while it has fewer than `takes` (3 by default)
    assert not motor.add_take("windmill", samples[0][0], samples[0][1])
    with pytest.raises(ConfigError, match="no learned movement 'jump'"):
        motor.add_take("jump", samples[0][0])


def test_one_take_is_the_papers_learning(pm):
    max_, samples = _windmill_takes(pm, 1)
    motor = max_.motor
    motor.learn("windmill", *samples[0], announce=False)
    assert [n for n in motor.paths if n.startswith("windmill")] == ["windmill"]  # one path, no takes besides
    assert motor.learned["windmill"]["spread"] == 0.0
    assert motor.add_take("windmill", *_windmill_takes(pm, 1, seed=1)[1][0])
    assert len(motor.learned["windmill"]["takes"]) == 2 and len([n for n in motor.paths if n.startswith("windmill")]) == 3


def test_the_learned_takes_are_saved_and_loaded(pm):
    max_, samples = _windmill_takes(pm, 2)
    max_.motor.learn_takes("windmill", [s[0] for s in samples], [s[1] for s in samples], announce=False)
    state = max_.motor.get_state()
    assert len(state["learned"]["windmill"]["takes"]) == 2
    fresh = load_character(CHARACTERS / "max.toml", pm)
    fresh.motor.set_state(state)
    assert fresh.motor.get_state() == state
    np.testing.assert_allclose(fresh.motor.perform("windmill").positions, max_.motor.perform("windmill").positions,
                               atol=1e-5)
    # a state from before takes were kept (one path): that path, one take
    old = {"learned": {"w": {"source": "x", "poses": state["learned"]["windmill"]["poses"]}}}
    other = load_character(CHARACTERS / "max.toml", pm)
    other.motor.set_state(old)
    assert len(other.motor.learned["w"]["takes"]) == 1
    with pytest.raises(ConfigError, match=r"invalid poses of learned movement 'w'"):
        load_character(CHARACTERS / "max.toml", pm).motor.set_state(
            {"learned": {"w": {"poses": old["learned"]["w"]["poses"], "takes": [[[1, 2]]]}}})


def test_watching_the_new_movement_again_adds_a_take(pm, write):
    """learn_windmill: the first windmill makes the movement; the second, recognised as it, is its second take (the
    ``likeme_movement_recognised`` hook); with ``takes = 1`` it stays what the first showed."""
    world = load_scenario(CHARACTERS / "scenarios" / "learn_windmill.toml", pm).run()
    motor = world.actors["max"].character.motor
    assert len(motor.learned["learned-1"]["takes"]) == 2 and motor.learned["learned-1"]["spread"] > 0
    text = (CHARACTERS / "scenarios" / "learn_windmill.toml").read_text().replace('"../', f'"{CHARACTERS}/')
    world = load_scenario(write("one.toml", text + "[actors.override.motor]\ntakes = 1\n"), pm).run()
    assert len(world.actors["max"].character.motor.learned["learned-1"]["takes"]) == 1


def test_learned_from_more_takes_fresh_takes_are_recognised_more_often(pm):
    """The figure of ``likeme bench learning`` on a small sample: learned from three takes, the new movements'
    fresh takes are recognised more often than learned from one, and Max's own movements are not taken for them."""
    from plugins.bench.learning import learning_benchmark

    r = learning_benchmark(pm, takes=(1, 3), generated=1, trials=2, tests=10, seed=1)
    one, three = r["table"]["1"], r["table"]["3"]
    assert three["recognised"] > one["recognised"]
    assert three["false"] <= 0.1 and one["false"] <= 0.1
