"""The runtime: a world stepping actors through act, perceive, segment, match, interpret, respond."""

from __future__ import annotations

import numpy as np
import pytest

from tests.conftest import CHARACTERS
from toolkit import (
    ConfigError,
    Percept,
    Perception,
    PluginError,
    World,
    WorldObject,
    hookimpl,
    load_character,
    load_scenario,
)
from toolkit.manager import PluginInfo


def _performed_frames(pm, watch_scene, moves):
    """Run Morris alone to learn on which world frames each movement starts and ends."""
    world = load_scenario(watch_scene(moves), pm).run()
    morris = world.actors["morris"]
    spans = []
    for frame, request in morris.performed:
        n = morris.character.motor.perform(request.movement, fps=world.fps).n_frames
        spans.append((frame, frame + n))
    return world, spans


def test_script_performs_its_movements_in_order_and_returns_to_rest(pm, watch_scene):
    world, spans = _performed_frames(pm, watch_scene, ["jump", "wave"])
    morris = world.actors["morris"]
    assert [r.movement for _, r in morris.performed] == ["jump", "wave"]
    assert spans[1][0] - spans[0][1] == pytest.approx(15, abs=1)  # 0.5 s pause in the hub
    assert morris.idle
    np.testing.assert_allclose(morris.local_pose(), morris.character.motor.rest_pose())
    # Morris faces Max: his nose is nearer to Max than his root is
    pose = morris.world_pose()
    assert pose[morris.body.index("nose"), 2] < pose[morris.body.root_index, 2]


def test_perceive_segment_match_respond(pm, watch_scene, recorder, scripted):
    _, spans = _performed_frames(pm, watch_scene, ["jump", "cover_face"])
    recorder.calls.clear()
    cuts = [[s - 1, e - 1] for s, e in spans]  # memory row 0 is world frame 1: Max watches from the first step
    path = watch_scene(
        ["jump", "cover_face"],
        f'[actors.override.segmenter]\nplugin = "scripted-cuts"\ncuts = {cuts}\n'
        '[actors.override.matcher]\nplugin = "nearest-movement"\n',
    )
    world = load_scenario(path, pm).run()
    names = recorder.names()
    assert names.count("segment_found") == 2
    recognised = [c["match"].movement for n, c in recorder.calls if n == "movement_recognised"]
    assert recognised == ["jump", "cover_face"]
    max_ = world.actors["max"]
    assert [(r.movement, r.imitating) for _, r in max_.performed] == [("jump", "morris"), ("cover_face", "morris")]
    started = [c for n, c in recorder.calls if n == "imitation_started"]
    stopped = [c for n, c in recorder.calls if n == "imitation_stopped"]
    assert [c["movement"] for c in started] == ["jump", "cover_face"]
    assert [c["reason"] for c in stopped] == ["completed", "completed"]
    assert names.count("world_stepped") == world.frame
    assert names.count("character_composed") == 2
    # events are also kept on the world, in order
    kinds = [e.kind for e in world.events]
    assert kinds.index("segment_found") < kinds.index("movement_recognised") < kinds.index("imitation_started")
    # working memory holds every perceived frame; Max's synthetic vision loses Morris's nose behind his hands
    assert max_.memory.n == world.frame
    nose = max_.memory.visible[:, world.actors["morris"].body.index("nose")]
    assert 0 < (~nose).sum() < 0.5 * len(nose)


def test_streaming_matcher_commits_before_the_segment_ends(pm, watch_scene, recorder, scripted):
    _, spans = _performed_frames(pm, watch_scene, ["wave"])
    (s, e), = spans
    recorder.calls.clear()
    path = watch_scene(
        ["wave"],
        f'[actors.override.segmenter]\nplugin = "scripted-cuts"\ncuts = [[{s - 1}, {e - 1}]]\n'
        '[actors.override.matcher]\nplugin = "early-commit"\nmovement = "wave"\nafter = 5\n',
    )
    world = load_scenario(path, pm).run()
    recognised = [(c["segment"], c["match"]) for n, c in recorder.calls if n == "movement_recognised"]
    assert len(recognised) == 1
    segment, match = recognised[0]
    assert segment is None and match.decided_at == 5 and match.movement == "wave"
    event = world.events_of("movement_recognised")[0]
    assert event.frame == s + 4  # the fifth frame of the segment
    imitation = world.actors["max"].performed[0]
    assert imitation[0] < e  # response facilitation: Max starts before Morris ends


@pytest.mark.parametrize("typed", [True, False])
def test_a_deviation_stops_the_imitation_with_the_matchers_reason(pm, watch_scene, recorder, scripted, typed):
    """K&G Fig. 3's "stop imitation": the runtime reads the typed ``Match.stop`` and ``Match.reason``; a "stop" in
    the matcher's own ``details`` is not an order."""
    _, spans = _performed_frames(pm, watch_scene, ["wave"])
    (s, e), = spans
    recorder.calls.clear()
    path = watch_scene(
        ["wave"],
        f'[actors.override.segmenter]\nplugin = "scripted-cuts"\ncuts = [[{s - 1}, {e - 1}]]\n'
        f'[actors.override.matcher]\nplugin = "deviating"\nmovement = "wave"\nafter = 5\ndeviate = 8\n'
        f'typed = {str(typed).lower()}\n',
    )
    load_scenario(path, pm).run()
    stopped = [c["reason"] for n, c in recorder.calls if n == "imitation_stopped"]
    assert stopped == (["it sped up"] if typed else ["completed"])


def test_watching_needs_a_perception(pm, watch_scene):
    path = watch_scene(["jump"])
    scenario = load_scenario(path, pm)
    max_ = scenario.world.actors["max"]
    max_.character.perception = None
    with pytest.raises(ConfigError, match=r"max cannot watch morris: character Max has no \[perception\] table.*available: motion-capture"):
        max_.watch(scenario.world.actors["morris"])


def test_a_component_that_raises_is_reported_by_name_and_method(pm, watch_scene):
    class Broken(Perception):
        """Always fails."""

        name = "broken"

        def perceive(self, observer, target, world):
            raise ValueError("lens cap on")

    class Plugin:
        @hookimpl
        def likeme_register_perceptions(self):
            return [Broken]

    pm.register_plugin(Plugin(), PluginInfo("broken-plugin", "m", "(tests)", ""))
    path = watch_scene(["jump"], '[actors.override.perception]\nplugin = "broken"')
    scenario = load_scenario(path, pm)
    with pytest.raises(PluginError, match=r"plugin 'broken' failed in Broken.perceive: ValueError: lens cap on"):
        scenario.run()


def test_held_object_follows_the_holder(pm):
    world = World(fps=30)
    morris = world.add_actor(load_character(CHARACTERS / "morris.toml", pm), position=(1.0, 0.0, 0.0))
    cheese = world.add_object(WorldObject("cheese", "food", (0, 0, 0), held_by="morris", properties={"held_in": "right_hand"}))
    world.step()
    np.testing.assert_allclose(cheese.position, morris.world_pose()[morris.body.index("right_hand")])
    with pytest.raises(ConfigError, match="duplicate object name 'cheese'"):
        world.add_object(WorldObject("cheese", "food", (0, 0, 0)))
    with pytest.raises(ConfigError, match="duplicate actor id 'morris'"):
        world.add_actor(morris.character)


def test_request_of_unknown_movement_lists_the_repertoire(pm):
    from toolkit import MovementRequest

    world = World(fps=30)
    max_ = world.add_actor(load_character(CHARACTERS / "max.toml", pm))
    with pytest.raises(ConfigError, match=r"max has no movement 'fly'.*available: stand, jump, cover_face, wave, reach, reach_high"):
        max_.request(MovementRequest("fly"))


def test_percept_of_motion_capture_is_root_relative(pm, watch_scene):
    scenario = load_scenario(watch_scene(["jump"]), pm)
    world = scenario.world
    world.step()
    max_, morris = world.actors["max"], world.actors["morris"]
    from plugins.perception.motion_capture import MotionCapture

    perception = MotionCapture()  # exact (Max's own eye is a camera, off by its pixels)
    perception.attach(max_.character)
    perception.reset(world.fps)
    percept = perception.perceive(max_, morris, world)
    assert isinstance(percept, Percept)
    rest = morris.character.motor.rest_pose()
    np.testing.assert_allclose(percept.pose, rest - rest[morris.body.root_index], atol=1e-9)
    assert percept.heading == pytest.approx(np.pi)
