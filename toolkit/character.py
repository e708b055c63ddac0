"""Characters declared in TOML, composed at load time from registered components.

A character file has these tables (``docs/character-format.md`` is the full reference)::

    [character]   name, optional extends, description and lengths_for_height
    [body]        tracked parts, root, facing parts, bones, colours
    [motor]       plugin = NAME and its parameters (the movement repertoire)
    [perception]  plugin = NAME and its parameters      (optional)
    [correspondence] plugin = NAME and its parameters   (optional; none: the papers' plain behaviour)
    [segmenter]   plugin = NAME and its parameters      (optional)
    [matcher]     plugin = NAME and its parameters      (optional)
    [action]      plugin = NAME and its parameters      (optional)
    [layer]       plugin = NAME and its parameters      (optional; a look-at over every movement)

``extends`` names another character file; its tables are the defaults, the
file's own tables are merged over them key by key (a component table whose
``plugin`` changes replaces the inherited one whole): :mod:`toolkit.config.search`
finds and merges the files, :mod:`toolkit.config.toml` reads them.

Every problem is a :class:`~toolkit.errors.ConfigError` naming the file, the
key path (and the line where it can be found), what was expected and what is
available.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from toolkit.body import Body
from toolkit.components import (ActionSystem, Component, Correspondence, Layer, Matcher, MotorSystem, Perception,
                                 Segmenter)
from toolkit.config.search import load_chain, merge_tables, resolve_file
from toolkit.config.toml import find_key_line
from toolkit.errors import ConfigError, LikemeError, PluginError
from toolkit.manager import PluginManager
from toolkit.params import finite_number

__all__ = [
    "Character",
    "load_character",
    "compose_character",
    "build_component",
    "COMPONENT_TABLES",
    "check_body",
]

COMPONENT_TABLES: dict[str, bool] = {
    "motor": True,
    "perception": False,
    "correspondence": False,
    "segmenter": False,
    "matcher": False,
    "action": False,
    "layer": False,
}
"""Component tables of a character file and whether each is required."""

TOP_LEVEL = ("character", "body", *COMPONENT_TABLES)
CHARACTER_KEYS = ("name", "extends", "description", "lengths_for_height")


@dataclass
class Character:
    """A composed character: its body and the components of its pipeline.

    Attributes
    ----------
    name : str
    body : Body
    motor : MotorSystem
    perception, correspondence, segmenter, matcher, action, layer : component or None
    files : tuple of Path
        The file it was loaded from first, then the files it extends.
    description : str
    lengths_for_height : float or None
        The standing height (m) the length parameters of its components were written for; they are scaled by
        :attr:`length_scale`. ``None``: lengths are metres as written (the papers).
    config : dict
        The merged declaration.
    pm : PluginManager or None
        The plugin manager it was composed with; components announce events through ``pm.hook``.
    repertoire : object or None
        A repertoire given when it was composed (:func:`compose_character`'s ``repertoire``), which its motor
        system builds from instead of a folder named in its table: a :class:`toolkit.recordings.clips.ClipFolder`
        (clips and the profile they are read with) or, for ``posegraph`` and ``motor-command-graph``, a
        :class:`plugins.lib.clip_repertoire.ClipRepertoire` built in memory.
    """

    name: str
    body: Body
    motor: MotorSystem
    perception: Perception | None = None
    correspondence: Correspondence | None = None
    segmenter: Segmenter | None = None
    matcher: Matcher | None = None
    action: ActionSystem | None = None
    layer: Layer | None = None
    files: tuple[Path, ...] = ()
    description: str = ""
    lengths_for_height: float | None = None
    config: dict[str, Any] = field(default_factory=dict)
    pm: PluginManager | None = field(default=None, repr=False)
    repertoire: Any = field(default=None, repr=False)

    @property
    def file(self) -> Path | None:
        return self.files[0] if self.files else None

    @property
    def height(self) -> float:
        """The character's own standing height (m): the vertical extent of its rest pose's positions."""
        rest = np.asarray(self.motor.rest_pose(), dtype=float)[~self.body.angle_mask]
        return float(np.nanmax(rest[:, 1]) - np.nanmin(rest[:, 1]))

    @property
    def length_scale(self) -> float:
        """What every length parameter of its components is multiplied by: its own height over
        :attr:`lengths_for_height` (1 when that is not given)."""
        return 1.0 if self.lengths_for_height is None else self.height / self.lengths_for_height

    def components(self) -> dict[str, Component]:
        """The configured components by table name (``motor``, ``perception``...)."""
        return {k: c for k in COMPONENT_TABLES if (c := getattr(self, k)) is not None}

    def pipeline(self) -> list[tuple[str, Component | None]]:
        """The stages perceive, correspond, segment, match, interpret, respond with the component of each."""
        return [
            ("perceive", self.perception),
            ("correspond", self.correspondence),
            ("segment", self.segmenter),
            ("match", self.matcher),
            ("interpret", self.action),
            ("respond", self.action),
        ]

    def announce(self, hook: str, **kwargs: Any) -> None:
        """Call a run-event hook if this character has a plugin manager (components announce what they learn).

        Through the plugin manager: traced, and under the failure policy of the world that is stepping, if any.
        """
        if self.pm is not None:
            self.pm.announce(hook, **kwargs)


def load_character(
    path: str | Path, pm: PluginManager | None = None, *, override: Mapping[str, Any] | None = None,
    override_at: tuple[str | Path | None, tuple[str | int, ...]] | None = None,
) -> Character:
    """Load, merge, validate and compose the character declared in ``path``.

    Parameters
    ----------
    path : str or Path
        The character file, or the name of a character on the search path.
    pm : PluginManager, optional
        Where components are looked up; a new one is created if omitted.
    override : mapping, optional
        Tables merged over the file's (a scenario's per-actor overrides).
    override_at : (file, key prefix), optional
        Where ``override`` was written (a scenario file and ``("actors", 0, "override")``; ``(None, ("--set",))``
        for the command line): an error in a key the override gives is reported there, not in the character file.
    """
    if pm is None:
        from toolkit.manager import create_plugin_manager

        pm = create_plugin_manager()
    p = Path(path)
    if not p.is_file():
        p = resolve_file(str(path), None, pm)
    table, files = load_chain(p, pm)
    if override:
        table = merge_tables(table, override)
    try:
        return compose_character(table, pm, files=files)
    except ConfigError as err:
        if override and override_at is not None and err.file is None and _gives(override, err.key):
            file, prefix = override_at
            key = (*prefix, *err.key)
            line = find_key_line(Path(file), key) if file is not None else None
            raise ConfigError(err.problem, file=file, key=key, line=line, expected=err.expected,
                              available=err.available) from None
        raise _locate(err, files) from None


def _gives(override: Mapping[str, Any], key: tuple) -> bool:
    """Whether the key path ``key`` leads to a value that ``override`` gives (a table of it, a key, an element)."""
    value: Any = override
    for part in key:
        if isinstance(value, Mapping) and isinstance(part, str) and part in value:
            value = value[part]
        elif isinstance(value, list) and isinstance(part, int) and 0 <= part < len(value):
            value = value[part]
        else:
            return False
    return bool(key)


def compose_character(table: Mapping[str, Any], pm: PluginManager, *, files: tuple[Path, ...] = (),
                      repertoire: Any = None) -> Character:
    """Validate a merged character table and build its components.

    ``repertoire``: what the motor system builds its repertoire from (:attr:`Character.repertoire`), read when it
    is attached, instead of a folder its table names (``[motor] clips``).

    Raises :class:`ConfigError` with the key path (file placement is done by
    :func:`load_character`) or :class:`PluginError` if a component fails to build.
    """
    for key in table:
        if key not in TOP_LEVEL:
            raise ConfigError(f"unknown table {key!r}", key=(key,), expected="a character table", available=TOP_LEVEL)
    head = _table(table, "character", required=True)
    for key in head:
        if key not in CHARACTER_KEYS:
            raise ConfigError(f"unknown key {key!r}", key=("character", key), expected="a [character] key", available=CHARACTER_KEYS)
    name = head.get("name")
    if not isinstance(name, str) or not name.strip():
        raise ConfigError("missing or invalid", key=("character", "name"), expected="a non-empty string")
    description = head.get("description", "")
    if not isinstance(description, str):
        raise ConfigError("wrong type", key=("character", "description"), expected="a string")
    lengths_for = head.get("lengths_for_height")
    if lengths_for is not None and (finite_number(lengths_for) or 0.0) <= 0:
        raise ConfigError(f"invalid value {lengths_for!r}", key=("character", "lengths_for_height"),
                          expected="a positive number: the standing height (m) the length parameters were written for")
    body_table = _table(table, "body", required=True)
    try:
        body = check_body(Body.from_config(body_table))
    except ConfigError as err:
        raise err.within(prefix=("body",)) from None

    built: dict[str, Component | None] = {}
    for key, required in COMPONENT_TABLES.items():
        sub = _table(table, key, required=required)
        built[key] = None if sub is None else build_component(key, sub, pm)
    character = Character(
        name=name,
        body=body,
        motor=built["motor"],  # type: ignore[arg-type]
        perception=built["perception"],  # type: ignore[arg-type]
        correspondence=built["correspondence"],  # type: ignore[arg-type]
        segmenter=built["segmenter"],  # type: ignore[arg-type]
        matcher=built["matcher"],  # type: ignore[arg-type]
        action=built["action"],  # type: ignore[arg-type]
        layer=built["layer"],  # type: ignore[arg-type]
        files=files,
        description=description,
        lengths_for_height=None if lengths_for is None else float(lengths_for),
        config=dict(table),
        pm=pm,
        repertoire=repertoire,
    )
    scale = None  # known once the motor system is attached (its rest pose gives the height)
    for key, component in character.components().items():  # motor first: the others read it
        if key != "motor" and lengths_for is not None:  # the motor system measures the body: its lengths stay
            scale = scale or _length_scale(character)
            component.scale_lengths(scale)
        _guard(component, key, "attach", lambda c=component: c.attach(character))
    pm.hook.likeme_character_composed(character=character)  # a failing plugin is named by the plugin manager
    return character


def check_body(body: Body) -> Body:
    """``body`` if its facing and bones are usable, else a :class:`ConfigError` keyed relative to its table: the
    facing's left and right parts must differ (their difference is the facing direction) and a bone joins two
    different parts. Character files and body profiles both go through it."""
    if body.facing.left == body.facing.right:
        raise ConfigError(f"left and right are the same part {body.facing.left!r}", key=("facing", "right"),
                          expected="two different parts (the facing direction is their difference)",
                          available=[p for p in body.parts if p != body.facing.left])
    for i, (a, b) in enumerate(body.bones):
        if a == b:
            raise ConfigError(f"a bone from part {a!r} to itself", key=("bones", i),
                              expected="a pair of two different parts")
    return body


def _length_scale(character: Character) -> float:
    """The character's length scale, or a :class:`ConfigError` when its rest pose has no height."""
    scale = character.length_scale
    if not np.isfinite(scale) or scale <= 0:
        raise ConfigError(f"the rest pose of motor {character.motor.name!r} has no height ({character.height!r} m)",
                          key=("character", "lengths_for_height"),
                          expected="a motor system whose rest pose stands (parts at different heights)")
    return scale


def build_component(key: str, table: Mapping[str, Any], pm: PluginManager) -> Component:
    """Build the component declared by one component table (``plugin = NAME`` plus parameters)."""
    name = table.get("plugin")
    registry = pm.registry
    if not isinstance(name, str):
        raise ConfigError(
            "missing or invalid plugin name",
            key=(key, "plugin"),
            expected=f"the name of a registered {_label(key)}",
            available=registry.names(key),
        )
    try:
        cls = registry.get(key, name)
    except ConfigError as err:
        raise err.within(prefix=(key, "plugin")) from None
    params = {k: v for k, v in table.items() if k != "plugin"}
    return _guard(None, key, f"{cls.__name__}()", lambda: cls(**params), plugin=name)


def _guard(component: Component | None, key: str, where: str, call: Any, plugin: str | None = None) -> Any:
    try:
        return call()
    except ConfigError as err:
        raise err.within(prefix=(key,)) from None
    except LikemeError:
        raise
    except Exception as exc:
        owner = plugin or (component.name if component is not None else key)
        raise PluginError(owner, f"{key} {where}", f"{type(exc).__name__}: {exc}") from exc


def _label(key: str) -> str:
    from toolkit.components import KINDS

    return KINDS[key].kind


def _table(table: Mapping[str, Any], key: str, *, required: bool) -> Mapping[str, Any] | None:
    sub = table.get(key)
    if sub is None:
        if required:
            raise ConfigError(f"missing [{key}] table", key=(key,), expected=f"a [{key}] table")
        return None
    if not isinstance(sub, Mapping):
        raise ConfigError(f"wrong type {type(sub).__name__}", key=(key,), expected="a table")
    return sub


# -- placing errors in files -----------------------------------------------------------


def _locate(err: ConfigError, files: Iterable[Path]) -> ConfigError:
    """Attach the file (and line, where it can be found) that declares the failing key."""
    if err.file is not None or not err.key:
        return err if err.file is not None else err.within(file=next(iter(files), None))
    files = list(files)
    for path in files:
        line = find_key_line(path, err.key)
        if line is not None:
            return ConfigError(
                err.problem, file=path, key=err.key, line=line, expected=err.expected, available=err.available
            )
    return err.within(file=files[0] if files else None)


