"""Scenarios declared in TOML: characters placed in a world with objects, and how long to run.

::

    [scenario]
    name = "Max watches Morris"
    fps = 30.0            # frames per second (default 30)
    duration = 20.0       # seconds; omit to run until every actor is idle
    tail = 1.0            # seconds to keep running once all are idle (default 1)
    seed = 7              # handed to components that draw random numbers

    [[actors]]
    id = "morris"                 # default: the character's name in lower case
    character = "morris"          # a file relative to this one, or a name on the character path
    position = [0.0, 0.0, 1.6]    # metres
    heading = 180.0               # degrees, 0 faces +z
    watch = "max"                 # optional: the id of the actor it watches
    [actors.override.action]      # optional: tables merged over the character's own
    plugin = "script"

    [[objects]]
    name = "cheese"
    kind = "food"
    position = [0.3, 0.4, 1.2]
    radius = 0.05                 # optional
    colour = "#ffd700"            # optional
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from toolkit.character import load_character
from toolkit.config.search import merge_tables, resolve_file
from toolkit.config.toml import read_toml
from toolkit.errors import ConfigError
from toolkit.manager import PluginManager
from toolkit.params import finite_number
from toolkit.runtime import MAX_FPS, MAX_FRAMES, MAX_SECONDS, World, WorldObject

__all__ = ["Scenario", "load_scenario", "is_scenario", "check_duration", "check_seed"]

SCENARIO_KEYS = ("name", "description", "fps", "duration", "tail", "seed")
ACTOR_KEYS = ("id", "character", "position", "heading", "watch", "override")
OBJECT_KEYS = ("name", "kind", "position", "radius", "colour", "held_by", "properties")


@dataclass
class Scenario:
    """A loaded scenario: the world ready to run and how long to run it."""

    name: str
    description: str
    file: Path | None
    world: World
    duration: float | None
    tail: float
    seed: int

    def run(self) -> World:
        """Run the world for the scenario's duration (or until every actor is idle)."""
        if self.duration is not None:
            self.world.run(self.duration)
        else:
            self.world.run(until_idle=True, tail=self.tail)
        return self.world


def is_scenario(table: Mapping[str, Any]) -> bool:
    """Whether a parsed TOML table is a scenario (it has a ``[scenario]`` table)."""
    return "scenario" in table


def load_scenario(path: str | Path, pm: PluginManager, *, seed: int | None = None, on_plugin_error: str = "stop") -> Scenario:
    """Load a scenario file, its characters and objects, into a world ready to run.

    ``seed`` replaces the file's seed; it is given to every component parameter
    named ``seed`` that the scenario does not set explicitly. ``on_plugin_error``
    is the world's policy for failing plugins (see :class:`~toolkit.runtime.World`).
    """
    path = Path(path)
    if not path.is_file():
        path = resolve_file(str(path), None, pm)
    table = read_toml(path)
    try:
        return _build(table, path, pm, seed, on_plugin_error)
    except ConfigError as err:
        raise err.within(file=path) from None


MAX_SEED = 2**63 - 1
"""The largest seed: components hand it to numpy's random generators (which take no negative seed)."""


def check_seed(seed: Any, key: tuple) -> int:
    """``seed`` if it is an integer in [0, :data:`MAX_SEED`], else a :class:`ConfigError` at ``key``."""
    if isinstance(seed, bool) or not isinstance(seed, int) or not 0 <= seed <= MAX_SEED:
        raise ConfigError(f"invalid seed {seed!r}", key=key, expected=f"an integer in [0, {MAX_SEED}]")
    return seed


def check_duration(duration: Any, fps: float, key: tuple) -> float:
    """``duration`` (seconds) if it is a finite number in [0, :data:`MAX_SECONDS`] whose frames at ``fps`` are at
    most :data:`MAX_FRAMES`, else a :class:`ConfigError` at ``key``."""
    if isinstance(duration, bool) or not isinstance(duration, (int, float)) or not 0 <= duration <= MAX_SECONDS:
        raise ConfigError(f"invalid duration {duration!r}", key=key,
                          expected=f"a finite number of seconds in [0, {MAX_SECONDS:g}]")
    if duration * fps > MAX_FRAMES:
        raise ConfigError(f"duration {duration:g} s at {fps:g} fps is {duration * fps:.0f} frames", key=key,
                          expected=f"at most {MAX_FRAMES} frames in a run")
    return float(duration)


def _number(value: Any, key: tuple, expected: str = "a number") -> float:
    number = finite_number(value)
    if number is None:
        raise ConfigError(f"invalid value {value!r}", key=key, expected=expected)
    return number


def _radius(value: Any, key: tuple) -> float:
    radius = _number(value, key, "a positive number of metres")
    if radius <= 0:
        raise ConfigError(f"invalid value {value!r}", key=key, expected="a positive number of metres")
    return radius


def _vector(value: Any, key: tuple) -> list[float]:
    if not isinstance(value, list) or len(value) != 3:
        raise ConfigError(f"invalid value {value!r}", key=key, expected="[x, y, z] in metres")
    return [_number(v, (*key, i)) for i, v in enumerate(value)]


def _check_keys(table: Mapping[str, Any], known: tuple[str, ...], key: tuple, what: str) -> None:
    for k in table:
        if k not in known:
            raise ConfigError(f"unknown key {k!r}", key=(*key, k), expected=f"a {what} key", available=known)


def _build(table: Mapping[str, Any], path: Path, pm: PluginManager, seed: int | None, on_plugin_error: str) -> Scenario:
    for k in table:
        if k not in ("scenario", "actors", "objects"):
            raise ConfigError(f"unknown table {k!r}", key=(k,), expected="a scenario table", available=("actors", "objects", "scenario"))
    head = table.get("scenario")
    if not isinstance(head, Mapping):
        raise ConfigError("missing [scenario] table", key=("scenario",), expected="a table")
    _check_keys(head, SCENARIO_KEYS, ("scenario",), "[scenario]")
    fps = _number(head.get("fps", 30.0), ("scenario", "fps"))
    if fps <= 0:
        raise ConfigError(f"invalid value {fps!r}", key=("scenario", "fps"), expected="a positive number")
    if fps > MAX_FPS:
        raise ConfigError(f"invalid value {fps!r}", key=("scenario", "fps"),
                          expected=f"a positive number of frames per second, at most {MAX_FPS:g}")
    duration = head.get("duration")
    if duration is not None:
        duration = check_duration(_number(duration, ("scenario", "duration")), fps, ("scenario", "duration"))
    tail = _number(head.get("tail", 1.0), ("scenario", "tail"))
    if not 0 <= tail <= MAX_SECONDS:
        raise ConfigError(f"invalid value {tail!r}", key=("scenario", "tail"),
                          expected=f"seconds in [0, {MAX_SECONDS:g}]")
    file_seed = head.get("seed", 0)
    if isinstance(file_seed, bool) or not isinstance(file_seed, int):
        raise ConfigError(f"invalid value {file_seed!r}", key=("scenario", "seed"), expected="an integer")
    seed = check_seed(file_seed, ("scenario", "seed")) if seed is None else check_seed(seed, ("--seed",))

    world = World(fps=fps, pm=pm, on_plugin_error=on_plugin_error)
    actors = table.get("actors", [])
    if not isinstance(actors, list) or not actors:
        raise ConfigError("missing or invalid", key=("actors",), expected="one or more [[actors]] tables")
    watches: list[tuple[str, str, int]] = []
    for i, spec in enumerate(actors):
        key = ("actors", i)
        if not isinstance(spec, Mapping):
            raise ConfigError("not a table", key=key, expected="an [[actors]] table")
        _check_keys(spec, ACTOR_KEYS, key, "[[actors]]")
        ref = spec.get("character")
        if not isinstance(ref, str):
            raise ConfigError("missing or invalid", key=(*key, "character"), expected="a character file or name")
        char_path = resolve_file(ref, path.parent, pm, key=(*key, "character"), file=path)
        override = spec.get("override", {})
        if not isinstance(override, Mapping):
            raise ConfigError("not a table", key=(*key, "override"), expected="tables to merge over the character's")
        override = _seeded(override, seed, char_path, pm)
        character = load_character(char_path, pm, override=override, override_at=(path, (*key, "override")))
        heading = math.radians(_number(spec.get("heading", 0.0), (*key, "heading"), "degrees"))
        position = _vector(spec.get("position", [0.0, 0.0, 0.0]), (*key, "position"))
        actor_id = spec.get("id", re.sub(r"[^a-z0-9]+", "-", character.name.lower()).strip("-"))
        if not isinstance(actor_id, str) or not actor_id:
            raise ConfigError("invalid", key=(*key, "id"), expected="a non-empty string")
        try:
            world.add_actor(character, actor_id, position, heading)
        except ConfigError as err:
            raise err.within(prefix=(*key, "id")) from None
        if "watch" in spec:
            if not isinstance(spec["watch"], str):
                raise ConfigError("invalid", key=(*key, "watch"), expected="the id of another actor")
            watches.append((actor_id, spec["watch"], i))
    for watcher, watched, i in watches:
        if watched not in world.actors or watched == watcher:
            raise ConfigError(
                f"unknown actor {watched!r}",
                key=("actors", i, "watch"),
                expected="the id of another actor",
                available=[a for a in world.actors if a != watcher],
            )
        try:
            world.actors[watcher].watch(world.actors[watched])
        except ConfigError as err:
            raise err.within(prefix=("actors", i, "watch")) from None

    objects = table.get("objects", [])
    if not isinstance(objects, list):
        raise ConfigError("invalid", key=("objects",), expected="[[objects]] tables")
    for i, spec in enumerate(objects):
        key = ("objects", i)
        if not isinstance(spec, Mapping):
            raise ConfigError("not a table", key=key, expected="an [[objects]] table")
        _check_keys(spec, OBJECT_KEYS, key, "[[objects]]")
        for req in ("name", "kind"):
            if not isinstance(spec.get(req), str):
                raise ConfigError("missing or invalid", key=(*key, req), expected="a string")
        held_by = spec.get("held_by")
        if held_by is not None and not isinstance(held_by, str):
            raise ConfigError(f"wrong type {type(held_by).__name__} (value {held_by!r})", key=(*key, "held_by"),
                              expected="the id of one actor, as a string", available=list(world.actors))
        if held_by is not None and held_by not in world.actors:
            raise ConfigError(f"unknown actor {held_by!r}", key=(*key, "held_by"), expected="an actor id", available=list(world.actors))
        properties = spec.get("properties", {})
        if not isinstance(properties, Mapping):
            raise ConfigError(f"wrong type {type(properties).__name__} (value {properties!r})",
                              key=(*key, "properties"), expected="a table of properties, like { tasty = 0.8 }")
        colour = spec.get("colour", "#c0c0c0")
        if not _is_colour(colour):
            raise ConfigError(f"invalid colour {colour!r}", key=(*key, "colour"), expected='a colour "#rrggbb"')
        obj = WorldObject(
            name=spec["name"],
            kind=spec["kind"],
            position=_vector(spec.get("position", [0.0, 0.0, 0.0]), (*key, "position")),
            radius=_radius(spec.get("radius", 0.05), (*key, "radius")),
            colour=colour,
            held_by=held_by,
            properties=dict(properties),
        )
        try:
            world.add_object(obj)
        except ConfigError as err:
            raise err.within(prefix=(*key, "name")) from None
    return Scenario(
        name=str(head.get("name", path.stem)),
        description=str(head.get("description", "")),
        file=path,
        world=world,
        duration=duration,
        tail=tail,
        seed=seed,
    )


def _is_colour(value: Any) -> bool:
    return isinstance(value, str) and re.fullmatch(r"#[0-9a-fA-F]{6}", value) is not None


def _seeded(override: Mapping[str, Any], seed: int, char_path: Path, pm: PluginManager) -> dict[str, Any]:
    """Give the scenario seed to every component of the character that takes a ``seed`` parameter."""
    from toolkit.character import COMPONENT_TABLES
    from toolkit.config.search import load_chain

    table, _ = load_chain(char_path, pm)
    merged = merge_tables(table, override)
    out = dict(override)
    for key in COMPONENT_TABLES:
        sub = merged.get(key)
        if not isinstance(sub, Mapping) or "seed" in sub or not isinstance(sub.get("plugin"), str):
            continue
        try:
            cls = pm.registry.get(key, sub["plugin"])
        except ConfigError:
            continue  # reported when the character is composed
        if any(p.name == "seed" for p in cls.parameters):
            out[key] = merge_tables(dict(out.get(key, {})), {"seed": seed})
    return out
