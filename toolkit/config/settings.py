"""Settings given on the command line, ``--set TABLE.KEY=VALUE``: parsed into tables and checked before any work.

A value is read as TOML (``4``, ``0.5``, ``true``, ``["a", "b"]``; a bare word is a string); ``TABLE.KEY.INNER``
reaches into a parameter's own table (:class:`toolkit.params.Parameter`). :func:`check_settings` checks every key
and value against each plugin the settings will reach, so a misspelt key fails at once, naming what is there.
"""

from __future__ import annotations

import tomllib
from collections.abc import Mapping, Sequence
from typing import Any

from toolkit.character import COMPONENT_TABLES
from toolkit.components import KINDS
from toolkit.config.toml import MAX_DEPTH, MAX_DIGITS, NumberTooLong, loads, too_deep
from toolkit.errors import ConfigError
from toolkit.params import of_owner

__all__ = ["parse_settings", "check_settings"]


def parse_settings(items: list[str], *, tables: bool = True) -> dict[str, Any]:
    """Command-line ``--set`` strings as nested tables: ``TABLE.KEY=VALUE`` (or ``KEY=VALUE`` without ``tables``).

    VALUE is read as TOML (``4``, ``0.5``, ``true``, ``["a", "b"]``); a bare word is a string.
    """
    out: dict[str, Any] = {}
    for item in items:
        if any(c in item for c in "\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029"):  # str.splitlines' line breaks
            raise ConfigError(f"a setting holding a line break: {item!r}", key=("--set",),
                              expected="TABLE.KEY=VALUE on one line (one value; no TOML tables after it)")
        key, sep, value = item.partition("=")
        table, dot, name = key.strip().partition(".")
        if not tables:
            table, dot, name = "", ".", key.strip()
        path = name.split(".")
        if not sep or not dot or (tables and not table) or not all(path):
            raise ConfigError(f"invalid setting {item!r}", key=("--set",), expected="TABLE.KEY=VALUE, like segmenter.floor=0"
                              " (TABLE.KEY.KEY=VALUE inside a parameter's own table)"
                              if tables else "KEY=VALUE, like keys=4")
        try:
            parsed = loads(f"v = {value}")["v"]  # one line (no line break, above): one value, nothing after it
        except NumberTooLong as exc:
            raise ConfigError(f"{exc}", key=("--set", *([table] if tables else []), *path),
                              expected=f"an integer of at most {MAX_DIGITS} digits") from None
        except tomllib.TOMLDecodeError:
            parsed = value  # a bare word is a string
        except RecursionError:
            parsed = None
        if parsed is None or too_deep({"v": parsed}):
            raise ConfigError(f"value of {key.strip()!r} nested more than {MAX_DEPTH} levels deep", key=("--set",),
                              expected=f"arrays and tables nested at most {MAX_DEPTH} levels deep")
        where = out.setdefault(table, {}) if tables else out
        for i, part in enumerate(path[:-1]):  # KEY.KEY: inside a parameter's own table
            inner = where.setdefault(part, {})
            if not isinstance(inner, dict):
                raise ConfigError(f"{'.'.join(path[: i + 1])!r} given both a value and keys", key=("--set", table),
                                  expected="either KEY=VALUE or KEY.INNER=VALUE for one key")
            where = inner
        where[path[-1]] = parsed
    return out


def check_settings(settings: Mapping[str, Mapping[str, Any]], pm: Any, plugins: Mapping[str, Sequence[str]], *,
                   option: str = "--set") -> None:
    """Check command-line settings (``TABLE.KEY=VALUE`` as parsed by :func:`parse_settings`) before any work.

    Every table must be a component table; every key a parameter, and every value valid, for each plugin the
    table's settings will reach: ``plugins[TABLE]`` (a benchmark that compares several matchers checks
    ``matcher.KEY`` against each of them), or the plugin the settings themselves name with ``TABLE.plugin=NAME``.

    Raises
    ------
    ConfigError
        Keyed ``OPTION.TABLE.KEY``, listing the component tables, or the plugin's parameters.
    """
    for table, values in settings.items():
        if table not in COMPONENT_TABLES:
            raise ConfigError(f"unknown table {table!r}", key=(option, table), expected=f"{option} TABLE.KEY=VALUE "
                              "with TABLE a component table", available=list(COMPONENT_TABLES))
        named = values.get("plugin")
        names = [named] if named is not None else list(plugins.get(table, ()))
        if not names:
            raise ConfigError(f"no [{table}] component to set", key=(option, table),
                              expected=f"a table the observer has, or {table}.plugin=NAME with it",
                              available=[t for t in COMPONENT_TABLES if plugins.get(t)])
        for name in names:
            if not isinstance(name, str):
                raise ConfigError(f"invalid plugin name {name!r}", key=(option, table, "plugin"),
                                  expected=f"the name of a registered {KINDS[table].kind}",
                                  available=pm.registry.names(table))
            try:
                cls = pm.registry.get(table, name)
            except ConfigError as err:
                raise err.within(prefix=(option, table, "plugin")) from None
            owner = f"{KINDS[table].kind} {name!r}"
            known = {p.name: p for p in cls.parameters}
            for key, value in values.items():
                if key == "plugin":
                    continue
                if key not in known:
                    raise ConfigError(f"unknown parameter {key!r} for {owner}", key=(option, table, key),
                                      expected=f"a parameter of {owner}", available=sorted(known))
                try:
                    known[key].coerce(value)
                except ConfigError as err:
                    rest = (key, *err.key[1:]) if err.key[:1] == ("",) else err.key
                    if known[key].table and " for table " in err.problem:
                        err = of_owner(err, owner)
                    else:
                        err = ConfigError(f"{err.problem} for {owner}", expected=err.expected, available=err.available)
                    raise ConfigError(err.problem, key=(option, table, *rest), expected=err.expected,
                                      available=err.available) from None
