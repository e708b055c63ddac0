"""Hooks not covered elsewhere: triggers, commands, behaviour and learning events."""

from __future__ import annotations

from tests.conftest import CHARACTERS, make_plugin
from toolkit import ActionSystem, Behaviour, Trigger, TriggerContext, World, WorldObject, load_character
from toolkit.manager import PluginInfo


class Near(Trigger):
    """Whether the object of attention is within `distance` of the actor's root."""

    name = "near"

    def evaluate(self, context: TriggerContext) -> float:
        obj = context.world.objects[context.object]
        root = context.actor.world_pose()[context.actor.body.root_index]
        return float(((obj.position - root) ** 2).sum() ** 0.5 <= context.params.get("distance", 0.5))




def test_trigger_registered_through_the_hook_and_evaluated(pm):
    pm.register_plugin(make_plugin(likeme_register_triggers=lambda: [Near]), PluginInfo("near", "m", "(tests)", ""))
    cls = pm.registry.get("trigger", "near")
    world = World()
    max_ = world.add_actor(load_character(CHARACTERS / "max.toml", pm))
    world.add_object(WorldObject("cheese", "food", (0.0, 0.3, 0.3)))
    world.add_object(WorldObject("ball", "toy", (3.0, 0.3, 0.3)))
    assert cls().evaluate(TriggerContext(max_, world, "cheese")) == 1.0
    assert cls().evaluate(TriggerContext(max_, world, "ball")) == 0.0


def test_plugin_adds_a_command(pm, monkeypatch, capsys):
    def likeme_register_commands(subparsers):
        p = subparsers.add_parser("hello", help="say hello")
        p.add_argument("who")
        p.set_defaults(handler=lambda args, pm: print(f"hello {args.who}") or 0)

    from toolkit import cli

    monkeypatch.setattr(cli, "create_plugin_manager", lambda: pm)
    pm.register_plugin(make_plugin(likeme_register_commands=likeme_register_commands), PluginInfo("hello", "m", "(tests)", ""))
    assert cli.main(["hello", "Morris"]) == 0
    assert capsys.readouterr().out == "hello Morris\n"


class Explainer(ActionSystem):
    """Interprets every recognised movement as 'playing' (fixture)."""

    name = "explainer"

    def interpret(self, actor, target, segment, match, world):
        return Behaviour(True, match.movement, path=("play", match.movement), motivation=("playful",))


def test_behaviour_identified_is_announced(pm, watch_scene, recorder, scripted):
    pm.register_plugin(make_plugin(likeme_register_action_systems=lambda: [Explainer]), PluginInfo("explainer", "m", "(tests)", ""))
    scene = watch_scene(
        ["wave"],
        """
        [actors.override.segmenter]
        plugin = "scripted-cuts"
        cuts = [[15, 60]]
        [actors.override.matcher]
        plugin = "nearest-movement"
        [actors.override.action]
        plugin = "explainer"
        """,
    )
    from toolkit import load_scenario
    from toolkit.report import render_text, summarise

    world = load_scenario(scene, pm).run()
    behaviours = [c["behaviour"] for n, c in recorder.calls if n == "behaviour_identified"]
    assert [b.path for b in behaviours] == [("play", "wave")]
    assert world.behaviours("max")[0].motivation == ("playful",)
    assert "Max believes morris did wave (wave > play), because of playful" in render_text(summarise(world))


def test_movement_learned_is_announced_through_the_character(pm, recorder):
    character = load_character(CHARACTERS / "max.toml", pm)
    character.announce("likeme_movement_learned", character=character, movement="new-wave", details={"nodes": 3})
    assert ("movement_learned", {"character": "Max", "movement": "new-wave", "nodes": 3}) in recorder.calls


def test_motor_system_registered_through_the_hook(pm, write):
    import numpy as np

    from toolkit import Motion, MotorSystem, Parameter

    class Statue(MotorSystem):
        """Holds one pose; its only movement is keeping still for `hold` seconds."""

        name = "statue"
        parameters = (Parameter("height", float, 1.0), Parameter("hold", float, 1.0))

        def movements(self):
            return ["hold"]

        def rest_pose(self):
            pose = np.zeros((self.owner.body.n_parts, 3))
            pose[:, 1] = np.linspace(0, self.params["height"], self.owner.body.n_parts)
            return pose

        def perform(self, movement, *, speed=1.0, fps=30.0):
            n = int(self.params["hold"] * fps / speed)
            return Motion(np.repeat(self.rest_pose()[None], n, axis=0), fps, self.owner.body.parts)

    pm.register_plugin(make_plugin(likeme_register_motor_systems=lambda: [Statue]), PluginInfo("statue", "m", "(tests)", ""))
    path = write(
        "statue.toml",
        """
        [character]
        name = "Statue"
        [body]
        parts = ["root", "l", "r"]
        root = "root"
        facing = { left = "l", right = "r" }
        [motor]
        plugin = "statue"
        height = 2.0
        """,
    )
    statue = load_character(path, pm)
    assert statue.motor.perform("hold", fps=10).n_frames == 10
    assert statue.motor.rest_pose()[-1, 1] == 2.0
