"""The look-at layer (plugins/layers/look_at.py): the head turns toward the object of attention over every movement,
clamped to its limits and blended in and out; nothing changes without an object (Buchsbaum & Blumberg 2005, §6.1.2).
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.layers.look_at import blend_weight, gaze_angles, look_at, turn
from tests.conftest import CHARACTERS
from toolkit import ConfigError, MovementRequest, World, WorldObject, create_plugin_manager, load_character
from toolkit.motion import world_to_local

HEAD, NOSE, HAND = 0, 1, 2
POSE = np.array([[0.0, 0.55, 0.0], [0.0, 0.55, 0.12], [-0.14, 0.26, 0.03]])  # head, nose, a hand: Max standing
LIMITS = {"yaw_limit": np.radians(70), "pitch_up": np.radians(35), "pitch_down": np.radians(45)}


def _look(target, weight=1.0, pose=POSE):
    return look_at(pose, np.asarray(target, dtype=float), pivot=HEAD, parts=np.array([NOSE]), gaze=(HEAD, NOSE),
                   weight=weight, **LIMITS)


def _gaze(pose):
    return gaze_angles(pose[NOSE] - pose[HEAD])


# -- the formula ---------------------------------------------------------------------------------------------------


@settings(max_examples=200, deadline=None)
@given(yaw=st.floats(-69.0, 69.0), pitch=st.floats(-44.0, 34.0), distance=st.floats(0.1, 3.0),
       yaw0=st.floats(-80.0, 80.0), pitch0=st.floats(-60.0, 60.0))
def test_the_gaze_reaches_a_target_within_the_limits(yaw, pitch, distance, yaw0, pitch0):
    a, p = np.radians(yaw), np.radians(pitch)
    target = POSE[HEAD] + distance * np.array([np.sin(a) * np.cos(p), np.sin(p), np.cos(a) * np.cos(p)])
    straight, _, _ = _look(target)
    assert _gaze(straight) == pytest.approx((a, p), abs=1e-9)
    # from a head the motion already turned (yaw0, pitch0): the same gaze, turned by the difference
    start = turn(POSE, HEAD, np.array([NOSE]), POSE[NOSE] - POSE[HEAD], np.radians(yaw0), np.radians(pitch0))
    assert np.degrees(_gaze(start)) == pytest.approx((yaw0, pitch0), abs=1e-9)
    pose, d_yaw, d_pitch = _look(target, pose=start)
    assert _gaze(pose) == pytest.approx((a, p), abs=1e-9)
    assert np.degrees((d_yaw, d_pitch)) == pytest.approx((yaw - yaw0, pitch - pitch0), abs=1e-7)
    # a rigid turn about the head: the nose keeps its distance, the head and the hand do not move
    assert np.linalg.norm(pose[NOSE] - pose[HEAD]) == pytest.approx(0.12)
    np.testing.assert_array_equal(pose[[HEAD, HAND]], POSE[[HEAD, HAND]])


@pytest.mark.parametrize("target, expected", [
    ((1.0, 0.55, -0.2), (70, 0)),      # behind to the left: as far left as the neck goes
    ((-1.0, 0.55, 0.0), (-70, 0)),     # to the right
    ((0.0, 2.55, 0.3), (0, 35)),       # high above
    ((0.3, -1.0, 0.3), (45, -45)),     # below to the left: the yaw is reached, the pitch clamped
])
def test_the_gaze_is_clamped_to_the_limits(target, expected):
    pose, _, _ = _look(target)
    assert np.degrees(_gaze(pose)) == pytest.approx(expected, abs=1e-6)


def test_the_limits_hold_for_where_the_gaze_ends_not_for_the_turn():
    """A motion whose head already looks 50 degrees left turns only 20 degrees more toward a target far left."""
    looking_left = turn(POSE, HEAD, np.array([NOSE]), POSE[NOSE] - POSE[HEAD], np.radians(50), 0.0)
    pose, d_yaw, _ = _look((1.0, 0.55, -0.5), pose=looking_left)
    assert np.degrees(d_yaw) == pytest.approx(20)
    assert np.degrees(_gaze(pose)[0]) == pytest.approx(70)


def test_the_turn_is_blended():
    duration, blend = 1.5, 0.3
    t = np.linspace(0, duration, 301)
    w = blend_weight(t, duration, blend, blend)
    assert w[0] == 0 and w[-1] == 0
    assert np.all(w[(t >= blend) & (t <= duration - blend)] == 1)
    rising = w[t <= blend]
    assert np.all(np.diff(rising) >= 0) and float(blend_weight(blend / 2, duration, blend, blend)) == pytest.approx(0.5)
    assert np.all(np.diff(w[t >= duration - blend]) <= 0)
    # a smooth start: the weight's slope is zero at the ends of the ramp
    assert float(blend_weight(1e-4, duration, blend, blend)) < 1e-6
    assert blend_weight(0.0, duration, 0.0, 0.0) == 1  # no blend time: the whole turn at once
    # the applied angle is the weight times the full turn
    full = _look((0.3, 0.3, 0.3))
    half = _look((0.3, 0.3, 0.3), weight=0.5)
    assert half[1] == pytest.approx(full[1] / 2) and half[2] == pytest.approx(full[2] / 2)
    np.testing.assert_array_equal(_look((0.3, 0.3, 0.3), weight=0.0)[0], POSE)


# -- in a world ----------------------------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def pm():
    return create_plugin_manager(autoload=False)


def _morris_performs(pm, request, *, layer=True, objects=()):
    """Morris alone, performing ``request`` to the end: his local pose at every frame and the motion's."""
    morris = load_character(CHARACTERS / "morris.toml", pm, override={"action": {"drives": {
        "hunger": {"level": 0.0, "rate": 0.0}, "play": {"level": 0.0, "rate": 0.0}}}})
    if not layer:
        morris.layer = None
    world = World(fps=30.0, pm=pm)
    for obj in objects:
        world.add_object(obj)
    actor = world.add_actor(morris, "morris", (0.0, 0.0, 1.6), np.pi)
    world.add_actor(load_character(CHARACTERS / "max.toml", pm), "max")  # whom an imitation imitates
    actor.request(request)
    motion = actor._motion
    poses = [actor.local_pose().copy()]
    while not actor.idle:
        world.step()
        poses.append(actor.local_pose().copy())
    return actor, motion, np.array(poses)


def test_without_an_object_of_attention_nothing_changes(pm):
    cheese = WorldObject("cheese", "cheese", (0.3, 0.4, 1.4))
    for request in (MovementRequest("reach"), MovementRequest("reach", object="nothing here"),
                    MovementRequest("reach", object="cheese", imitating="max")):
        _, motion, with_layer = _morris_performs(pm, request, objects=[cheese])
        _, _, without = _morris_performs(pm, request, layer=False, objects=[cheese])
        np.testing.assert_array_equal(with_layer, without)
        np.testing.assert_array_equal(with_layer[:motion.n_frames], motion.positions)


def test_switched_off_nothing_changes(pm):
    cheese = WorldObject("cheese", "cheese", (0.3, 0.4, 1.4))
    morris = load_character(CHARACTERS / "morris.toml", pm, override={"layer": {"enabled": False}})
    world = World(fps=30.0, pm=pm)
    world.add_object(cheese)
    actor = world.add_actor(morris, "morris", (0.0, 0.0, 1.6), np.pi)
    actor.request(MovementRequest("reach", object="cheese"))
    motion = actor._motion
    for frame in range(motion.n_frames):
        np.testing.assert_array_equal(actor.local_pose(), motion.positions[frame])
        world.step()


def test_morris_looks_at_the_object_of_attention_during_the_movement(pm):
    cheese = WorldObject("cheese", "cheese", (-0.30, 0.40, 1.43))  # 60 degrees to his left, within reach
    actor, motion, poses = _morris_performs(pm, MovementRequest("reach", object="cheese"), objects=[cheese])
    body = actor.body
    head, nose = body.index("head"), body.index("nose")
    n = motion.n_frames
    # the movement starts and ends as the motor system made it: the hub is untouched
    np.testing.assert_array_equal(poses[0], motion.positions[0])
    np.testing.assert_array_equal(poses[n - 1], motion.positions[-1])
    np.testing.assert_array_equal(actor.local_pose(), motion.positions[-1])  # the posture held after it
    # in the middle the gaze points at the cheese (horizontally, as a line of sight is read)
    middle = n // 2
    target = world_to_local(cheese.position, actor.position, actor.heading)
    yaw, _ = gaze_angles(poses[middle, nose] - poses[middle, head])
    assert np.degrees(yaw) == pytest.approx(np.degrees(gaze_angles(target - poses[middle, head])[0]), abs=0.5)
    assert np.degrees(yaw) > 55
    # only the nose turned; every other part is the motion's
    others = [i for i in range(len(body.parts)) if i != nose]
    np.testing.assert_array_equal(poses[:n][:, others], motion.positions[:, others])
    # smoothly: the nose never jumps more than the motion's own fastest part does between frames
    steps = np.linalg.norm(np.diff(poses[:n, nose], axis=0), axis=1)
    assert steps.max() <= np.linalg.norm(np.diff(motion.positions, axis=0), axis=2).max()
    assert actor.character.layer.inspect()["weight"] == 0.0  # blended out at the last frame


@pytest.mark.parametrize("table, key", [
    ({"parts": ["tail"]}, ("layer", "parts", 0)),
    ({"pivot": "neck"}, ("layer", "pivot")),
    ({"gaze": ["head"]}, ("layer", "gaze")),
    ({"gaze": ["head", "left_hand"]}, ("layer", "gaze", 1)),
    ({"yaw": 120.0}, ("layer", "yaw")),
])
def test_bad_look_at_tables_are_named(pm, table, key):
    with pytest.raises(ConfigError) as err:
        load_character(CHARACTERS / "morris.toml", pm, override={"layer": table})
    assert err.value.key == key


def test_a_layer_that_returns_a_wrong_pose_is_named_or_dropped():
    """A third-party layer's bad answer stops the run with its name, or (skip) the run goes on without it."""
    from tests.conftest import make_plugin
    from toolkit import Layer, PluginError
    from toolkit.manager import PluginInfo

    class Flat(Layer):
        """Returns one point instead of a pose."""

        name = "flat"

        def apply(self, actor, request, motion, frame, world):
            return np.zeros(3)

    pm = create_plugin_manager(autoload=False)
    pm.register_plugin(make_plugin(likeme_register_layers=lambda: [Flat]), PluginInfo("flat", "m", "(tests)", ""))
    for policy in ("stop", "skip"):
        morris = load_character(CHARACTERS / "morris.toml", pm, override={"layer": {"plugin": "flat"}})
        world = World(fps=30.0, pm=pm, on_plugin_error=policy)
        actor = world.add_actor(morris, "morris", (0.0, 0.0, 1.6), np.pi)
        actor.request(MovementRequest("reach"))
        if policy == "stop":
            with pytest.raises(PluginError, match="flat.*Flat.apply.*shape"):
                actor.world_pose()
        else:
            motion = actor._motion
            np.testing.assert_array_equal(actor.local_pose(), motion.positions[0])
            assert morris.layer is None and [e.data["plugin"] for e in world.events_of("plugin_failed")] == ["flat"]
