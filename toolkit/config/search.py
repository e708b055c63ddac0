"""Where declarations are found and how they extend one another: the character path, ``extends`` chains, merging.

A file named without a path (``extends = "max"``, ``character = "morris"``, ``--observer papers``) is looked up
on the character path (:func:`character_paths`): ``$LIKEME_CHARACTERS``, the project's ``characters/``, the installed
copy, then the folders plugins add (``likeme_character_paths``). A file that ``extends`` another is merged onto it
(:func:`merge_tables`): tables key by key, a component table naming another ``plugin`` replacing the inherited one.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

from toolkit.config.toml import read_toml
from toolkit.errors import ConfigError

if TYPE_CHECKING:  # pragma: no cover
    from toolkit.manager import PluginManager

__all__ = ["MAX_EXTENDS", "builtin_characters", "character_paths", "resolve_file", "merge_tables", "load_chain"]


MAX_EXTENDS = 64
"""The longest ``extends`` chain a character file may start."""


def builtin_characters() -> Path:
    """The folder of the built-in characters (with ``scenarios/``, ``observers/`` and ``profiles/``): the project's
    ``characters/`` in a source tree or an editable install, else the copy a regular install puts under
    ``<prefix>/share/likeme/characters``."""
    import sys

    project = Path(__file__).resolve().parents[2] / "characters"
    installed = Path(sys.prefix) / "share" / "likeme" / "characters"
    return project if project.is_dir() or not installed.is_dir() else installed


def character_paths(pm: PluginManager | None = None) -> list[Path]:
    """Folders searched for character and scenario files named without a path.

    In order: ``$LIKEME_CHARACTERS`` (``os.pathsep``-separated), the project's
    ``characters/`` folder (source tree or editable install), the installed copy
    under ``<prefix>/share/likeme/characters``, then folders from the
    ``likeme_character_paths`` hook.
    """
    import os
    import sys

    paths: list[Path] = []
    env = os.environ.get("LIKEME_CHARACTERS")
    if env:
        paths.extend(Path(p) for p in env.split(os.pathsep) if p)
    paths.append(Path(__file__).resolve().parents[2] / "characters")
    paths.append(Path(sys.prefix) / "share" / "likeme" / "characters")
    if pm is not None:
        for result in pm.hook.likeme_character_paths():
            paths.extend(Path(p) for p in result or ())
    out: list[Path] = []
    for p in paths:
        for candidate in (p, p / "scenarios"):
            if candidate.is_dir() and candidate not in out:
                out.append(candidate)
    return out


def resolve_file(ref: str, base: Path | None, pm: PluginManager | None, *, key: tuple = (), file: Path | None = None) -> Path:
    """Find a referenced file: a path relative to ``base``, else a name on :func:`character_paths`."""
    candidates: list[Path] = []
    if base is not None:
        candidates.append(base / ref)
    candidates.append(Path(ref))
    name = ref if ref.endswith(".toml") else ref + ".toml"
    searched = character_paths(pm)
    candidates.extend(p / name for p in searched)
    for c in candidates:
        try:
            if c.is_file():
                return c.resolve()
        except OSError:  # a name too long for the file system, a loop of links: not a file that can be found
            continue
    known = sorted({f.stem for p in searched for f in p.glob("*.toml")})
    raise ConfigError(
        f"cannot find {ref[:80]!r}" + (f" ({len(ref)} characters)" if len(ref) > 80 else ""),
        file=file,
        key=key,
        expected="a path relative to this file or the name of a character on the search path",
        available=known,
    )


def merge_tables(base: Mapping[str, Any], over: Mapping[str, Any]) -> dict[str, Any]:
    """Deep-merge ``over`` onto ``base``: tables merge, anything else is replaced.

    A table whose ``plugin`` key differs from the inherited one replaces it whole,
    so parameters of one plugin never leak into another.
    """
    out = dict(base)
    for key, value in over.items():
        old = out.get(key)
        if isinstance(old, Mapping) and isinstance(value, Mapping):
            if "plugin" in value and value.get("plugin") != old.get("plugin"):
                out[key] = dict(value)
            else:
                out[key] = merge_tables(old, value)
        else:
            out[key] = value
    return out


def load_chain(path: Path, pm: PluginManager | None, stack: tuple[Path, ...] = (), *,
                head_key: str = "character", check: Callable[[Path, dict, Path | None], None] | None = None
                ) -> tuple[dict[str, Any], tuple[Path, ...]]:
    """The merged table of ``path`` and everything it extends, and the files involved (outermost first).

    ``head_key`` names the table holding ``extends`` (and the ``name`` a file does not pass on): ``[character]``
    for characters, ``[observer]`` for observer templates (:func:`toolkit.config.observer_templates.read_observer_template`).
    ``check(file, table, extended_by)``, if given, sees each file's own table as it is read (``extended_by``: the
    file whose ``extends`` named it, None for ``path``)."""
    path = path.resolve()
    if len(stack) >= MAX_EXTENDS:
        raise ConfigError(f"extends chain longer than {MAX_EXTENDS} files", file=stack[-1],
                          key=(head_key, "extends"),
                          expected=f"at most {MAX_EXTENDS} files, each extending the next")
    if path in stack:
        cycle = " -> ".join(p.name for p in (*stack, path))
        raise ConfigError(f"extends cycle: {cycle}", file=stack[-1], key=(head_key, "extends"), expected="no cycle")
    table = read_toml(path)
    if check is not None:
        check(path, table, stack[-1] if stack else None)
    head = table.get(head_key, {})
    if not isinstance(head, Mapping):
        raise ConfigError("not a table", file=path, key=(head_key,),
                          expected=f"{'an' if head_key[0] in 'aeiou' else 'a'} [{head_key}] table")
    ref = head.get("extends")
    if ref is None:
        return table, (path,)
    if not isinstance(ref, str):
        raise ConfigError(f"wrong type {type(ref).__name__}", file=path, key=(head_key, "extends"),
                          expected=f"a file path or {head_key} name")
    parent_path = resolve_file(ref, path.parent, pm, key=(head_key, "extends"), file=path)
    parent, files = load_chain(parent_path, pm, (*stack, path), head_key=head_key, check=check)
    own = dict(table)
    own[head_key] = {k: v for k, v in head.items() if k != "extends"}
    parent = dict(parent)
    parent[head_key] = {k: v for k, v in parent.get(head_key, {}).items() if k != "name"}
    return merge_tables(parent, own), (path, *files)
