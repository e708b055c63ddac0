"""Travel (plugins/lib/travel.py): where the body goes in its own frame, kept beside root-relative poses (issue 18).

Root-relative coordinates (Buchsbaum & Blumberg 2005, §5.1) make a walk forwards and a walk backwards nearly the
same leg swings. These tests check the formulas on bodies whose heading and velocity are known, that the world
positions travel with a :class:`Motion` through working memory, that the posegraph knows each node's travel and
loops a clip that is one cycle of a gait, and that path search with ``travel`` tells apart two movements whose
root-relative poses are the same.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plugins.lib.root_frame import root_relative
from plugins.lib.travel import body_velocity, bridged_rows, frame_rotation, travel_part, travelled
from tests.conftest import STICK, STICK_PARTS, write_stick_clip, write_stick_profile
from toolkit import Motion, create_plugin_manager, load_character
from toolkit.motion import local_to_world
from toolkit.observe import compose_observer
from toolkit.recordings.profile import load_profile
from toolkit.watching import ObservationLog

PARTS = STICK_PARTS
STAND = np.array([[0.0, 1.0, 0.0], [0.0, 1.6, 0.1], [0.1, 0.5, 0.0], [-0.1, 0.5, 0.0], [0.3, 1.0, 0.0],
                  [0.1, 0.0, 0.0], [-0.1, 0.0, 0.0]])


def walking(heading: float, velocity_local: np.ndarray, frames: int = 60, fps: float = 30.0) -> tuple[np.ndarray, np.ndarray]:
    """A rigid standing body facing ``heading`` whose root moves at ``velocity_local`` (m/s, body frame): world
    (F, P, 3) and root-relative local (F, P, 3) positions."""
    t = np.arange(frames) / fps
    direction = local_to_world(np.asarray(velocity_local, dtype=float)[None, None], np.zeros(3), heading)[0, 0]
    roots = np.array([5.0, 0.0, -2.0]) + t[:, None] * direction
    world = np.stack([local_to_world(STAND - STAND[0], r, heading) for r in roots])
    local = np.repeat((STAND - STAND[0])[None], frames, axis=0)
    return world, local


@settings(max_examples=50, deadline=None)
@given(heading=st.floats(-np.pi, np.pi), vx=st.floats(-2, 2), vz=st.floats(-4, 4), vy=st.floats(-1, 1))
def test_the_velocity_in_the_bodys_frame_is_the_one_it_moved_with_whatever_its_heading(heading, vx, vz, vy):
    world, local = walking(heading, np.array([vx, vy, vz]))
    velocity = body_velocity(world, local, np.ones(world.shape[:2], dtype=bool), 0, 30.0)
    assert np.allclose(velocity, [vx, vy, vz], atol=1e-9)


@settings(max_examples=30, deadline=None)
@given(heading=st.floats(-np.pi, np.pi))
def test_the_frame_rotation_undoes_the_heading_the_perception_found(heading):
    """The same root-relative transform the perceptions use (§5.1): with offsets as ``x + iz``, the rotation found
    is the heading the perception found."""
    world, _ = walking(heading, np.array([0.0, 0.0, 1.0]), frames=3)
    from toolkit.body import Body, Facing

    body = Body(PARTS, "root", facing=Facing("lk", "rk", "head"))
    local, visible, _, found = root_relative(world, None, body)
    angle = frame_rotation(world, local, visible, 0)
    assert np.allclose(np.angle(np.exp(1j * (angle - found))), 0.0, atol=1e-9)


def test_hidden_roots_and_frames_without_a_facing_have_no_velocity():
    world, local = walking(0.3, np.array([0.0, 0.0, 1.2]), frames=10)
    visible = np.ones(world.shape[:2], dtype=bool)
    visible[4, 0] = False  # the root hidden in one frame
    visible[6, 1:] = False  # nothing but the root seen: no facing
    velocity = body_velocity(world, local, visible, 0, 30.0)
    assert np.isnan(velocity[[4, 6]]).all()
    assert np.allclose(np.delete(velocity, [4, 6], axis=0), [0.0, 0.0, 1.2])
    assert np.isnan(body_velocity(world[:1], local[:1], visible[:1], 0, 30.0)).all()  # one frame: no velocity


@settings(max_examples=40, deadline=None)
@given(heading=st.floats(-np.pi, np.pi), vx=st.floats(-2, 2), vz=st.floats(-4, 4))
def test_where_the_root_went_is_in_the_bodys_first_frame_whatever_its_heading(heading, vx, vz):
    world, local = walking(heading, np.array([vx, 0.0, vz]))
    went = travelled(world, local, np.ones(world.shape[:2], dtype=bool), 0)
    assert np.allclose(went, np.arange(len(world))[:, None] / 30.0 * [vx, 0.0, vz], atol=1e-9)


def test_a_walk_that_turns_left_goes_off_to_the_left_of_where_it_began_facing():
    """A quarter turn to the heading's positive side (the body's left, +x) while walking along the facing: the path,
    in the body's first frame, ends ahead and to the left; a root never seen or a facing never known: NaN."""
    t = np.arange(61) / 30.0
    heading = np.pi / 2 * t / t[-1]
    roots = np.cumsum(np.stack([np.sin(heading), 0 * t, np.cos(heading)], axis=1) * 1.2 / 30.0, axis=0)
    world = np.stack([local_to_world(STAND - STAND[0], r, h) for r, h in zip(roots, heading)])
    local = np.repeat((STAND - STAND[0])[None], len(t), axis=0)
    visible = np.ones(world.shape[:2], dtype=bool)
    visible[10, 0] = False
    went = travelled(world, local, visible, 0)
    assert went[-1, 0] > 0.5 and went[-1, 2] > 0.5 and np.isnan(went[10]).all()
    assert np.isnan(travelled(world, local, visible & False, 0)).all()


def test_rows_not_seen_are_bridged_on_a_line_and_held_beyond_the_ends():
    values = np.array([[9.0, 9.0], [0.0, 2.0], [9.0, 9.0], [4.0, 6.0], [9.0, 9.0]])
    seen = np.array([False, True, False, True, False])
    assert np.array_equal(bridged_rows(values, seen), [[0, 2], [0, 2], [2, 4], [4, 6], [4, 6]])
    assert bridged_rows(values, np.ones(5, dtype=bool)) is values


def test_travel_is_the_displacement_over_the_horizon():
    assert np.allclose(travel_part(np.array([[0.0, 0.0, 1.5]]), 0.5), [[0.0, 0.0, 0.75]])


def test_world_positions_stay_with_a_motion_through_every_operation_and_working_memory():
    world, local = walking(1.0, np.array([0.0, 0.0, 1.0]), frames=8)
    motion = Motion(local, 30.0, PARTS, None, world)
    assert np.array_equal(motion.slice(2, 5).world, world[2:5])
    assert np.array_equal(motion.select(["hand", "root"]).world, world[:, [4, 0]])
    onto = motion.onto(["hand", "tail"])
    assert np.array_equal(onto.world[:, 0], world[:, 4]) and np.isnan(onto.world[:, 1]).all()
    assert np.array_equal(motion.filled().world, world)
    assert np.array_equal(Motion(world, 30.0, PARTS).root_relative("root").world, world)
    with pytest.raises(ValueError, match="world positions have shape"):
        Motion(local, 30.0, PARTS, None, world[:, :2])
    log = ObservationLog(PARTS, 30.0, capacity=2)
    log.extend(local, np.ones(local.shape[:2], dtype=bool), world)
    assert np.array_equal(log.motion(3, 6).world, world[3:6])


# -- the posegraph: travel per node, cycles ----------------------------------------------------------------------


def _step_cycle(frames: int, direction: float, fps: float = 30.0, cycles: int = 1, phase: float = 0.0) -> np.ndarray:
    """``cycles`` gait cycles of ``frames`` frames each, and the first frame of the next: the stick's feet swing
    forward and back once a cycle while the root travels along the facing (+z) at ``direction`` m/s; a cycle ends
    where it began, root-relative, with the feet 0.6 m apart (away from standing), or as far into the cycle as
    ``phase`` says."""
    k = np.arange(cycles * frames + 1)
    swing = 0.3 * np.cos(2 * np.pi * k / frames + phase)
    pose = np.repeat(STAND[None], len(k), axis=0).copy()
    pose[:, 5, 2] += swing
    pose[:, 6, 2] -= swing
    pose[:, :, 2] += direction * (k / fps)[:, None]
    return pose


def _raise_hand(frames: int = 30) -> np.ndarray:
    pose = np.repeat(STAND[None], frames, axis=0).copy()
    pose[:, 4, 1] += 0.5 * np.sin(np.linspace(0, np.pi, frames))
    return pose


@pytest.fixture(scope="module")
def clips(tmp_path_factory):
    """A repertoire of clips: ``raise`` (a gesture from standing to standing, four takes), ``walk`` and ``back``
    (one gait cycle each, the same leg swings from two points of the cycle, forwards and backwards: their ends are
    too few to make a hub), and a profile."""
    root = tmp_path_factory.mktemp("travel")
    for take, frames in enumerate((30, 36, 42, 48)):
        write_stick_clip(root / "repertoire" / "raise" / f"{take}.bvh", _raise_hand(frames))
    write_stick_clip(root / "repertoire" / "walk" / "a.bvh", _step_cycle(30, 1.2)[:-1])
    write_stick_clip(root / "repertoire" / "back" / "a.bvh", _step_cycle(30, -1.2, phase=np.pi)[:-1])
    write_stick_profile(root)
    return root


def _observer(clips, **matcher):
    pm = create_plugin_manager(autoload=False, trace=False)
    profile = load_profile(clips / "profile.toml")
    return profile, compose_observer(pm, profile, clips / "repertoire", lengths_for_height=0,
                                     settings={"matcher": matcher} if matcher else None)



def test_each_node_of_a_clip_knows_where_the_body_travelled(clips):
    _, observer = _observer(clips)
    motor = observer.motor
    for movement, speed in (("walk", 1.2), ("back", -1.2), ("raise", 0.0)):
        nodes = [motor.node_index(n) for n in motor.paths[movement][1:-1]]
        # the travel and the facing come from the same low-passed clip (plugins.lib.lowpass): a walk at even speed
        # stays at its speed
        assert np.allclose(motor.node_travel[nodes], [0.0, 0.0, speed], atol=1e-6)
    hubs = [motor.node_index(h) for h in motor.hubs]
    assert np.allclose(motor.node_travel[hubs], 0.0)


def test_a_clip_that_is_one_cycle_away_from_every_hub_loops_and_a_gesture_does_not(clips):
    _, observer = _observer(clips)
    motor = observer.motor
    loops = {(a, b) for a, b, d in motor.graph.edges(data=True) if d.get("cycle")}
    assert loops == {(motor.paths[m][-2], motor.paths[m][1]) for m in ("walk", "back")}
    pm = create_plugin_manager(autoload=False, trace=False)
    plain = compose_observer(pm, load_profile(clips / "profile.toml"), clips / "repertoire", lengths_for_height=0,
                             settings={"motor": {"cycles": False}})
    assert not any(d.get("cycle") for _, _, d in plain.motor.graph.edges(data=True))


def test_travel_tells_forwards_from_backwards_where_the_poses_are_the_same(clips):
    """Three cycles of the walk and of the walk backwards, watched from the same point of the cycle: their
    root-relative poses are the same, all the paper's eq. 1 sees; the motion comparison carries every part along
    where the body goes, and each is itself (the comparison alone: the takes' strokes, beside it in the template,
    are :func:`test_the_takes_strokes_see_where_the_root_went`'s)."""
    from toolkit.observe import Observer

    profile, observer = _observer(clips, comparison="motion")
    watch = Observer(observer, profile.body, 30.0)
    answers, poses = {}, {}
    for movement, speed in (("walk", 1.2), ("back", -1.2)):
        gait = Motion(_step_cycle(30, speed, cycles=3), 30.0, PARTS)  # from the same point of the cycle
        poses[movement] = gait.root_relative("root").positions
        answers[movement] = watch.classify(gait).match
    assert np.allclose(poses["walk"], poses["back"])
    assert answers["walk"].movement == "walk" and answers["back"].movement == "back"
    assert {observer.motor.movement_of(n) for n in answers["walk"].path} == {"walk"}


def test_the_takes_strokes_see_where_the_root_went(clips):
    """The strokes beside the motion comparison cut the root's travel as one more path
    (plugins.matchers.strokes_evidence.TravelStrokes): a walk forwards and one backwards from the same point of the
    cycle make the same strokes of the feet, and opposite strokes of the root, along the facing."""
    from plugins.lib.clip_repertoire import root_relative_motion
    from plugins.matchers.strokes_evidence import TakeStrokes

    body = load_profile(clips / "profile.toml").body
    strokes = TakeStrokes(body)
    walk, back = (strokes.series(root_relative_motion(Motion(_step_cycle(30, speed, cycles=3), 30.0, PARTS), body))
                  for speed in (1.2, -1.2))
    for feet, other in zip(walk[:-1], back[:-1]):
        np.testing.assert_allclose(feet, other, atol=1e-9)
    assert len(walk[-1]) == len(back[-1]) == 1 and walk[-1][0, 2] > 0.2
    np.testing.assert_allclose(back[-1], -walk[-1], atol=1e-9)


def test_a_key_posed_bob_travels_down_then_up(pm, write):
    """Key poses are in the body's own frame: the root's own motion there is the travel of the nodes (a mouse's
    jump), measured as an observer measures it: the stick bobs 0.2 m down in 0.5 s and back."""
    motor = load_character(write("bob.toml", STICK.replace('plugin = "keyframe"', 'plugin = "posegraph"')), pm).motor
    nodes = [motor.node_index(n) for n in motor.paths["bob"][1:-1]]
    rise = motor.node_travel[nodes, 1]
    assert (rise[:3] < -0.2).all() and (rise[-3:] > 0.2).all()
    assert np.allclose(motor.node_travel[nodes][:, [0, 2]], 0.0)
