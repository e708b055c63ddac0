"""Identifying behaviour, motivation and goal, learning affordances, predicting (Buchsbaum & Blumberg 2005, §6, §7.4).

Given a movement the observer recognised, it asks its *own* action hierarchy
what it would have been doing in the target's place (simulation theory). Every
fact it uses about the target and the world comes from its own perception and
memory, never from the world (§6.1.1: "Max must check whether there were any
food or toy objects available at the time he saw Morris reaching"):

- the target as perceived when the movement began (:func:`perceived_target`):
  its parts' world positions from working memory (hidden parts where last
  seen) and its heading as perceived, wrapped as a :class:`PerceivedActor`
  with an actor's interface (``id``, ``body``, ``world_pose()``, ``heading``)
  for the triggers to evaluate;
- the objects as perceived by then (:func:`perceived_objects`, from the
  observer's :class:`~toolkit.sightings.Sightings`): each under the observer's own name for it, where it was last
  seen (an occluded one where it was before it was hidden; one never seen does
  not exist; one missed where it should have been seen is gone), of the kind
  it looked like (its colour and size, :mod:`plugins.perception.object_looks`: a ball painted cheese-yellow is a
  cheese to the observer, and ``details["seen_as"]`` says why), and held by the target when it was seen moving
  with the target's hand (:func:`seen_held`).

So the observer can be wrong where its perception was: an object it never saw
makes no behaviour possible (§7.3.1's perceptual failure).

1. the candidate movements (Fig. 13): the matcher's ranked candidates within
   :data:`MARGIN` of the best (relative to its distance), best first, else the
   recognised movement alone;
2. for each candidate in turn, the leaf tuples that requested this movement, from the observer's
   movement-action correspondence map (most used first), else from its
   declaration (§6.1.1, Fig. 11);
3. every path from the top of the hierarchy down to those leaves (Fig. 12);
4. the order in which to try them: the objects in the target's line of sight, read from its head and nose as
   perceived, in 3D and with the uncertainty of the observer's own perception
   (:mod:`plugins.action.line_of_sight`); the paths whose motivational subsystem selects the kind of an object in
   sight come first; among them, and for the rest, the observer's own most frequent motivation for the movement
   first (§6.1.2). Objects close together are in sight together, and then the habits choose (§7.3.1's natural
   mistake); with no line of sight, the habits alone;
5. along each path, the can-I triggers are evaluated *for the target as
   perceived* and *against the objects as perceived when the movement began*
   (not now); an object selection trigger picks the object in the line of
   sight (of several of its kind in sight, the one the observer would attend to, the closest), else the one the
   observer would attend to (the closest of that kind). The first path whose triggers all hold is the identified
   behaviour; the rest are the fall back. When the motion alone is ambiguous, the can-I
   triggers decide between the candidates (reach or jump: the object within
   reach or high in the air, Fig. 13);
6. the should-I triggers of the path are the likely motivation, its do-until
   (success) contexts the goal (§6.2);
7. if no path is possible and the movement serves only one drive, the observer
   re-evaluates with an object it knows nothing about assumed to afford what
   that drive needs, and if that makes the behaviour possible it learns the
   affordance (§6.3: the ice cream becomes food);
8. otherwise the answer is an explicit "I don't know" (a shrug);
9. prediction (§7.4): the leaf tuples whose can-I triggers the success of the
   identified behaviour would satisfy (holding the cheese makes eating
   possible), ranked by the observer's own tuple-to-tuple transition map.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any

import numpy as np

from plugins.action.action_tuple import evaluate_path
from plugins.action.line_of_sight import in_sight, perceived_gaze
from plugins.action.prediction import predict
from toolkit import Behaviour

__all__ = ["MARGIN", "GRIP", "PerceivedActor", "PerceivedObject", "close_candidates", "identify", "sight",
           "evaluate_path", "perceived_objects", "perceived_target", "predict", "seen_held"]

MARGIN = 0.25
"""The relative margin of Fig. 13 (the default of the hierarchical action system's ``candidate_margin``): a matcher's
candidate whose distance is within ``(1 + MARGIN)`` times the best's is close enough that the motion alone does not
tell them apart, and the can-I triggers decide."""

GRIP = 0.10
"""Metres beyond an object's radius within which it is at the target's hand (seen held, with :func:`seen_held`): a
hand's own size (the object sits in its grip, not at its centre) and what an eye may be off by, a hand seen half
hidden behind what it holds."""

MOVED = 0.02
"""Metres an object must have moved from where it was first seen to have been taken (not lying where it lay)."""


class PerceivedActor:
    """The target as the observer perceived it at one moment: what the triggers evaluate in its place.

    The interface the triggers use of an :class:`~toolkit.runtime.Actor`: ``id``, ``body`` (the observer's own
    body, whose parts working memory holds), :meth:`world_pose` and ``heading``, all as perceived.
    """

    def __init__(self, id: str, body: Any, pose: np.ndarray, heading: float, row: int) -> None:
        self.id = id
        self.body = body
        self._pose = np.asarray(pose, dtype=float)
        self.heading = float(heading)
        self.row = row

    def __repr__(self) -> str:
        return f"PerceivedActor({self.id!r}, row {self.row})"

    def world_pose(self) -> np.ndarray:
        """The parts' world positions as perceived (P, 3): hidden parts where last seen, never seen ones NaN."""
        return self._pose.copy()


@dataclass
class PerceivedObject:
    """An object as the observer perceived it: what the triggers read of an object (kind, position, radius, held_by)."""

    name: str
    kind: str | None
    position: np.ndarray
    radius: float
    held_by: str | None = None
    seen_at: int = 0
    properties: dict[str, Any] = field(default_factory=dict)


def close_candidates(match: Any, margin: float = MARGIN) -> list[str]:
    """The movements the observer cannot tell apart by their motion: the matcher's ranked candidates within
    ``margin`` (relative) of the best, best first; else the recognised movement alone."""
    ranked = [(str(m), float(d)) for m, d in getattr(match, "candidates", ()) or ()]
    if not ranked:
        return [match.movement]
    best = ranked[0][1]
    close = [m for m, d in ranked if np.isfinite(d) and d <= best * (1.0 + margin) + 1e-12]
    return list(dict.fromkeys([match.movement, *close]))


def _row(memory: Any, row: int) -> int:
    """``row`` within the rows working memory still holds."""
    return int(min(max(row, memory.offset), memory.n - 1))


def perceived_target(observer: Any, target: Any, row: int) -> PerceivedActor:
    """The target as the observer perceived it at working memory row ``row``: pose from working memory, heading
    from its sightings."""
    memory = observer.memory
    r = _row(memory, row)
    pose = memory.world[r - memory.offset]
    sightings = getattr(observer, "sightings", None)
    heading = sightings.heading(r) if sightings is not None else float("nan")
    return PerceivedActor(target.id, observer.body, pose, heading, r)


def _hand_parts(memory: Any, body: Any) -> np.ndarray:
    """Indices of the parts that can hold something: the hands (and wrists), else every part but the root."""
    parts = list(memory.parts)
    hands = {h.wrist for h in getattr(body, "hands", {}).values()}
    idx = [i for i, p in enumerate(parts) if "hand" in p or "wrist" in p or p in hands]
    if not idx:
        idx = [i for i, p in enumerate(parts) if p != getattr(body, "root", None)]
    return np.array(idx, dtype=int)


def seen_held(observer: Any, name: str, radius: float, row: int, until: int | None = None) -> bool:
    """Whether the observer saw the target holding object ``name`` at row ``row``: when last seen by then it was at
    one of the target's perceived hands (within :data:`GRIP` of its radius), and while it stayed at the hand (the
    sightings up to ``until``, default ``row``, around that one) it moved with it: it moved more than :data:`MOVED`,
    or it had come to the hand from somewhere else. An object that merely lies next to a hand is not held."""
    memory, sightings = observer.memory, observer.sightings
    rows, positions = sightings.track(name, row if until is None else max(row, until))
    j = int(np.searchsorted(rows, row, side="right")) - 1
    if j < 0:
        return False
    hands = _hand_parts(memory, observer.body)
    held_rows = np.clip(rows, memory.offset, memory.n - 1) - memory.offset
    d = np.linalg.norm(memory.world[held_rows][:, hands] - positions[:, None], axis=2)  # (sightings, hands)
    near = np.nan_to_num(d, nan=np.inf).min(axis=1) <= radius + GRIP
    if not near[j]:
        return False
    apart = np.flatnonzero(~near)
    a = int(apart[apart < j].max()) + 1 if (apart < j).any() else 0  # the stretch of sightings at the hand
    b = int(apart[apart > j].min()) if (apart > j).any() else len(rows)
    stretch = positions[a:b]
    if (np.linalg.norm(stretch - stretch[0], axis=1) > MOVED).any():
        return True  # it moved while at the hand
    return a > 0 and float(np.linalg.norm(positions[a] - positions[a - 1])) > MOVED  # it came to the hand


def perceived_objects(observer: Any, target: Any, row: int, until: int | None = None) -> dict[str, PerceivedObject]:
    """The objects as the observer knew them at row ``row``: last seen positions, kinds as they looked, held by the
    target if seen moving with its hand (judged on the sightings up to ``until``, :func:`seen_held`)."""
    sightings = getattr(observer, "sightings", None)
    if sightings is None:
        return {}
    out = {}
    for name, s in sightings.at(row).items():
        held = target.id if seen_held(observer, name, s.radius, row, until) else None
        out[name] = PerceivedObject(name, s.kind, s.position, s.radius, held, s.row)
    return out


def sight(system: Any, observer: Any, target: Any, row: int, objects: dict[str, Any]) -> list[tuple[str, float]]:
    """The objects in the target's line of sight around memory row ``row``, read from its head and nose as the
    observer perceived them, with the uncertainty of its perception (:func:`plugins.action.line_of_sight.in_sight`):
    (name, degrees off the gaze), nearest first; empty when the head and nose were not seen or no object is in sight."""
    gaze = perceived_gaze(observer, row, tuple(system.params["gaze"]))
    if gaze is None:
        return []
    return in_sight(gaze, objects, system.params["sight_angle"], holder=target.id)


def _words(text: str, obj: str | None) -> str:
    return text.replace("the object", f"the {obj}") if obj else text


def _category(system: Any, top: str) -> str | None:
    select = system.hierarchy.tuples[top].select
    return select.params.get("kind") if select is not None else None


def _ordered_paths(system: Any, movement: str, seen: list[str], objects: dict[str, Any]) -> list[tuple[str, ...]]:
    """The paths to try for ``movement``: those whose motivational subsystem selects the kind of an object in sight
    (``seen``) first, then the rest; each group in the order of the observer's own habits (§6.1.2)."""
    h = system.hierarchy
    counts: Counter = system.correspondence.get(movement, Counter())
    leaves = [p[-1] for p, _ in counts.most_common()] + h.leaves_for(movement)
    leaves = list(dict.fromkeys(leaves))
    paths = list(dict.fromkeys(p for leaf in leaves for p in h.paths_to(leaf)))
    habit = Counter()
    for p, n in counts.items():
        habit[p[0]] += n
    kinds = {system.beliefs.get(objects[n].kind) for n in seen} - {None}
    first = sorted((p for p in paths if _category(system, p[0]) in kinds), key=lambda p: -habit[p[0]])
    rest = sorted((p for p in paths if p not in first), key=lambda p: -habit[p[0]])
    return first + rest


def _attending(system: Any, path: tuple[str, ...], seen: list[str], then: Any) -> tuple[str | None, Any]:
    """The object of attention to evaluate ``path`` with, and the objects to evaluate it against: the one object of
    its kind in sight; of several in sight, the observer's own choice among them (its object selection picks from
    those, the others of the kind left out); none in sight: its own choice among all."""
    category = _category(system, path[0])
    mine = [n for n in seen if category is not None and system.beliefs.get(then.objects[n].kind) == category]
    if len(mine) == 1:
        return mine[0], then
    if not mine:
        return None, then
    kept = {n: o for n, o in then.objects.items() if n in mine or system.beliefs.get(o.kind) != category}
    return None, SimpleNamespace(**{**vars(then), "objects": kept})


def identify(system: Any, observer: Any, target: Any, movements: str | list[str], row: int,
             middle: int | None = None, until: int | None = None) -> Behaviour | None:
    """Identify the behaviour behind the movement ``target`` began at row ``row`` of the observer's working memory.

    ``movements``: the recognised movement, or the candidates the motion does not tell apart, best first
    (:func:`close_candidates`). ``middle`` is the row to look for the target's line of sight at (the segment's
    middle; default ``row``); ``until`` the last row of the movement seen (what was held at its start is judged
    from how the objects moved with the target's hands until then). Only ``target.id`` is read of the target: the rest is what the observer perceived
    (its working memory and sightings). Returns ``None`` when no behaviour of the observer uses the movements at
    all.
    """
    movements = [movements] if isinstance(movements, str) else list(movements)
    memory = observer.memory
    if memory is None or memory.n == 0 or not movements:
        return None
    perceived = perceived_target(observer, target, row)
    objects = perceived_objects(observer, target, row, until)
    then = SimpleNamespace(objects=objects, row=perceived.row, frame=getattr(observer, "watch_start", 0) + perceived.row,
                           time=perceived.row / memory.fps)
    sighted = sight(system, observer, perceived, row if middle is None else middle, objects)
    seen = [n for n, _ in sighted]
    looked = {"line_of_sight": seen[0] if len(seen) == 1 else None, "in_sight": {n: round(a, 1) for n, a in sighted}}
    candidates = {"candidates": movements} if len(movements) > 1 else {}
    tried: list[str] = []
    first_paths: list[tuple[str, ...]] = []
    for movement in movements:
        paths = _ordered_paths(system, movement, seen, objects)
        if not paths:
            continue
        if not first_paths:
            first, first_paths = movement, paths
        for path in paths:
            attention, against = _attending(system, path, seen, then)
            ok, obj = evaluate_path(system, perceived, against, path, attention, system.beliefs)
            tried.append(" > ".join(path))
            if ok:
                return _behaviour(system, perceived, movement, path, obj, then, looked, tried, **candidates)
    if not first_paths:
        return None  # a movement no behaviour of the observer uses: there is nothing to identify
    if system.params["learn_affordances"]:
        learned = _learn_affordance(system, perceived, first, first_paths, then, seen, looked)
        if learned is not None:
            return learned
    return Behaviour(False, first, details={"reason": "no behaviour of mine with this movement was possible", "tried": tried,
                                               **looked, "objects_seen": sorted(objects),
                                               "seen_as": _seen_as(objects, objects), **candidates})


def _seen_as(objects: dict[str, Any], names: Any) -> dict[str, str]:
    """Why each of ``names`` was taken for what it was: its kind and the look that told it (colour, size)."""
    out = {}
    for name in names:
        obj = objects.get(name)
        if obj is not None and obj.kind is not None:
            reason = getattr(obj.kind, "reason", "")
            out[name] = f"{obj.kind}: {reason}" if reason else str(obj.kind)
    return out


def _behaviour(system: Any, target: Any, movement: str, path: tuple[str, ...], obj: str | None, then: Any,
               looked: dict[str, Any], tried: list[str], **details: Any) -> Behaviour:
    h = system.hierarchy
    motivation = tuple(dict.fromkeys(t.describe() for name in path for t in h.tuples[name].should))
    goal = tuple(dict.fromkeys(_words(t.describe(), obj) for name in path for t in h.tuples[name].until))
    prediction = predict(system, target, path, obj, then)
    return Behaviour(
        True, movement, path=path, motivation=motivation, goal=goal, object=obj, prediction=prediction,
        details={**looked, "tried": tried, "drive": h.drive_of(path),
                 **({"seen_as": _seen_as(then.objects, [obj])} if obj is not None else {}), **details},
        learned=details.get("learned", {}),
    )


def _learn_affordance(system: Any, target: Any, movement: str, paths: list[tuple[str, ...]], then: Any,
                      seen: list[str], looked: dict[str, Any]) -> Behaviour | None:
    drives = {system.hierarchy.drive_of(p) for p in paths}
    if len(drives) != 1:
        return None  # the movement serves several purposes: nothing to conclude
    categories = {_category(system, p[0]) for p in paths} - {None}
    if len(categories) != 1:
        return None
    category = categories.pop()
    unknown = {n: o for n, o in then.objects.items() if o.kind is not None and o.kind not in system.beliefs}
    if not unknown:
        return None
    looked_at = [n for n in seen if n in unknown]
    if looked_at:
        candidates = looked_at
    else:  # the closest to the target as perceived (an object at an unknown distance last)
        root = target.world_pose()[target.body.root_index]
        candidates = sorted(unknown, key=lambda n: np.nan_to_num(float(np.linalg.norm(unknown[n].position - root)),
                                                                 nan=np.inf))
    for name in candidates:
        assumed = dict(system.beliefs)
        assumed[str(unknown[name].kind)] = category
        for path in paths:
            ok, obj = evaluate_path(system, target, then, path, name, assumed)
            if ok and obj == name:
                system.beliefs[str(unknown[name].kind)] = category
                return _behaviour(system, target, movement, path, obj, then, looked, [" > ".join(p) for p in paths],
                                  learned={str(unknown[name].kind): category})
    return None
