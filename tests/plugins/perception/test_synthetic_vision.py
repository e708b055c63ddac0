"""Synthetic vision (B&B §4.2, §5.1): field of view, occlusion by parts and objects, noise, dropouts, the sensory buffer."""

from __future__ import annotations

import numpy as np

from plugins.perception.sensory_buffer import SensoryBuffer
from plugins.perception.synthetic_vision import line_of_sight_blocked
from tests.conftest import CHARACTERS
from toolkit import World, WorldObject, load_character


def geometric(pm, **params):
    """Max's perception table with synthetic vision instead of his rendered vision: his eye, part radii and the looks
    he knows things by, the geometric plugin's parameters only (a new plugin replaces the table whole)."""
    from plugins.perception.synthetic_vision import SyntheticVision

    own = load_character(CHARACTERS / "max.toml", pm).perception.params
    names = {q.name for q in SyntheticVision.parameters}
    return {"plugin": "synthetic-vision", **{k: v for k, v in own.items() if k in names}, **params}


def _pair(pm, **params):
    world = World(fps=30)
    morris = world.add_actor(load_character(CHARACTERS / "morris.toml", pm), position=(0, 0, 1.6), heading=np.pi)
    max_ = world.add_actor(load_character(CHARACTERS / "max.toml", pm, override={"perception": geometric(pm, **params)}))
    morris.character.action = None
    max_.watch(morris)
    return world, max_, morris


def test_a_standing_target_in_front_is_fully_visible_and_root_relative(pm):
    world, max_, morris = _pair(pm)
    world.step()
    percept = max_.character.perception.perceive(max_, morris, world)
    assert percept.visible.all()
    rest = morris.character.motor.rest_pose()
    np.testing.assert_allclose(percept.pose, rest - rest[0], atol=1e-6)
    assert abs(abs(percept.heading) - np.pi) < 1e-6


def test_an_object_between_hides_the_parts_behind_it(pm):
    world, max_, morris = _pair(pm)
    world.add_object(WorldObject("box", "toy", (0.0, 0.4, 0.8), radius=0.25, colour="#8b5a2b"))
    world.step()
    percept = max_.character.perception.perceive(max_, morris, world)
    hidden = {p for p, v in zip(morris.body.parts, percept.visible) if not v}
    assert {"root", "head", "nose"} <= hidden
    assert list(percept.objects) == ["box"] and percept.kinds["box"] == "box"  # known by its look, not its kind


def test_field_of_view_and_range(pm):
    world, max_, morris = _pair(pm, fov=30.0)
    morris.position = np.array([1.5, 0.0, 0.5])  # far to Max's left
    world.step()
    assert not max_.character.perception.perceive(max_, morris, world).visible.any()
    world, max_, morris = _pair(pm, range=1.0)
    world.step()
    assert not max_.character.perception.perceive(max_, morris, world).visible.any()


def test_noise_and_dropouts_are_seeded(pm):
    outs = []
    for _ in range(2):
        world, max_, morris = _pair(pm, noise=0.01, dropout=0.3, buffer=0.0, seed=4)
        world.step()
        outs.append(max_.character.perception.perceive(max_, morris, world))
    np.testing.assert_array_equal(outs[0].visible, outs[1].visible)
    np.testing.assert_allclose(outs[0].world, outs[1].world)
    assert not outs[0].visible.all()


def test_sensory_buffer_bridges_short_dropouts_only():
    buf = SensoryBuffer(2, hold_frames=2)
    seen = np.array([[1.0, 2.0, 3.0], [4.0, 5.0, 6.0]])
    pos, vis = buf.update(seen, np.array([True, True]))
    assert vis.all()
    gone = np.full((2, 3), np.nan)
    for frame in range(1, 5):
        pos, vis = buf.update(gone, np.array([True, False]))
        assert vis[0] == vis[1] == (frame <= 2)  # a NaN "visible" part is a dropout like any other
        if vis[1]:
            np.testing.assert_allclose(pos[1], [4, 5, 6])


def test_line_of_sight():
    eye = np.zeros(3)
    targets = np.array([[0.0, 0.0, 2.0], [1.0, 0.0, 2.0]])
    blocked = line_of_sight_blocked(eye, targets, np.array([0.03, 0.03]), np.array([[0.0, 0.0, 1.0]]), np.array([0.1]))
    assert blocked.tolist() == [True, False]
    behind = line_of_sight_blocked(eye, targets, np.array([0.03, 0.03]), np.array([[0.0, 0.0, 3.0]]), np.array([0.5]))
    assert not behind.any()
