"""Predicting what another will do next (Buchsbaum & Blumberg 2005, §7.4).

"The simplest way to do this would be for a character to evaluate their action
hierarchy using conditions that assume the success of the identified action
tuple": when Max sees Morris reach for the cheese, the success context of his
own reach is holding the object, so he imagines Morris holding the cheese and
checks which of his own action tuples could run then (eat: can-I holding). "Which
of his own behaviors tend to follow which" (his tuple-to-tuple transition map,
filled while he acts) ranks the candidates.

1. The success context: the do-until triggers of the identified leaf tuple, else
   of its closest ancestor that has any (a leaf is a means to its parent's end).
   Without one there is nothing to imagine and nothing is predicted.
2. The imagined world: each success trigger imagines the world in which it holds
   (``imagine(context)``, see :mod:`plugins.triggers`), one after the other, from
   the objects as they were when the movement began; a trigger that cannot
   imagine (no ``imagine``) leaves the world as it is. The success context must
   hold in the imagined world, else nothing is predicted.
3. The candidates: every leaf tuple some path of which is possible for the target
   in the imagined world, with the same object of attention (its object selection
   and can-I triggers, evaluated for the target with the observer's beliefs).
4. The order: how often the observer itself went from the identified leaf to the
   candidate (its transition map), then those serving the same drive, then by name.
"""

from __future__ import annotations

from types import SimpleNamespace
from typing import Any

from plugins.action.action_tuple import evaluate_path
from toolkit import TriggerContext

__all__ = ["predict", "success_context", "imagine"]


def success_context(system: Any, path: tuple[str, ...]) -> list[Any]:
    """The do-until triggers of the lowest tuple on ``path`` (leaf first, then up) that has any; else ``[]``."""
    for name in reversed(path):
        until = system.hierarchy.tuples[name].until
        if until:
            return list(until)
    return []


def imagine(triggers: list[Any], target: Any, objects: dict[str, Any], obj: str | None,
            beliefs: dict[str, str]) -> dict[str, Any] | None:
    """The objects of a world in which every trigger of ``triggers`` holds for ``target`` and ``obj``; else ``None``."""
    world = SimpleNamespace(objects=dict(objects))
    for trigger in triggers:
        make = getattr(trigger, "imagine", None)
        if make is None:
            continue
        imagined = make(TriggerContext(target, world, obj, beliefs, {}))
        if imagined is not None:
            world = SimpleNamespace(objects=imagined)
    context = TriggerContext(target, world, obj, beliefs, {})
    if not all(trigger.evaluate(context) > 0 for trigger in triggers):
        return None
    return world.objects


def predict(system: Any, target: Any, path: tuple[str, ...], obj: str | None, then: Any) -> tuple[str, ...]:
    """What ``target`` will do next once the behaviour ``path`` on ``obj`` succeeds (§7.4), best first.

    Parameters
    ----------
    system : Hierarchical
        The observer's action system: its hierarchy, beliefs and transition map.
    target : Actor
        The character observed (the triggers are evaluated for it).
    path : tuple of str
        The identified behaviour, top to leaf.
    obj : str or None
        Its object of attention.
    then : any
        Anything with ``objects``: the objects as the observer knows them when the movement began.

    Returns
    -------
    tuple of str
        ``"<movement> the <object>"`` for each candidate, most likely first; empty when nothing can be predicted.
    """
    h = system.hierarchy
    if obj is None or obj not in then.objects:
        return ()
    triggers = success_context(system, path)
    if not triggers:
        return ()
    imagined = imagine(triggers, target, then.objects, obj, system.beliefs)
    if imagined is None:
        return ()
    world = SimpleNamespace(objects=imagined)
    leaf = path[-1]
    candidates = []
    for name, t in h.tuples.items():
        if not t.leaf:
            continue
        for p in h.paths_to(name):
            ok, selected = evaluate_path(system, target, world, p, obj, system.beliefs)
            if ok and selected == obj:
                rank = (-system.transitions.get((leaf, name), 0), h.drive_of(p) != h.drive_of(path), name)
                candidates.append((rank, f"{t.movement} the {obj}"))
                break
    return tuple(dict.fromkeys(text for _, text in sorted(candidates)))
