"""Every hook call goes through pluggy: tracing shows the run events as they happen, and one failure policy holds for
every hook, whoever calls it (the world, a component announcing what it learned, the registry)."""

from __future__ import annotations

import re

import pytest

from tests.conftest import make_plugin
from tests.fixtures.recorder import Recorder
from toolkit import PluginError, create_plugin_manager, hookimpl, load_scenario
from toolkit.cli import main
from toolkit.manager import PluginInfo

RUN_EVENTS = ("movement_started", "segment_found", "movement_recognised", "behaviour_identified", "imitation_started",
              "imitation_stopped", "movement_learned")


def _traced_hooks(text: str) -> list[str]:
    """The hook names of the calls a trace printed, in order (``finish`` lines left out)."""
    return re.findall(r"^\s*likeme_(\w+) \[hook\]$", text, re.M)


def test_trace_hooks_prints_every_run_event_as_it_happens(monkeypatch, capsys):
    """``LIKEME_TRACE_HOOKS=1 likeme run jump_then_cover_face``: a percept a frame, then segmented, recognised and
    movement started, in the order the world recorded them, interleaved with the frames they happened on."""
    monkeypatch.setenv("LIKEME_TRACE_HOOKS", "1")
    monkeypatch.setenv("LIKEME_DISABLE_PLUGIN_AUTOLOAD", "1")
    assert main(["run", "jump_then_cover_face", "--json"]) == 0
    trace = capsys.readouterr().err
    hooks = _traced_hooks(trace)
    for kind in ("target_perceived", "segment_found", "movement_recognised", "movement_started", "world_stepped"):
        assert kind in hooks, kind
    assert hooks.count("register_perceptions") >= 1 and "character_composed" in hooks  # loading is traced too
    # the same run, untraced, records its events: the trace shows the same events in the same order
    world = load_scenario("jump_then_cover_face", create_plugin_manager(autoload=False, trace=False)).run()
    assert [h for h in hooks if h in RUN_EVENTS] == [e.kind for e in world.events if e.kind in RUN_EVENTS]
    # as they happen: each frame's percepts come before that frame's world_stepped, and every event between them
    steps = [i for i, h in enumerate(hooks) if h == "world_stepped"]
    assert len(steps) == world.frame
    perceived = [i for i, h in enumerate(hooks) if h == "target_perceived"]
    assert len(perceived) == world.actors["max"].percepts
    first_segment = hooks.index("segment_found")
    frame = sum(1 for i in steps if i < first_segment) + 1  # the world frame the trace printed it in
    assert frame == world.events_of("segment_found")[0].frame


class _Failing:
    """Raises in a run-event hook: in the first segment found, or in the first movement learned."""

    def __init__(self, hook: str) -> None:
        self.hook = hook

    @hookimpl
    def likeme_segment_found(self, world, observer, target, segment):
        if self.hook == "segment_found":
            raise RuntimeError("disk full")

    @hookimpl
    def likeme_movement_learned(self, character, movement, details):
        if self.hook == "movement_learned":
            raise RuntimeError("disk full")


def test_a_failing_run_event_hook_is_named_or_skipped_through_the_plugin_manager():
    pm = create_plugin_manager(autoload=False, trace=False)
    before, after = Recorder(), Recorder()
    pm.register(before, name="before")  # registered before the failing plugin: pluggy calls it after
    pm.register_plugin(_Failing("segment_found"), PluginInfo("failing", "m", "(tests)", ""))
    pm.register(after, name="after")
    with pytest.raises(PluginError, match=r"plugin 'failing' failed in likeme_segment_found: RuntimeError: disk full"):
        load_scenario("jump_then_cover_face", pm).run()

    pm = create_plugin_manager(autoload=False, trace=False)
    before, after = Recorder(), Recorder()
    pm.register(before, name="before")
    pm.register_plugin(_Failing("segment_found"), PluginInfo("failing", "m", "(tests)", ""))
    pm.register(after, name="after")
    world = load_scenario("jump_then_cover_face", pm, on_plugin_error="skip").run()
    failed = [e.data for e in world.events if e.kind == "plugin_failed"]
    assert failed == [{"plugin": "failing", "where": "likeme_segment_found",
                       "error": "plugin 'failing' failed in likeme_segment_found: RuntimeError: disk full"}]
    assert not pm.has_plugin("failing")
    # the implementations on either side of the failing one still heard of every segment, the first included
    segments = len(world.events_of("segment_found"))
    assert before.names().count("segment_found") == after.names().count("segment_found") == segments == 2
    assert [c["match"].movement for n, c in before.calls if n == "movement_recognised"] == ["jump", "cover_face"]


def test_keep_going_skips_a_hook_that_fails_inside_a_component(monkeypatch, capsys):
    """A movement learned is announced by the motor system, inside a matcher's call: under --keep-going the failing
    hook plugin is dropped and the learning goes on (the matcher is not blamed, nor dropped)."""
    pm = create_plugin_manager(autoload=False, trace=False)
    pm.register_plugin(_Failing("movement_learned"), PluginInfo("failing", "m", "(tests)", ""))
    monkeypatch.setattr("toolkit.cli.create_plugin_manager", lambda: pm)
    assert main(["run", "learn_windmill", "--keep-going"]) == 0
    out = capsys.readouterr().out
    assert "went on without plugin 'failing' (likeme_movement_learned)" in out
    assert "learned" in out and "plugin 'path-search'" not in out


def test_a_failing_registration_hook_is_named_by_the_plugin_manager():
    def broken():
        raise ValueError("half installed")

    pm = create_plugin_manager(autoload=False, trace=False)
    pm.register_plugin(make_plugin(likeme_register_matchers=broken), PluginInfo("half", "m", "(tests)", ""))
    with pytest.raises(PluginError, match=r"plugin 'half' failed in likeme_register_matchers: ValueError: half installed"):
        pm.registry.names("matcher")
