"""Proximity triggers: where the object of attention is relative to the character (Buchsbaum & Blumberg 2005, §6.1.1).

- ``proximity``: close enough to *get* without walking, and not already held;
- ``reachable``: within reach of the hands, not too high (reach for it);
- ``object-high``: near enough but too high to reach (jump for it, Fig. 13);
- ``holding`` / ``not-holding``: in the character's hands or not (the success
  context of get, §6.2, and the can-I trigger of eat).

Distances are horizontal from the character's root; heights are above the ground.

Each of these triggers can also *imagine* the world in which it holds
(:meth:`Holding.imagine`: the character holds the object), which is how an
observer imagines the success of a behaviour it identified (§7.4, see
:mod:`plugins.action.prediction`).
"""

from __future__ import annotations

import copy
from typing import Any

import numpy as np

from toolkit import Parameter, Trigger, TriggerContext, hookimpl

__all__ = ["Proximity", "Reachable", "ObjectHigh", "Holding", "NotHolding", "horizontal_distance", "imagined_objects"]


def imagined_objects(context: TriggerContext, **changes: Any) -> dict[str, Any] | None:
    """The objects of ``context.world`` with the object of attention changed (``held_by=...``), as copies.

    The real objects are never changed. ``None`` without an object of attention.
    """
    if context.object is None or context.object not in context.world.objects:
        return None
    objects = {n: copy.copy(o) for n, o in context.world.objects.items()}
    obj = objects[context.object]
    obj.properties = dict(obj.properties)
    for key, value in changes.items():
        setattr(obj, key, value)
    return objects


def horizontal_distance(context: TriggerContext) -> float:
    """Horizontal distance from the actor's root to the object of attention (inf without one)."""
    obj = context.attended()
    if obj is None:
        return float("inf")
    root = context.actor.world_pose()[context.actor.body.root_index]
    d = obj.position - root
    return float(np.hypot(d[0], d[2]))


def _free_within(context: TriggerContext, distance: float, low: float, high: float) -> float:
    """1 if the object of attention is free (held by nobody), within ``distance`` and ``low < height <= high``."""
    obj = context.attended()
    if obj is None or obj.held_by is not None:
        return 0.0
    return 1.0 if horizontal_distance(context) <= distance and low < obj.position[1] <= high else 0.0


class Proximity(Trigger):
    """The object of attention is within `distance` (m) and not already held by the character."""

    name = "proximity"
    parameters = (Parameter("distance", float, 0.9, "Farthest horizontal distance (m) at which it can be got without walking.", minimum=0.0),)

    def evaluate(self, context: TriggerContext) -> float:
        obj = context.attended()
        if obj is None or obj.held_by == context.actor.id:
            return 0.0
        return 1.0 if horizontal_distance(context) <= self.params["distance"] else 0.0

    def describe(self) -> str:
        return "object close enough to get"


class Reachable(Trigger):
    """The object of attention is within `distance` (m) and no higher than `height` (m): reach for it."""

    name = "reachable"
    parameters = (
        Parameter("distance", float, 0.5, "Farthest horizontal distance (m) the hands reach.", minimum=0.0),
        Parameter("height", float, 0.6, "Highest point (m above the ground) the hands reach standing.", minimum=0.0),
    )

    def evaluate(self, context: TriggerContext) -> float:
        return _free_within(context, self.params["distance"], -np.inf, self.params["height"])

    def describe(self) -> str:
        return "object within reach"


class ObjectHigh(Trigger):
    """The object of attention is higher than `height` (m) but within `distance` (m): jump for it (Fig. 13)."""

    name = "object-high"
    parameters = (
        Parameter("distance", float, 0.5, "Farthest horizontal distance (m) below which a jump gets it.", minimum=0.0),
        Parameter("height", float, 0.6, "Height (m) above which the hands do not reach standing.", minimum=0.0),
        Parameter("max_height", float, 1.2, "Highest point (m) a jump gets to.", minimum=0.0),
    )

    def evaluate(self, context: TriggerContext) -> float:
        return _free_within(context, self.params["distance"], self.params["height"], self.params["max_height"])

    def describe(self) -> str:
        return "object high in the air"


class Holding(Trigger):
    """The character holds the object of attention (the success context of get, §6.2)."""

    name = "holding"

    def evaluate(self, context: TriggerContext) -> float:
        obj = context.attended()
        return 1.0 if obj is not None and obj.held_by == context.actor.id else 0.0

    def imagine(self, context: TriggerContext) -> dict[str, Any] | None:
        """The world in which this trigger holds: ``context.world``'s objects (copies) with the object of attention
        held by ``context.actor``; ``None`` without an object of attention (§7.4: Morris will hold the cheese)."""
        return imagined_objects(context, held_by=context.actor.id)

    def describe(self) -> str:
        return "holding the object"


class NotHolding(Trigger):
    """The character does not hold the object of attention."""

    name = "not-holding"

    def evaluate(self, context: TriggerContext) -> float:
        obj = context.attended()
        return 1.0 if obj is None or obj.held_by != context.actor.id else 0.0

    def imagine(self, context: TriggerContext) -> dict[str, Any] | None:
        """The world in which this trigger holds: the object of attention (copied) held by nobody (put down)."""
        if context.object is None:
            return dict(context.world.objects)
        obj = context.attended()
        if obj is not None and obj.held_by != context.actor.id:
            return dict(context.world.objects)  # it already holds
        return imagined_objects(context, held_by=None)

    def describe(self) -> str:
        return "not holding the object"


@hookimpl
def likeme_register_triggers():
    return [Proximity, Reachable, ObjectHigh, Holding, NotHolding]
