"""likeme core: the data model, hook specifications, plugin manager, TOML composition and runtime.

The core holds no algorithm; every perception, segmenter, matcher, motor system,
action system and trigger is a plugin (the built-in ones live in the ``plugins``
package and are registered through the same ``likeme`` entry-point group a third
party uses).

Typical use::

    from toolkit import create_plugin_manager, load_scenario

    pm = create_plugin_manager()
    scenario = load_scenario("characters/scenarios/demo.toml", pm)
    world = scenario.run()
    for event in world.events:
        print(event.time, event.kind, event.actor)
"""

from toolkit.body import Body, Facing, Hand
from toolkit.character import Character, load_character
from toolkit.components import (
    ActionSystem,
    Behaviour,
    Component,
    Correspondence,
    Match,
    Matcher,
    MotorSystem,
    MovementRequest,
    Percept,
    Perception,
    Segment,
    Segmenter,
    Trigger,
    TriggerContext,
    View,
)
from toolkit.errors import ConfigError, LikemeError, PluginError
from toolkit.hookspecs import hookimpl
from toolkit.manager import PluginManager, create_plugin_manager
from toolkit.motion import Motion, Pose
from toolkit.params import Parameter
from toolkit.runtime import Actor, Event, World, WorldObject
from toolkit.scenario import Scenario, load_scenario

__version__ = "0.1.0"

__all__ = [
    "ActionSystem",
    "Actor",
    "Behaviour",
    "Body",
    "Character",
    "Component",
    "ConfigError",
    "Correspondence",
    "Event",
    "Facing",
    "Hand",
    "LikemeError",
    "Match",
    "Matcher",
    "Motion",
    "MotorSystem",
    "MovementRequest",
    "Parameter",
    "Percept",
    "Perception",
    "PluginError",
    "PluginManager",
    "Pose",
    "Scenario",
    "Segment",
    "Segmenter",
    "Trigger",
    "TriggerContext",
    "View",
    "World",
    "WorldObject",
    "create_plugin_manager",
    "hookimpl",
    "load_character",
    "load_scenario",
]
