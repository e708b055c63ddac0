"""Action tuples and their hierarchy (Buchsbaum & Blumberg 2005, §6).

An *action tuple* holds an action to perform, trigger contexts in which to
perform it, an optional object of attention, and do-until contexts telling
when it is done. Tuples are organised in levels of *action groups*: the top
level holds one tuple per motivational subsystem (satisfy hunger, play); each
tuple's children are the next level's group, whose tuples are mutually
exclusive; a leaf tuple's action is a movement requested from the motor system.
A tuple may be the child of several parents (``get`` serves hunger and play,
Fig. 12), so the hierarchy is a directed acyclic graph.

Declaration, inside the ``[action]`` table of the ``hierarchical`` action system::

    [action.tuples.satisfy_hunger]
    drive = "hunger"                                           # top level: the drive it satisfies
    select = { trigger = "object-present", kind = "food" }     # object selection (a can-I trigger)
    should = [{ trigger = "drive", drive = "hunger", above = 0.3 }]   # should-I triggers
    children = ["get", "eat"]                                  # the next level's action group

    [action.tuples.reach]
    movement = "reach"                                         # a leaf: the movement it requests
    can = [{ trigger = "reachable", distance = 0.5 }]          # can-I triggers
    until = [{ trigger = "holding" }]                          # do-until (success) contexts
    effect = "grasp"                                           # what performing it does to the object
    chance = 1.0                                               # how often the effect takes place (a grasp can miss)

    [action.tuples.get]
    until = [{ trigger = "holding" }]                          # stays active until holding (§6.2)
    retries = 2                                                # children that may fail in a row before it gives up
    children = ["reach", "jump"]

A tuple stays active until its do-until contexts hold (it succeeded) or its
triggers no longer hold (it failed); see :mod:`plugins.action.hierarchical`.

Triggers are components registered through ``likeme_register_triggers``; a
trigger table names one with ``trigger = NAME`` and gives its parameters.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from toolkit import ConfigError, Trigger, TriggerContext

__all__ = ["ActionTuple", "ActionHierarchy", "EFFECTS", "evaluate_path", "parse_hierarchy"]

EFFECTS = ("none", "grasp", "consume", "toss")
"""What completing a leaf tuple's movement does to its object of attention."""

TUPLE_KEYS = ("drive", "select", "should", "can", "until", "children", "movement", "effect", "satisfies", "chance",
              "retries", "description")

DEFAULT_RETRIES = 2
"""How many of its children may fail in a row before a tuple gives up on its object, unless it says otherwise."""


@dataclass
class ActionTuple:
    """One action tuple. ``movement`` is set for leaves, ``children`` for the others."""

    name: str
    drive: str | None = None
    select: Trigger | None = None
    should: list[Trigger] = field(default_factory=list)
    can: list[Trigger] = field(default_factory=list)
    until: list[Trigger] = field(default_factory=list)
    children: list[str] = field(default_factory=list)
    movement: str | None = None
    effect: str = "none"
    satisfies: float = 0.0
    chance: float = 1.0
    retries: int = DEFAULT_RETRIES
    description: str = ""
    parents: list[str] = field(default_factory=list)

    @property
    def leaf(self) -> bool:
        return self.movement is not None


@dataclass
class ActionHierarchy:
    """The tuples by name, the top-level group, and every path from the top to each leaf."""

    tuples: dict[str, ActionTuple]
    top: list[str]

    def paths_to(self, name: str) -> list[tuple[str, ...]]:
        """Every path from a top-level tuple down to ``name``."""
        t = self.tuples[name]
        if not t.parents:
            return [(name,)]
        return [(*p, name) for parent in t.parents for p in self.paths_to(parent)]

    def leaves_for(self, movement: str) -> list[str]:
        """The leaf tuples that request ``movement``."""
        return [n for n, t in self.tuples.items() if t.movement == movement]

    def drive_of(self, path: tuple[str, ...]) -> str | None:
        return self.tuples[path[0]].drive

    def render(self) -> str:
        """The hierarchy as an indented text tree (a tuple under several parents is shown under each)."""
        lines: list[str] = []

        def walk(name: str, depth: int) -> None:
            t = self.tuples[name]
            label = f"{name}"
            if t.movement:
                label += f"  -> movement {t.movement}"
            parts = []
            if t.drive:
                parts.append(f"drive {t.drive}")
            if t.select is not None:
                parts.append(f"select: {t.select.describe()}")
            if t.should:
                parts.append("should-I: " + ", ".join(x.describe() for x in t.should))
            if t.can:
                parts.append("can-I: " + ", ".join(x.describe() for x in t.can))
            if t.until:
                parts.append("until: " + ", ".join(x.describe() for x in t.until))
            if t.children and t.retries != DEFAULT_RETRIES:
                parts.append(f"retries {t.retries}")
            if t.effect != "none":
                parts.append(f"effect {t.effect}" + (f" (chance {t.chance:g})" if t.chance < 1 else ""))
            lines.append("  " * depth + label + (f"   [{'; '.join(parts)}]" if parts else ""))
            for child in t.children:
                walk(child, depth + 1)

        for name in self.top:
            walk(name, 0)
        return "\n".join(lines)


def _trigger(spec: Any, key: tuple, registry: Any) -> Trigger:
    if not isinstance(spec, Mapping) or not isinstance(spec.get("trigger"), str):
        raise ConfigError(f"invalid trigger {spec!r}", key=key, expected='{ trigger = "NAME", ...parameters }',
                          available=registry.names("trigger"))
    try:
        cls = registry.get("trigger", spec["trigger"])
    except ConfigError as err:
        raise err.within(prefix=(*key, "trigger")) from None
    try:
        return cls(**{k: v for k, v in spec.items() if k != "trigger"})
    except ConfigError as err:
        raise err.within(prefix=key) from None


def _triggers(value: Any, key: tuple, registry: Any) -> list[Trigger]:
    if value is None:
        return []
    if not isinstance(value, list):
        raise ConfigError("not an array", key=key, expected="an array of trigger tables")
    return [_trigger(v, (*key, i), registry) for i, v in enumerate(value)]


def parse_hierarchy(table: Mapping[str, Any], registry: Any, movements: list[str], drives: list[str]) -> ActionHierarchy:
    """Validate and build the hierarchy: names, triggers, movements, drives, no cycles, leaves and inner tuples."""
    if not table:
        raise ConfigError("no action tuples declared", key=("tuples",), expected="at least one [action.tuples.NAME]")
    tuples: dict[str, ActionTuple] = {}
    for name, spec in table.items():
        key = ("tuples", name)
        if not isinstance(spec, Mapping):
            raise ConfigError("not a table", key=key, expected="an action tuple table")
        for k in spec:
            if k not in TUPLE_KEYS:
                raise ConfigError(f"unknown key {k!r}", key=(*key, k), expected="an action tuple key", available=TUPLE_KEYS)
        movement = spec.get("movement")
        children = spec.get("children", [])
        if movement is not None and movement not in movements:
            raise ConfigError(f"unknown movement {movement!r}", key=(*key, "movement"), expected="a movement of this character", available=movements)
        if not isinstance(children, list) or not all(isinstance(c, str) for c in children):
            raise ConfigError("invalid", key=(*key, "children"), expected="an array of tuple names")
        if (movement is None) == (not children):
            raise ConfigError("a tuple needs either a movement (a leaf) or children, not both or neither",
                              key=key, expected="movement = NAME or children = [...]")
        drive = spec.get("drive")
        if drive is not None and drive not in drives:
            raise ConfigError(f"unknown drive {drive!r}", key=(*key, "drive"), expected="a declared drive", available=drives)
        effect = spec.get("effect", "none")
        if effect not in EFFECTS:
            raise ConfigError(f"unknown effect {effect!r}", key=(*key, "effect"), expected="an effect", available=EFFECTS)
        satisfies = spec.get("satisfies", 0.0)
        if isinstance(satisfies, bool) or not isinstance(satisfies, (int, float)) or not 0 <= satisfies <= 1:
            raise ConfigError(f"invalid value {satisfies!r}", key=(*key, "satisfies"), expected="the drive decrease in [0, 1]")
        chance = spec.get("chance", 1.0)
        if isinstance(chance, bool) or not isinstance(chance, (int, float)) or not 0 <= chance <= 1:
            raise ConfigError(f"invalid value {chance!r}", key=(*key, "chance"),
                              expected="the probability in [0, 1] that the leaf's effect takes place")
        if "chance" in spec and movement is None:
            raise ConfigError("only a leaf (a tuple with a movement) has a chance", key=(*key, "chance"),
                              expected="chance on a tuple with movement = NAME")
        retries = spec.get("retries", DEFAULT_RETRIES)
        if isinstance(retries, bool) or not isinstance(retries, int) or not 0 <= retries <= 100:
            raise ConfigError(f"invalid value {retries!r}", key=(*key, "retries"),
                              expected="a whole number in [0, 100] of failed children before giving up")
        if "retries" in spec and not children:
            raise ConfigError("only a tuple with children retries them", key=(*key, "retries"),
                              expected="retries on a tuple with children = [...]")
        tuples[name] = ActionTuple(
            name=name,
            drive=drive,
            select=_trigger(spec["select"], (*key, "select"), registry) if "select" in spec else None,
            should=_triggers(spec.get("should"), (*key, "should"), registry),
            can=_triggers(spec.get("can"), (*key, "can"), registry),
            until=_triggers(spec.get("until"), (*key, "until"), registry),
            children=list(children),
            movement=movement,
            effect=effect,
            satisfies=float(satisfies),
            chance=float(chance),
            retries=int(retries),
            description=str(spec.get("description", "")),
        )
    for name, t in tuples.items():
        for i, child in enumerate(t.children):
            if child not in tuples:
                raise ConfigError(f"unknown tuple {child!r}", key=("tuples", name, "children", i),
                                  expected="a declared action tuple", available=sorted(tuples))
            tuples[child].parents.append(name)
    _check_acyclic(tuples)
    top = [n for n, t in tuples.items() if not t.parents]
    for name in top:
        if tuples[name].drive is None:
            raise ConfigError("a top-level tuple is a motivational subsystem and needs the drive it satisfies",
                              key=("tuples", name, "drive"), expected="a declared drive", available=drives)
    return ActionHierarchy(tuples, top)


def _check_acyclic(tuples: dict[str, ActionTuple]) -> None:
    state: dict[str, int] = {}

    def visit(name: str, stack: tuple[str, ...]) -> None:
        if state.get(name) == 2:
            return
        if state.get(name) == 1:
            cycle = " -> ".join((*stack[stack.index(name):], name))
            raise ConfigError(f"action hierarchy cycle: {cycle}", key=("tuples", name, "children"), expected="no cycle")
        state[name] = 1
        for child in tuples[name].children:
            visit(child, (*stack, name))
        state[name] = 2

    for name in tuples:
        visit(name, ())


def evaluate_path(system: Any, target: Any, world: Any, path: tuple[str, ...], attention: str | None,
                  beliefs: dict[str, str]) -> tuple[bool, str | None]:
    """Whether every can-I trigger along ``path`` holds for ``target`` in ``world``; and the object of attention.

    Each object selection trigger on the way picks the object the triggers below it are evaluated for, starting
    from ``attention``. Used wherever a character asks whether another could do what it would do itself:
    identification (§6.1.1) and prediction (§7.4)."""
    context = TriggerContext(target, world, attention, beliefs, {})
    obj = attention
    for name in path:
        t = system.hierarchy.tuples[name]
        if t.select is not None:
            obj = t.select.select(context)
            if obj is None:
                return False, None
            context = TriggerContext(target, world, obj, beliefs, {})
        if any(trigger.evaluate(context) <= 0 for trigger in t.can):
            return False, obj
    return True, obj
