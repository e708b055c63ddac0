"""Identifying behaviour, motivation and goal, learning affordances, predicting (Buchsbaum & Blumberg 2005, §6, §7.4).

Given a movement the observer recognised, it asks its *own* action hierarchy
what it would have been doing in the target's place (simulation theory):

1. the leaf tuples that requested this movement, from the observer's
   movement-action correspondence map (most used first), else from its
   declaration (§6.1.1, Fig. 11);
2. every path from the top of the hierarchy down to those leaves (Fig. 12);
3. the order in which to try them: if the target's line of sight (its head and
   nose, both visible) falls on an object, the paths whose motivational
   subsystem selects that kind of object first; otherwise the observer's own
   most frequent motivation for the movement first (§6.1.2);
4. along each path, the can-I triggers are evaluated *for the target* and
   *against the world as it was when the movement began* (not now); an object
   selection trigger picks the object in the line of sight, else the one the
   observer would attend to (the closest of that kind). The first path whose
   triggers all hold is the identified behaviour; the rest are the fall back;
5. the should-I triggers of the path are the likely motivation, its do-until
   (success) contexts the goal (§6.2);
6. if no path is possible and the movement serves only one drive, the observer
   re-evaluates with an object it knows nothing about assumed to afford what
   that drive needs, and if that makes the behaviour possible it learns the
   affordance (§6.3: the ice cream becomes food);
7. otherwise the answer is an explicit "I don't know" (a shrug);
8. prediction (§7.4): the leaf tuples whose can-I triggers the success of the
   identified behaviour would satisfy (holding the cheese makes eating
   possible), ranked by the observer's own tuple-to-tuple transition map.
"""

from __future__ import annotations

from collections import Counter
from types import SimpleNamespace
from typing import Any

import numpy as np

from plugins.action.action_tuple import ActionTuple
from plugins.action.prediction import predict
from toolkit import Behaviour, TriggerContext

__all__ = ["identify", "line_of_sight", "evaluate_path", "predict"]


def line_of_sight(system: Any, observer: Any, target: Any, row: int, objects: dict[str, Any]) -> str | None:
    """The object the target was looking at around memory row ``row``, from its seen head and nose; else ``None``."""
    memory = observer.memory
    if memory is None or memory.n == 0:
        return None
    parts = memory.parts  # the observer's own parts, onto which it perceives the target's
    a, b = (parts.index(p) if p in parts else None for p in system.params["gaze"])
    if a is None or b is None:
        return None
    both = memory.visible[:, a] & memory.visible[:, b]
    if not both.any():
        return None
    rows = np.flatnonzero(both)
    r = int(rows[np.argmin(np.abs(rows - row))])
    if abs(r - row) > memory.fps:  # nothing seen within a second of the movement
        return None
    head, nose = memory.world[r, a], memory.world[r, b]
    gaze = (nose - head)[[0, 2]]
    if np.linalg.norm(gaze) < 1e-9:
        return None
    best, best_angle = None, np.radians(system.params["sight_angle"])
    for name, obj in objects.items():
        if obj.held_by is not None and obj.held_by != target.id:
            continue
        to = (obj.position - head)[[0, 2]]
        if np.linalg.norm(to) < 1e-9:
            continue
        angle = np.arccos(np.clip(np.dot(gaze, to) / (np.linalg.norm(gaze) * np.linalg.norm(to)), -1, 1))
        if angle <= best_angle:
            best, best_angle = name, angle
    return best


def evaluate_path(system: Any, target: Any, world: Any, path: tuple[str, ...], attention: str | None,
                  beliefs: dict[str, str]) -> tuple[bool, str | None]:
    """Whether every can-I trigger along ``path`` holds for ``target`` in ``world``; and the object of attention."""
    context = TriggerContext(target, world, attention, beliefs, {})
    obj = attention
    for name in path:
        t: ActionTuple = system.hierarchy.tuples[name]
        if t.select is not None:
            obj = t.select.select(context)
            if obj is None:
                return False, None
            context = TriggerContext(target, world, obj, beliefs, {})
        if any(trigger.evaluate(context) <= 0 for trigger in t.can):
            return False, obj
    return True, obj


def _words(text: str, obj: str | None) -> str:
    return text.replace("the object", f"the {obj}") if obj else text


def _category(system: Any, top: str) -> str | None:
    select = system.hierarchy.tuples[top].select
    return select.params.get("kind") if select is not None else None


def _ordered_paths(system: Any, movement: str, seen: str | None, objects: dict[str, Any]) -> list[tuple[str, ...]]:
    h = system.hierarchy
    counts: Counter = system.correspondence.get(movement, Counter())
    leaves = [p[-1] for p, _ in counts.most_common()] + h.leaves_for(movement)
    leaves = list(dict.fromkeys(leaves))
    paths = list(dict.fromkeys(p for leaf in leaves for p in h.paths_to(leaf)))
    habit = Counter()
    for p, n in counts.items():
        habit[p[0]] += n
    first = []
    if seen is not None:
        kind = system.beliefs.get(objects[seen].kind)
        first = [p for p in paths if kind is not None and _category(system, p[0]) == kind]
    rest = sorted((p for p in paths if p not in first), key=lambda p: -habit[p[0]])
    return first + rest


def identify(system: Any, observer: Any, target: Any, movement: str, start_frame: int, row: int, world: Any) -> Behaviour | None:
    """Identify the behaviour behind ``movement``, which ``target`` began at world frame ``start_frame``.

    ``row`` is the row of the observer's working memory to look for the target's line of sight at (the
    segment's middle). Returns ``None`` when no behaviour of the observer uses the movement at all.
    """
    objects = world.objects_at(start_frame)
    then = SimpleNamespace(objects=objects, frame=start_frame, time=start_frame / world.fps)
    seen = line_of_sight(system, observer, target, row, objects)
    paths = _ordered_paths(system, movement, seen, objects)
    if not paths:
        return None  # a movement no behaviour of the observer uses: there is nothing to identify
    tried = []
    for path in paths:
        attention = seen if seen is not None and _category(system, path[0]) == system.beliefs.get(objects[seen].kind) else None
        ok, obj = evaluate_path(system, target, then, path, attention, system.beliefs)
        tried.append(" > ".join(path))
        if ok:
            return _behaviour(system, target, movement, path, obj, then, seen, tried)
    if system.params["learn_affordances"]:
        learned = _learn_affordance(system, target, movement, paths, then, seen)
        if learned is not None:
            return learned
    return Behaviour(False, movement, details={"reason": "no behaviour of mine with this movement was possible", "tried": tried,
                                               "line_of_sight": seen})


def _behaviour(system: Any, target: Any, movement: str, path: tuple[str, ...], obj: str | None, then: Any,
               seen: str | None, tried: list[str], **details: Any) -> Behaviour:
    h = system.hierarchy
    motivation = tuple(dict.fromkeys(t.describe() for name in path for t in h.tuples[name].should))
    goal = tuple(dict.fromkeys(_words(t.describe(), obj) for name in path for t in h.tuples[name].until))
    prediction = predict(system, target, path, obj, then)
    return Behaviour(
        True, movement, path=path, motivation=motivation, goal=goal, object=obj, prediction=prediction,
        details={"line_of_sight": seen, "tried": tried, "drive": h.drive_of(path), **details},
    )


def _learn_affordance(system: Any, target: Any, movement: str, paths: list[tuple[str, ...]], then: Any,
                      seen: str | None) -> Behaviour | None:
    drives = {system.hierarchy.drive_of(p) for p in paths}
    if len(drives) != 1:
        return None  # the movement serves several purposes: nothing to conclude
    categories = {_category(system, p[0]) for p in paths} - {None}
    if len(categories) != 1:
        return None
    category = categories.pop()
    unknown = {n: o for n, o in then.objects.items() if o.kind not in system.beliefs}
    if not unknown:
        return None
    if seen in unknown:
        candidates = [seen]
    else:
        root = target.world_pose()[target.body.root_index]
        candidates = sorted(unknown, key=lambda n: float(np.linalg.norm(unknown[n].position - root)))
    for name in candidates:
        assumed = dict(system.beliefs)
        assumed[unknown[name].kind] = category
        for path in paths:
            ok, obj = evaluate_path(system, target, then, path, name, assumed)
            if ok and obj == name:
                system.beliefs[unknown[name].kind] = category
                return _behaviour(system, target, movement, path, obj, then, seen, [" > ".join(p) for p in paths],
                                  learned={unknown[name].kind: category})
    return None

