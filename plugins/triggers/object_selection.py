"""Object-selection triggers: can-I triggers that also choose the object of attention.

Buchsbaum & Blumberg 2005, §6.1.1: "food object present" and "toy object
present" are *object selection triggers*: they check whether any appropriate
object is available and, if so, select one of them as the object of attention
for every action tuple below. What is "appropriate" is what the evaluating
character *believes* the object affords (its beliefs, §6.3), not what the
object is. The character itself attends to the closest such object (§6.1.2:
"generally the closest object of that type"); an observer that has found the
target's line of sight passes that object in instead.
"""

from __future__ import annotations

import numpy as np

from toolkit import Parameter, Trigger, TriggerContext, hookimpl

__all__ = ["ObjectPresent", "closest_object"]


def closest_object(context: TriggerContext, category: str, prefer: str = "closest") -> str | None:
    """The object believed to afford ``category``, not held by someone else, that the actor prefers.

    ``prefer`` is ``"closest"`` (to the actor's root), ``"farthest"`` or ``"largest"`` (by radius). Objects named in
    ``context.params["ignored"]`` (those the action system has given up on) are left out.
    """
    root = context.actor.world_pose()[context.actor.body.root_index]
    ignored = context.params.get("ignored", ())
    candidates = [
        (name, obj) for name, obj in context.world.objects.items()
        if context.category(obj) == category and obj.held_by in (None, context.actor.id) and name not in ignored
    ]
    if not candidates:
        return None
    if prefer == "largest":
        return max(candidates, key=lambda c: (c[1].radius, -float(np.linalg.norm(c[1].position - root))))[0]
    sign = -1.0 if prefer == "farthest" else 1.0
    return min(candidates, key=lambda c: sign * float(np.linalg.norm(c[1].position - root)))[0]


class ObjectPresent(Trigger):
    """Can-I and object selection: an object believed to afford `kind` is present (§6.1.1)."""

    name = "object-present"
    parameters = (
        Parameter("kind", str, doc="The category the object must afford, as the character believes (food, toy)."),
        Parameter("prefer", str, "closest", "Which qualifying object the character attends to.",
                  choices=("closest", "farthest", "largest")),
    )

    def select(self, context: TriggerContext) -> str | None:
        """The object of attention: the one already attended if it qualifies, else the closest that does."""
        obj = context.attended()
        if (obj is not None and context.category(obj) == self.params["kind"] and obj.held_by in (None, context.actor.id)
                and context.object not in context.params.get("ignored", ())):
            return context.object
        return closest_object(context, self.params["kind"], self.params["prefer"])

    def evaluate(self, context: TriggerContext) -> float:
        return 1.0 if self.select(context) is not None else 0.0

    def describe(self) -> str:
        return f"{self.params['kind']} object present"


@hookimpl
def likeme_register_triggers():
    return [ObjectPresent]
