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

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"

_EXPORTS: dict[str, str] = {
    "toolkit.body": "Body Facing Hand",
    "toolkit.character": "Character load_character",
    "toolkit.components": "ActionSystem Behaviour Component Correspondence Layer Match Matcher MotorSystem "
                          "MovementRequest Percept Perception Segment Segmenter Trigger TriggerContext View",
    "toolkit.errors": "ConfigError LikemeError PluginError",
    "toolkit.hookspecs": "hookimpl",
    "toolkit.manager": "PluginManager create_plugin_manager",
    "toolkit.motion": "Motion Pose",
    "toolkit.params": "Parameter",
    "toolkit.runtime": "Actor Event World WorldObject",
    "toolkit.scenario": "Scenario load_scenario",
}
"""Where each public name lives. They are imported when first used (``from toolkit import Motion`` imports
:mod:`toolkit.motion` then), so that ``import toolkit`` itself, and ``likeme --version``, load no numpy."""

_MODULE_OF = {name: module for module, names in _EXPORTS.items() for name in names.split()}


def __getattr__(name: str) -> Any:
    """A public name, imported from its module on first use (PEP 562) and kept in this module after."""
    module = _MODULE_OF.get(name)
    if module is None:
        raise AttributeError(f"module 'toolkit' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_MODULE_OF))


if TYPE_CHECKING:  # pragma: no cover - for type checkers and editors: the same names, imported eagerly
    from toolkit.body import Body, Facing, Hand
    from toolkit.character import Character, load_character
    from toolkit.components import (ActionSystem, Behaviour, Component, Correspondence, Layer, Match, Matcher,
                                    MotorSystem, MovementRequest, Percept, Perception, Segment, Segmenter, Trigger,
                                    TriggerContext, View)
    from toolkit.errors import ConfigError, LikemeError, PluginError
    from toolkit.hookspecs import hookimpl
    from toolkit.manager import PluginManager, create_plugin_manager
    from toolkit.motion import Motion, Pose
    from toolkit.params import Parameter
    from toolkit.runtime import Actor, Event, World, WorldObject
    from toolkit.scenario import Scenario, load_scenario


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
    "Layer",
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
