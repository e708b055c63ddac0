"""Saving and loading what characters learn, atomically and with a format version.

A state file is JSON::

    {"format": "likeme-state", "version": 1,
     "frame": 812, "time": 27.07,
     "actors": {"max": {"character": "Max",
                        "components": {"motor": {"plugin": "posegraph", "state": {...}},
                                       "action": {"plugin": "hierarchical", "state": {...}}}}}}

Each component contributes its own :meth:`~toolkit.components.Component.get_state`
(learned movements of a posegraph; drives, beliefs, correspondence and
transition maps of an action system...). Loading checks the format, the
version, the actors and the plugin of every component before it changes
anything, and refuses a file of an unknown version.

Writes are atomic: the data goes to a temporary file in the same folder, is
flushed and synced, and replaces the old file in one rename, so a run killed at
any moment leaves either the previous state or the new one, never half a file.
:class:`Checkpoint` is a plugin that saves after every step in which something
was learned.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from toolkit.character import Character, read_text
from toolkit.errors import ConfigError
from toolkit.hookspecs import hookimpl

__all__ = ["FORMAT", "VERSION", "write_atomic", "character_state", "world_state", "save_state", "read_state",
           "load_state", "Checkpoint"]

FORMAT = "likeme-state"
VERSION = 1


def write_atomic(path: str | Path, text: str) -> None:
    """Write ``text`` to ``path`` so that readers see the old or the new content, never a part."""
    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as handle:
            handle.write(text)
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    try:  # make the rename itself durable
        dir_fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(dir_fd)
        finally:
            os.close(dir_fd)
    except OSError:
        pass


def character_state(character: Character) -> dict[str, Any]:
    """The learned state of one character, by component table."""
    components = {}
    for key, component in character.components().items():
        state = component.get_state()
        if state:
            components[key] = {"plugin": component.name, "state": state}
    return {"character": character.name, "components": components}


def world_state(world: Any) -> dict[str, Any]:
    """The learned state of every actor of a world, with the format header."""
    return {
        "format": FORMAT,
        "version": VERSION,
        "frame": world.frame,
        "time": world.time,
        "actors": {actor_id: character_state(actor.character) for actor_id, actor in world.actors.items()},
    }


def save_state(target: Any, path: str | Path) -> None:
    """Save a world's (every actor's) or one character's learned state to ``path`` atomically."""
    if isinstance(target, Character):
        data = {"format": FORMAT, "version": VERSION, "actors": {target.name.lower(): character_state(target)}}
    else:
        data = world_state(target)
    write_atomic(path, json.dumps(data, indent=1, sort_keys=True) + "\n")


def read_state(path: str | Path) -> dict[str, Any]:
    """Read and check a state file's header; :class:`ConfigError` for anything that is not a supported state file."""
    path = Path(path)
    text = read_text(path, "state file written by --save")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ConfigError(f"not JSON: {exc.msg}", file=path, line=exc.lineno, column=exc.colno,
                          expected="a JSON state file written by likeme") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise ConfigError("not a likeme state file", file=path, key=("format",), expected=f'"format": "{FORMAT}"')
    if data.get("version") != VERSION:
        raise ConfigError(f"unsupported state format version {data.get('version')!r}", file=path, key=("version",),
                          expected="a version this likeme reads", available=[str(VERSION)])
    if not isinstance(data.get("actors"), dict):
        raise ConfigError("missing or invalid", file=path, key=("actors",), expected="a table of actors")
    return data


def load_state(target: Any, path: str | Path) -> dict[str, Any]:
    """Restore learned state from ``path`` into a world (actors matched by id) or one character.

    Every check happens before anything is changed; returns the file's data.
    """
    path = Path(path)
    data = read_state(path)
    if isinstance(target, Character):
        pairs = [(actor_id, target) for actor_id in data["actors"]][:1]
        if not pairs:
            raise ConfigError("no actor in the file", file=path, key=("actors",), expected="one saved character")
    else:
        pairs = []
        for actor_id in data["actors"]:
            if actor_id not in target.actors:
                raise ConfigError(f"unknown actor {actor_id!r}", file=path, key=("actors", actor_id),
                                  expected="an actor of this world", available=list(target.actors))
            pairs.append((actor_id, target.actors[actor_id].character))
    plans = []
    for actor_id, character in pairs:
        entry = data["actors"][actor_id]
        if not isinstance(entry, Mapping) or not isinstance(entry.get("components"), Mapping):
            raise ConfigError("invalid actor entry", file=path, key=("actors", actor_id), expected="{character, components}")
        for key, item in entry["components"].items():
            prefix = ("actors", actor_id, "components", key)
            component = character.components().get(key)
            if component is None:
                raise ConfigError(f"{character.name} has no {key} component", file=path, key=prefix,
                                  expected="a component table of the character", available=list(character.components()))
            if not isinstance(item, Mapping) or item.get("plugin") != component.name:
                raise ConfigError(f"state saved for plugin {item.get('plugin') if isinstance(item, Mapping) else item!r}",
                                  file=path, key=(*prefix, "plugin"), expected=f"state of {component.name!r}")
            plans.append((component, item.get("state", {}), (*prefix, "state")))
    for component, state, prefix in plans:
        try:
            component.set_state(dict(state))
        except ConfigError as err:
            raise err.within(file=path, prefix=prefix) from None
    return data


class Checkpoint:
    """A plugin that saves a world's learned state after every step in which something was learned,
    and at least every ``every`` seconds of world time (drives and habits change all the time).

    Register it with ``pm.register(Checkpoint(world, path))``; a run killed in the
    middle then loses at most what was being learned when it died.
    """

    def __init__(self, world: Any, path: str | Path, every: float = 5.0) -> None:
        self.world = world
        self.path = Path(path)
        self.every = every
        self.dirty = False
        self.saves = 0
        self._last = world.frame

    @hookimpl
    def likeme_movement_learned(self, character, movement, details):
        self.dirty = True

    @hookimpl
    def likeme_behaviour_identified(self, world, observer, target, behaviour):
        if behaviour.details.get("learned"):
            self.dirty = True

    @hookimpl
    def likeme_world_stepped(self, world):
        if world is not self.world:
            return
        if self.dirty or (self.every > 0 and world.frame - self._last >= self.every * world.fps):
            self.save()

    def save(self) -> None:
        """Save now (also called at the end of a run)."""
        save_state(self.world, self.path)
        self.dirty = False
        self._last = self.world.frame
        self.saves += 1
