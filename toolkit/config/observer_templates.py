"""Observer templates: the components an observer of recordings has when a command names none.

A template (``characters/observers/recordings.toml``, ``papers.toml``, or a file of one's own) is an
``[observer]`` table and a character's component tables without a ``[body]``: the body comes from the recordings'
body profile and the repertoire from a folder of labelled clips when the observer is composed
(:func:`toolkit.observe.compose_observer`). A template may ``extends`` another, as a character file does, and may
hold, per plugin, the parameters that plugin gets when a command names it instead of the template's own
(``[segmenters.NAME]``, ``[matchers.NAME]``, ``[motors.NAME]``). ``docs/conventions.md`` has the format.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from toolkit.character import COMPONENT_TABLES, build_component
from toolkit.config.search import character_paths, load_chain, resolve_file
from toolkit.config.toml import find_key_line
from toolkit.errors import ConfigError
from toolkit.params import finite_number

__all__ = ["OBSERVER_TEMPLATE", "OBSERVER_FOLDER", "OBSERVER_KEYS", "ALTERNATIVES", "observer_templates",
           "observer_template_path", "read_observer_template", "is_observer_template", "check_observer_template",
           "checked_template"]


OBSERVER_TEMPLATE = "observers/recordings.toml"
"""The observer template on the character path: the components an observer of recordings has by default."""


OBSERVER_FOLDER = "observers"
"""The folder of observer templates in each folder of the character path (:func:`toolkit.config.search.character_paths`):
a template named without a path (``--observer papers``) is looked up there."""


def observer_templates(pm: Any = None) -> list[str]:
    """The names of the observer templates on the character path (``characters/observers/*.toml``), sorted."""
    return sorted({f.stem for p in character_paths(pm) for f in (p / OBSERVER_FOLDER).glob("*.toml")})


def observer_template_path(template: str | Path | None, pm: Any = None, *, key: tuple = ("--observer",)) -> Path:
    """The file of an observer template: a path, a name on the character path (``observers/recordings``), or the
    name of a template in an ``observers`` folder of the character path (``recordings``, ``papers``);
    ``None`` or ``""``: :data:`OBSERVER_TEMPLATE`. A :class:`ConfigError` naming ``key`` and listing the templates
    found otherwise."""
    ref = str(template or OBSERVER_TEMPLATE)
    if Path(ref).is_file():
        return Path(ref).resolve()
    tries = [ref] if "/" in ref or "\\" in ref else [f"{OBSERVER_FOLDER}/{ref}", ref]
    for attempt in tries:
        try:
            return resolve_file(attempt, None, pm, key=key)
        except ConfigError:
            continue
    raise ConfigError(f"cannot find observer template {ref[:80]!r}", key=key,
                      expected="an observer template's file, or the name of one in characters/observers/",
                      available=observer_templates(pm))


def read_observer_template(template: str | Path | None, pm: Any = None, *, key: tuple = ("--observer",)
                           ) -> tuple[dict[str, Any], tuple[Path, ...]]:
    """The table of an observer template and the files it was read from (outermost first): a template may extend
    another (``[observer] extends = "recordings.toml"``, a path relative to it or a name on the character path), as
    a character file does; its tables are merged onto the other's, a table naming another ``plugin`` replacing it
    whole (:func:`toolkit.config.search.merge_tables`). A file that is not an observer template (a character file, a
    body profile) is a :class:`ConfigError` naming ``key`` (the template itself) or the ``extends`` that names it."""
    def check(file: Path, own: dict, extended_by: Path | None) -> None:
        if not is_observer_template(own):
            what = "a character file" if "character" in own else "no [observer] table"
            raise ConfigError(f"{file.name} is not an observer template ({what})", file=extended_by,
                              key=("observer", "extends") if extended_by else key,
                              expected="an observer template: an [observer] table and component tables, no "
                              "[character] or [body]", available=observer_templates(pm))

    return load_chain(observer_template_path(template, pm, key=key), pm, head_key="observer", check=check)


OBSERVER_KEYS = ("name", "description", "lengths_for_height", "extends")


# Tables of an observer template holding, per plugin, the parameters it gets when named instead of the template's own
# (`--segmenter NAME`): [segmenters.NAME], [matchers.NAME], [motors.NAME].
ALTERNATIVES = {"segmenter": "segmenters", "matcher": "matchers", "motor": "motors"}


def is_observer_template(table: Mapping[str, Any]) -> bool:
    """Whether a parsed TOML table is an observer template: an ``[observer]`` table (name, description) and a
    character's component tables, without a ``[body]`` (a body profile gives it when the observer is composed)."""
    return "observer" in table and "character" not in table


def check_observer_template(path: str | Path, pm: Any) -> dict[str, str]:
    """The plugin of each component table of an observer template (and of those it extends), every name and
    parameter checked (a :class:`ConfigError` naming the file, key and line otherwise: the outermost file that
    writes the key); attaching waits for a body and clips."""
    return checked_template(path, pm)[1]


def checked_template(path: str | Path | None, pm: Any) -> tuple[dict[str, Any], dict[str, str]]:
    """The merged table of an observer template, read once, and the plugin of each component table, as
    :func:`check_observer_template` checks them."""
    table, files = read_observer_template(path, pm)
    if path and Path(path).is_file():  # the outermost file named as the caller named it
        files = (Path(path), *files[1:])
    plugins = {}
    try:
        for key in table:
            if key not in ("observer", *COMPONENT_TABLES, *ALTERNATIVES.values()):
                raise ConfigError(f"unknown table {key!r}", key=(key,), expected="an observer template table",
                                  available=("observer", *COMPONENT_TABLES, *ALTERNATIVES.values()))
        for kind, key in ALTERNATIVES.items():  # [segmenters.NAME]: NAME's parameters when it is named instead
            for name, params in table.get(key, {}).items():
                if not isinstance(params, Mapping):
                    raise ConfigError("not a table", key=(key, name), expected=f"a [{key}.{name}] table")
                if "plugin" in params:
                    raise ConfigError("a plugin named inside a plugin's own table", key=(key, name, "plugin"),
                                      expected=f"{name}'s parameters only (the table's name is the plugin)")
                try:
                    build_component(kind, {"plugin": name, **params}, pm)
                except ConfigError as err:  # named as written: [segmenters.NAME], not [segmenter]
                    inner = err.key[1:] if err.key and err.key[0] == kind and err.key[1:] != ("plugin",) else ()
                    where = (key, name, *inner)
                    raise ConfigError(err.problem, key=where, expected=err.expected, available=err.available) from None
        head = table["observer"]
        if not isinstance(head, Mapping):
            raise ConfigError("not a table", key=("observer",), expected="an [observer] table")
        for key in head:
            if key not in OBSERVER_KEYS:
                raise ConfigError(f"unknown key {key!r}", key=("observer", key), expected="an [observer] key",
                                  available=OBSERVER_KEYS)
        lengths_for = head.get("lengths_for_height")  # what composing the observer refuses, refused here too
        if lengths_for is not None and (finite_number(lengths_for) or 0.0) <= 0:
            raise ConfigError(f"invalid value {lengths_for!r}", key=("observer", "lengths_for_height"),
                              expected="a positive number: the standing height (m) the length parameters were "
                                       "written for")
        for key in COMPONENT_TABLES:
            if key in table:
                if not isinstance(table[key], Mapping):
                    raise ConfigError("not a table", key=(key,), expected=f"a [{key}] table")
                plugins[key] = build_component(key, table[key], pm).name
    except ConfigError as err:
        where, line = files[0], None
        for file in files if err.key else ():
            line = find_key_line(file, err.key)
            if line is not None:
                where = file
                break
        raise ConfigError(err.problem, file=where, key=err.key, line=line, expected=err.expected,
                          available=err.available) from None
    return table, plugins
